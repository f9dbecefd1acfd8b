// The nmbake command's output set: the shared output contract (io/output_files.h) with the run's
// interruption checked before the renames.
#pragma once

#include <functional>

#include "io/output_files.h"

namespace nmbake {

class OutputSet : public OutputFiles {
 public:
  // Throws Cancelled, nothing renamed, when `cancelled` says so before the first rename; else
  // OutputFiles::commit.
  void commit(const std::function<bool()>& cancelled);
};

}  // namespace nmbake
