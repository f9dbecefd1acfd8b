#include "cli/outputs.h"

#include "pipeline/bake.h"

namespace nmbake {

void OutputSet::commit(const std::function<bool()>& cancelled) {
  if (cancelled && cancelled()) throw Cancelled();
  OutputFiles::commit();
}

}  // namespace nmbake
