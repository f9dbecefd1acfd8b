// Error kinds of nmbake and the exit codes the command line maps them to.
//
// Bad user data throws one of these, carrying the file and the element ("low.obj: face 812 has no
// UVs"); main() prints it as one line "error: <what>" and exits with code(). Programmer mistakes
// are asserts, degenerate but legal geometry is counted and never throws.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace nmbake {

enum class ExitCode : int {
  ok = 0,
  usage = 1,   // bad command line
  input = 2,   // unreadable or invalid input file
  output = 3,  // output could not be written
  memory = 4,  // out of memory or refused size
  strict = 5,  // a warning under --strict
};

class Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& what) : std::runtime_error(what), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

struct UsageError : Error {
  explicit UsageError(const std::string& what) : Error(ExitCode::usage, what) {}
};
struct InputError : Error {
  explicit InputError(const std::string& what) : Error(ExitCode::input, what) {}
};
struct OutputError : Error {
  explicit OutputError(const std::string& what) : Error(ExitCode::output, what) {}
};
struct ResourceError : Error {
  explicit ResourceError(const std::string& what) : Error(ExitCode::memory, what) {}
};

// A message as one line, as every error of the three commands is printed: line breaks and runs of
// white space as one space, control bytes as '?', no blanks at either end; cut to `max` characters
// with "..." when max > 0.
std::string one_line(std::string_view text, std::size_t max = 0);

}  // namespace nmbake
