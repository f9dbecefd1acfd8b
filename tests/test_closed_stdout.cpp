// A closed stdout (`nmbake ... | head -0`) is an error like any other failed write: exit 3 for
// nmbake, 2 for nmdiff, with one line on stderr, never a SIGPIPE death (exit 141). The pipe's
// read end is closed before the program starts, so every write to stdout fails at once.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"

namespace {

struct Finished {
  bool signalled = false;
  int code = -1;
  std::string err;
};

// Runs `argv` in `dir` with stdout a pipe nobody reads and stderr captured.
Finished run_with_closed_stdout(const std::vector<std::string>& argv, const std::string& dir) {
  int out[2], err[2];
  if (::pipe(out) != 0 || ::pipe(err) != 0) return {};
  ::close(out[0]);  // no reader: writes to out[1] fail with EPIPE (or SIGPIPE)
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGPIPE, SIG_DFL);  // as a shell starts it
    if (::chdir(dir.c_str()) != 0) ::_exit(127);
    ::dup2(out[1], 1);
    ::dup2(err[1], 2);
    ::close(err[0]);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  ::close(out[1]);
  ::close(err[1]);
  Finished f;
  char buf[4096];
  for (ssize_t n; (n = ::read(err[0], buf, sizeof buf)) > 0;) f.err.append(buf, std::size_t(n));
  ::close(err[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  f.signalled = WIFSIGNALED(status);
  f.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return f;
}

}  // namespace

TEST(ClosedStdout, NmbakeExitsWithAnOutputError) {
  const std::string dir = nmbake::test::scratch_dir();
  const Finished f =
      run_with_closed_stdout({std::string(NMBAKE_BINARY_DIR) + "/baker/nmbake", nmbake::test::data_path("sample/torus_low.obj"),
                              nmbake::test::data_path("sample/torus_high.ply"), "-o", "out.png", "--size", "64"},
                             dir);
  EXPECT_FALSE(f.signalled) << "killed by a signal";
  EXPECT_EQ(f.code, 3) << f.err;
  EXPECT_NE(f.err.find("error: stdout: cannot write"), std::string::npos) << f.err;
}

TEST(ClosedStdout, NmdiffExitsWithAnError) {
  const std::string dir = nmbake::test::scratch_dir();
  const std::string map = nmbake::test::data_path("golden/torus_256.png");
  const Finished f = run_with_closed_stdout({std::string(NMBAKE_BINARY_DIR) + "/nmdiff/nmdiff", map, map}, dir);
  EXPECT_FALSE(f.signalled) << "killed by a signal";
  EXPECT_EQ(f.code, 2) << f.err;
  EXPECT_NE(f.err.find("error: stdout: cannot write"), std::string::npos) << f.err;
}
