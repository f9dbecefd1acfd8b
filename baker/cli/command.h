// The nmbake command as a function of its arguments, so that the program's main() and the tests
// run the same code: parses argv (argv[0] is the program's name), runs the bake or the batch, prints
// on stdout and stderr and returns the exit status (README's table). An error is one
// "error: <what>" line on stderr and its status; nothing escapes as an exception.
// It installs handlers for SIGINT, SIGTERM and SIGHUP (a signal ends the bake with 128 + its number
// and no output). The working directory, the environment and the standard streams are the caller's;
// main() protects the streams first (io/output_files.h).
#pragma once

namespace nmbake {

int nmbake_command(int argc, char** argv);

}  // namespace nmbake
