// The shell the three commands (nmbake, nmdiff, nmview) share around their work: one way to parse
// the command line, one mapping from errors to an exit status, one "error: <what>" line.
#pragma once

#include <exception>
#include <functional>
#include <optional>
#include <string>

// CLI11's App, declared: CLI/CLI.hpp costs seconds of compile time in every translation unit that
// includes it, so only the .cpp files that parse do.
namespace CLI {
class App;
}  // namespace CLI

#include "core/errors.h"

namespace nmbake {

// A command's exit status for each kind of error (errors.h): README's table for nmbake and nmview;
// nmdiff, whose 1 means "outside tolerance", exits 2 for a bad command line too.
// Other codes (ok, strict) are the same in every command.
struct ExitStatuses {
  int usage = int(ExitCode::usage), input = int(ExitCode::input), output = int(ExitCode::output), memory = int(ExitCode::memory);
  int of(ExitCode code) const;
};

// Parses the command line into `app`'s options: nothing to go on, or the status to exit with after
// --help or --version (printed by CLI11). A command line in error throws UsageError with CLI11's
// message and "(see TOOL --help)".
std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv, const std::string& tool);

// What an error ends a command (or a batch's job) with: its exit status and its message, one line.
struct Failure {
  int status = 0;
  std::string message;
};

// The failure of `error`, by its kind:
//   nmbake::Error                  statuses.of(its code())
//   std::bad_alloc                 memory: "out of memory", "out of memory while <*doing>" when set
//   std::system_error, ENOMEM or EAGAIN (a thread the system would not give under ulimit -v): memory
//   any other exception            input
Failure failure_of(const std::exception_ptr& error, const ExitStatuses& statuses = {}, const char* const* doing = nullptr);

// Runs `work` and returns its status; an exception is printed on stderr as "error: <message>" and
// ends it with its status (failure_of).
int run_command(const std::function<int()>& work, const ExitStatuses& statuses = {}, const char* const* doing = nullptr);

}  // namespace nmbake
