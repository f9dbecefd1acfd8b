// The nmbake command as a function of its arguments, so that the program's main() and the tests
// run the same code: parses argv (argv[0] is the program's name), runs the bake or the batch, prints
// on stdout and stderr and returns the exit status (README's table). An error is one
// "error: <what>" line on stderr and its status; nothing escapes as an exception.
// It installs handlers for SIGINT, SIGTERM and SIGHUP (a signal ends the bake with 128 + its number
// and no output). The working directory, the environment and the standard streams are the caller's;
// main() protects the streams first (io/output_files.h).
#pragma once

#include <optional>

#include "cli/args.h"

namespace nmbake {

int nmbake_command(int argc, char** argv);

// A bake's command line (not --batch; argv[0] the program's name) parsed into `a` as the command
// parses it, every check and message the same (the Python module, python/, turns its keyword
// arguments into one): throws UsageError on a bad one; returns the status to exit with after
// --help or --version (printed on stdout), nothing when the bake is to go on.
std::optional<int> parse_bake_command_line(int argc, char** argv, Args& a);

}  // namespace nmbake
