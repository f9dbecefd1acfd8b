// Running the real nmview and nmbake binaries from the viewer's tests, headless.
#pragma once

#include <initializer_list>
#include <string>
#include <vector>

#include "metrics.h"

namespace nmview::test {

// This process made headless, as run_tool makes its children: DISPLAY and WAYLAND_DISPLAY unset,
// LIBGL_ALWAYS_SOFTWARE=1 (EGL surfaceless with llvmpipe). Before a test's own HeadlessContext.
void make_headless();

// nmview --compare's figures over the interior (the lit panes only: CompareScope::shading),
// measured in the test's process: the scene of `low`, the texture set found from `map` and `high`
// loaded once, then rendered at `width` x `height` a pane once per entry of `map_on` (the map
// applied or not). Needs a current context (nmview::HeadlessContext, after make_headless).
std::vector<ErrorSums> compare_interior(const std::string& low, const std::string& map, const std::string& high, int width,
                                        int height, std::initializer_list<bool> map_on);

// What a run printed and how it ended (-1: not a normal exit).
struct ToolRun {
  int exit_code = -1;
  std::string out, err;
};

// `s` as one single-quoted shell word.
std::string quote(const std::string& s);

// Runs `program` with `args` (shell words) through the shell, headless (make_headless), stdin from
// /dev/null, stdout and
// stderr kept in stdout.txt and stderr.txt in `dir`.
ToolRun run_tool(const std::string& dir, const std::string& program, const std::string& args);

// run_tool of the nmview binary (nmbake::build::nmview_exe()).
ToolRun nmview(const std::string& dir, const std::string& args);

// The one "error: ..." line among a run's stderr notes ("" when none; a second one fails the test).
std::string error_line(const std::string& err);

}  // namespace nmview::test
