// The nmdiff command as functions, so that the program's main() (main.cpp) and the Python module
// (python/) run the same code.
#pragma once

#include <string>
#include <vector>

namespace nmbake {

// nmdiff with main()'s arguments: prints and writes what the command does and returns its exit
// status (0 within the tolerances, 1 outside, 2 bad input or command line, 3 output, 4 memory);
// nothing escapes as an exception. The caller protects the standard streams first
// (io/output_files.h), as main() does.
int nmdiff_command(int argc, char** argv);

// The comparison of the command line `words` (words[0] the program's name) without nmdiff's lines
// on stdout: returns the JSON text --json would write (one object, the normal maps' keys or the other
// maps', as nmdiff writes them), and writes --heatmap and --json when they are given. Throws
// nmdiff's errors (UsageError for a bad command line or --help, InputError, OutputError,
// std::bad_alloc); prints its convention lines on stderr.
std::string nmdiff_json_text(const std::vector<std::string>& words);

}  // namespace nmbake
