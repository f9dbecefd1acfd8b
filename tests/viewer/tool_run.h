// Running the real nmview and nmbake binaries from the viewer's tests, headless.
#pragma once

#include <string>

namespace nmview::test {

// What a run printed and how it ended (-1: not a normal exit).
struct ToolRun {
  int exit_code = -1;
  std::string out, err;
};

// `s` as one single-quoted shell word.
std::string quote(const std::string& s);

// Runs `program` with `args` (shell words) through the shell, headless (DISPLAY and WAYLAND_DISPLAY
// unset, LIBGL_ALWAYS_SOFTWARE=1: EGL surfaceless with llvmpipe), stdin from /dev/null, stdout and
// stderr kept in stdout.txt and stderr.txt in `dir`.
ToolRun run_tool(const std::string& dir, const std::string& program, const std::string& args);

// run_tool of the nmview binary (nmbake::build::nmview_exe()).
ToolRun nmview(const std::string& dir, const std::string& args);

// The one "error: ..." line among a run's stderr notes ("" when none; a second one fails the test).
std::string error_line(const std::string& err);

}  // namespace nmview::test
