// Text outputs (reports, JSON, cages) written like the maps: to a temporary file beside the target,
// renamed into place only when complete, so a failed write never leaves a partial file or loses the
// old one.
#pragma once

#include <string>

namespace nmbake {

// Throws OutputError "<path>: cannot write: <reason>" (the temporary removed).
void write_text_atomically(const std::string& path, const std::string& text);

}  // namespace nmbake
