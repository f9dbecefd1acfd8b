// nmdiff's comparison for the Python module: the figures `nmdiff A B ... --json FILE` writes, for
// the same command line, without its lines on stdout.
#pragma once

#include <string>
#include <vector>

namespace nmbake::python {

// `words` is nmdiff's command line (words[0] its name). Returns the JSON text --json would write
// (one object; the normal maps' keys or the other maps', as nmdiff writes them) and writes
// --heatmap and --json when they are given. Throws nmdiff's errors (UsageError for a bad command
// line, InputError, OutputError, std::bad_alloc); prints nmdiff's convention lines on stderr.
std::string nmdiff_json(const std::vector<std::string>& words);

}  // namespace nmbake::python
