#include "cli/shell.h"

#include <cstdio>
#include <new>
#include <system_error>
#include <CLI/CLI.hpp>

namespace nmbake {

int ExitStatuses::of(ExitCode code) const {
  switch (code) {
    case ExitCode::usage: return usage;
    case ExitCode::input: return input;
    case ExitCode::output: return output;
    case ExitCode::memory: return memory;
    default: return int(code);
  }
}

std::optional<int> parse_command_line(CLI::App& app, int argc, char** argv, const std::string& tool) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --help-all, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    throw UsageError(std::string(e.what()) + " (see " + tool + " --help)");
  }
  return std::nullopt;
}

Failure failure_of(const std::exception_ptr& error, const ExitStatuses& statuses, const char* const* doing) {
  Failure f{statuses.input, "unknown error"};
  try {
    std::rethrow_exception(error);
  } catch (const Error& e) {
    f = {statuses.of(e.code()), e.what()};
  } catch (const std::bad_alloc&) {
    const bool known = doing && *doing;
    f = {statuses.memory, std::string("out of memory") + (known ? " while " : "") + (known ? *doing : "")};
  } catch (const std::system_error& e) {
    const bool memory = e.code() == std::errc::resource_unavailable_try_again || e.code() == std::errc::not_enough_memory;
    f = {memory ? statuses.memory : statuses.input, std::string(memory ? "out of memory: " : "") + e.what()};
  } catch (const std::exception& e) {
    f.message = e.what();
  } catch (...) {
  }
  f.message = one_line(f.message);
  if (f.message.empty()) f.message = "unknown error";
  return f;
}

int run_command(const std::function<int()>& work, const ExitStatuses& statuses, const char* const* doing) {
  try {
    return work();
  } catch (...) {
    const Failure f = failure_of(std::current_exception(), statuses, doing);
    std::fprintf(stderr, "error: %s\n", f.message.c_str());
    return f.status;
  }
}

}  // namespace nmbake
