// A closed or full stdout or stderr (`>&-`, `>/dev/full`, `2>&-`, `2>/dev/full`, `| head -c 0`)
// loses the messages and nothing else (issue 34, item 9; io/output_files.h,
// protect_standard_streams): nmbake, nmdiff and nmview exit as with working streams, their
// outputs complete and byte-identical to a run with working streams, never killed by SIGPIPE; a
// run that fails still fails (non-zero) and leaves the old outputs as they were. Never both.
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"
#include "build_paths.h"

namespace {

using nmbake::test::data_path;
using nmbake::test::read_file;

// Runs `command` with bash in `dir` (the streams it leaves alone go to /dev/null); the exit status
// of its first command (of a pipeline too): 128 + the signal that killed it, -1 when bash itself
// did not exit normally.
int run_in(const std::string& dir, const std::string& command) {
  const std::string script =
      "cd '" + dir + "' || exit 125; { " + command + "; status=${PIPESTATUS[0]}; } >/dev/null 2>&1; exit $status";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/bash", "bash", "-c", script.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The stream conditions, as redirections.
const std::vector<std::string> kBrokenStreams{">&-",         ">/dev/full",      "2>&-", "2>/dev/full", ">&- 2>&-",
                                              "| head -c 0", "2>&1 | head -c 0"};

// A tool's command line and the files it writes (compared with a run with working streams).
struct Tool {
  std::string command;              // run in the scratch folder
  std::vector<std::string> files;   // its outputs there
  std::vector<std::string> stable;  // those byte-identical between runs (the others only complete)
  std::string failing;              // a command line that fails (a missing input), same outputs
};

std::string binary(const std::string& relative) { return std::string(nmbake::build::binary_dir()) + "/" + relative; }

Tool nmbake_tool() {
  const std::string args = " '" + data_path("sample/torus_low.obj") + "' '" + data_path("sample/torus_high.ply") + "'";
  const std::string out = " -o m.png --size 64 --report r.json";
  return {binary("baker/nmbake") + args + out,
          {"m.png", "r.json"},
          {"m.png"},
          binary("baker/nmbake") + " missing.obj '" + data_path("sample/torus_high.ply") + "'" + out};
}

Tool nmdiff_tool() {
  const std::string map = " '" + data_path("golden/torus_256.png") + "'";
  const std::string out = " --json d.json --heatmap h.png";
  return {binary("nmdiff/nmdiff") + map + map + out,
          {"d.json", "h.png"},
          {"d.json", "h.png"},
          binary("nmdiff/nmdiff") + " missing.png" + map + out};
}

Tool nmview_tool() {
  const std::string meshes[2] = {" '" + data_path("sample/torus_low.obj") + "'", " '" + data_path("sample/torus_high.ply") + "'"};
  const std::string out = " --screenshot s.png --size 64x32";
  return {binary("viewer/nmview") + meshes[0] + " '" + data_path("golden/torus_256.png") + "'" + meshes[1] + out,
          {"s.png"},
          {},
          binary("viewer/nmview") + meshes[0] + " missing.png" + meshes[1] + out};
}

// A PNG that ends with its IEND chunk; any other file not empty.
bool complete(const std::string& path) {
  const std::string bytes = read_file(path);
  if (path.size() < 4 || path.substr(path.size() - 4) != ".png") return !bytes.empty();
  return bytes.size() > 20 && bytes.compare(0, 4, "\x89PNG") == 0 && bytes.compare(bytes.size() - 8, 4, "IEND") == 0;
}

// Each broken stream: the same exit status and outputs as with working streams; then the failing
// command with broken streams: its status non-zero, the old outputs untouched.
void check_tool(const Tool& tool) {
  const std::string ref = nmbake::test::scratch_dir();
  const int expected = run_in(ref, tool.command);
  ASSERT_EQ(expected, 0) << tool.command;
  for (const std::string& streams : kBrokenStreams) {
    const std::string dir = nmbake::test::scratch_dir();
    for (const std::string& f : tool.files) nmbake::test::write_file(dir + "/" + f, "old");
    EXPECT_EQ(run_in(dir, tool.command + " " + streams), expected) << streams << ": " << tool.command;
    for (const std::string& f : tool.files) EXPECT_TRUE(complete(dir + "/" + f)) << streams << ": " << f;
    for (const std::string& f : tool.stable)
      EXPECT_EQ(read_file(dir + "/" + f), read_file(ref + "/" + f)) << streams << ": " << f << " differs";

    for (const std::string& f : tool.files) nmbake::test::write_file(dir + "/" + f, "old");
    const int failed = run_in(dir, tool.failing + " " + streams);
    EXPECT_NE(failed, 0) << streams << ": " << tool.failing;
    EXPECT_LT(failed, 128) << streams << ": killed by a signal";
    for (const std::string& f : tool.files) EXPECT_EQ(read_file(dir + "/" + f), "old") << streams << ": " << f << " changed";
  }
}

}  // namespace

TEST(ClosedStreams, NmbakeWritesItsOutputsAndExitsZero) { check_tool(nmbake_tool()); }

TEST(ClosedStreams, NmdiffWritesItsOutputsAndExitsWithItsVerdict) { check_tool(nmdiff_tool()); }

TEST(ClosedStreams, NmviewWritesItsScreenshotAndExitsZero) {
  if (!nmbake::test::exists(binary("viewer/nmview"))) GTEST_SKIP() << "nmview not built (NMBAKE_VIEWER=OFF)";
  const std::string dir = nmbake::test::scratch_dir();
  if (run_in(dir, nmview_tool().command) != 0) GTEST_SKIP() << "nmview cannot render here (no EGL)";
  check_tool(nmview_tool());
}
