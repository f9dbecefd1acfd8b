#include "tool_run.h"

#include <sys/wait.h>

#include <cstdlib>
#include <sstream>

#include <gtest/gtest.h>

#include "compare.h"
#include "scene.h"
#include "test_support.h"
#include "texture_set.h"
#include "build_paths.h"

namespace nmview::test {

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

void make_headless() {
  unsetenv("DISPLAY");
  unsetenv("WAYLAND_DISPLAY");
  setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
}

std::vector<ErrorSums> compare_interior(const std::string& low, const std::string& map, const std::string& high, int width,
                                        int height, std::initializer_list<bool> map_on) {
  std::ostringstream log;
  const Scene scene = load_scene(low, find_texture_set(map), high, log);
  Renderer renderer(scene.low, scene.high, scene.map, scene.radius, scene.decoding);
  std::vector<ErrorSums> out;
  for (const bool on : map_on) {
    Toggles measure;
    measure.map = on;
    out.push_back(run_compare(renderer, width, height, Light{}, measure, CompareScope::shading).total.interior);
  }
  return out;
}

ToolRun run_tool(const std::string& dir, const std::string& program, const std::string& args) {
  make_headless();
  const std::string out = dir + "/stdout.txt", err = dir + "/stderr.txt";
  const std::string command = quote(program) + " " + args + " >" + quote(out) + " 2>" + quote(err) + " </dev/null";
  const int status = std::system(command.c_str());
  ToolRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = nmbake::test::read_file(out);
  r.err = nmbake::test::read_file(err);
  return r;
}

ToolRun nmview(const std::string& dir, const std::string& args) { return run_tool(dir, nmbake::build::nmview_exe(), args); }

std::string error_line(const std::string& err) {
  std::istringstream in(err);
  std::string found;
  for (std::string line; std::getline(in, line);)
    if (line.rfind("error: ", 0) == 0) {
      EXPECT_TRUE(found.empty()) << "two error lines:\n" << err;
      found = line;
    }
  return found;
}

}  // namespace nmview::test
