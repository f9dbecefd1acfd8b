// nmview against hostile inputs and outputs, run headless like test_nmview.cpp: inputs that are not
// regular files (refused at once, exit 2), a map header stating more pixels than its file holds
// (exit 4), a closed stdout (exit 3, never a SIGPIPE death), --compare leaving no file behind
// unless asked for one, and ulimit -v (a map too big for it is exit 4 with no image). Every failure
// is one "error: ..." line naming the file.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../cli/nmdiff/hostile_fixtures.h"
#include "scene_maker.h"
#include "test_support.h"
#include "build_paths.h"

namespace {

namespace fs = std::filesystem;

struct Finished {
  bool signalled = false;
  int code = -1;
  std::string out, err;
};

// Runs nmview with `args` in `dir`, headless, stdin /dev/null. With `closed_stdout`, stdout is a
// pipe whose reader is already gone (every write fails with EPIPE, or kills by SIGPIPE). Killed
// after 60 s (a hang fails the test instead of blocking it). A nonzero `limit_mb` is its ulimit -v.
Finished run_nmview(const std::string& dir, const std::vector<std::string>& args, bool closed_stdout = false,
                    unsigned limit_mb = 0) {
  int out[2], err[2];
  if (::pipe(out) != 0 || ::pipe(err) != 0) return {};
  if (closed_stdout) ::close(out[0]);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::signal(SIGPIPE, SIG_DFL);  // as a shell starts it
    ::unsetenv("DISPLAY");
    ::unsetenv("WAYLAND_DISPLAY");
    ::setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
    if (::chdir(dir.c_str()) != 0) ::_exit(127);
    const int null = ::open("/dev/null", O_RDONLY);
    ::dup2(null, 0);
    ::dup2(out[1], 1);
    ::dup2(err[1], 2);
    ::alarm(60);
    if (limit_mb) {
      const rlimit limit{rlim_t(limit_mb) << 20, rlim_t(limit_mb) << 20};
      if (::setrlimit(RLIMIT_AS, &limit) != 0) ::_exit(126);
    }
    std::vector<std::string> all{nmbake::build::nmview_exe()};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (const std::string& a : all) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(out[1]);
  ::close(err[1]);
  Finished f;
  char buf[4096];
  if (!closed_stdout) {
    for (ssize_t n; (n = ::read(out[0], buf, sizeof buf)) > 0;) f.out.append(buf, std::size_t(n));
    ::close(out[0]);
  }
  for (ssize_t n; (n = ::read(err[0], buf, sizeof buf)) > 0;) f.err.append(buf, std::size_t(n));
  ::close(err[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  f.signalled = WIFSIGNALED(status);
  f.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return f;
}

// The error is the one last stderr line, "error: <what>"; notes ("nmview: ...") may come first.
void expect_error(const Finished& f, int code, const std::string& line) {
  EXPECT_FALSE(f.signalled) << "killed by a signal: " << f.err;
  EXPECT_EQ(f.code, code) << f.err;
  std::istringstream in(f.err);
  std::vector<std::string> errors;
  for (std::string l; std::getline(in, l);)
    if (l.rfind("nmview: ", 0) != 0) errors.push_back(l);
  ASSERT_EQ(errors.size(), 1u) << "expected one error line:\n" << f.err;
  EXPECT_EQ(errors[0], line);
}

struct SphereScene {
  std::string dir, low, high, map;
};

SphereScene make_sphere_scene() {
  SphereScene s;
  s.dir = nmbake::test::scratch_dir();
  s.low = s.dir + "/low.obj";
  s.high = s.dir + "/high.obj";
  s.map = s.dir + "/map.png";
  nmview::test::write_uv_sphere(s.low, 16, 8);
  nmview::test::write_uv_sphere(s.high, 32, 16);
  nmview::test::write_flat_map(s.map, 64, 32);
  return s;
}

std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

TEST(NmviewHostile, FifoMapIsRefusedAtOnce) {
  const SphereScene s = make_sphere_scene();
  ASSERT_EQ(::mkfifo((s.dir + "/fifo.png").c_str(), 0600), 0);
  expect_error(run_nmview(s.dir, {s.low, "fifo.png", s.high, "--compare"}), 2, "error: fifo.png: not a regular file (a FIFO)");
}

TEST(NmviewHostile, LinkToAFifoIsRefused) {
  const SphereScene s = make_sphere_scene();
  ASSERT_EQ(::mkfifo((s.dir + "/fifo").c_str(), 0600), 0);
  ASSERT_EQ(::symlink("fifo", (s.dir + "/link.png").c_str()), 0);
  expect_error(run_nmview(s.dir, {s.low, "link.png", s.high, "--compare"}), 2, "error: link.png: not a regular file (a FIFO)");
}

TEST(NmviewHostile, DeviceMapIsRefused) {
  const SphereScene s = make_sphere_scene();
  expect_error(run_nmview(s.dir, {s.low, "/dev/zero", s.high, "--compare"}), 2,
               "error: /dev/zero: not a regular file (a character device)");
}

TEST(NmviewHostile, FifoMeshesAreRefused) {
  const SphereScene s = make_sphere_scene();
  ASSERT_EQ(::mkfifo((s.dir + "/fifo.obj").c_str(), 0600), 0);
  expect_error(run_nmview(s.dir, {"fifo.obj", s.map, s.high, "--compare"}), 2, "error: fifo.obj: is not a regular file");
  expect_error(run_nmview(s.dir, {s.low, s.map, "/dev/zero", "--compare"}), 2, "error: /dev/zero: is not a regular file");
}

TEST(NmviewHostile, HeaderLargerThanItsFileIsRefused) {
  const SphereScene s = make_sphere_scene();
  write_png_header(s.dir + "/big.png", 20000, 20000, 100);
  expect_error(run_nmview(s.dir, {s.low, "big.png", s.high, "--compare"}), 4,
               "error: big.png: header says 20000x20000 pixels (4.8 GB) but the file has 157 bytes");
}

// A closed stdout loses the messages and changes nothing else (io/output_files.h): the status is
// the work's, never a SIGPIPE death (the three commands' streams: tests/test_closed_stdout.cpp).
TEST(NmviewOutputs, ClosedStdoutLosesOnlyTheMessages) {
  const SphereScene s = make_sphere_scene();
  const Finished f = run_nmview(s.dir, {s.low, s.map, s.high, "--compare", "--size", "200x100"}, true);
  EXPECT_FALSE(f.signalled) << "killed by a signal";
  EXPECT_EQ(f.code, 0) << f.err;
  EXPECT_EQ(f.err.find("error:"), std::string::npos) << f.err;
}

TEST(NmviewOutputs, CompareWritesNoImageUnlessAsked) {
  const SphereScene s = make_sphere_scene();
  const std::string work = s.dir + "/work";
  fs::create_directories(work);
  Finished f = run_nmview(work, {s.low, s.map, s.high, "--compare", "--size", "200x100"});
  ASSERT_EQ(f.code, 0) << f.err;
  EXPECT_NE(f.out.find("psnr="), std::string::npos) << f.out;
  EXPECT_TRUE(files_in(work).empty()) << "--compare left " << files_in(work).front() << " in the current folder";

  f = run_nmview(work, {s.low, s.map, s.high, "--compare", "--size", "200x100", "--screenshot", s.dir + "/worst.png"});
  ASSERT_EQ(f.code, 0) << f.err;
  EXPECT_TRUE(fs::exists(s.dir + "/worst.png"));
  EXPECT_NE(f.err.find("worst view written to " + s.dir + "/worst.png"), std::string::npos) << f.err;
  EXPECT_TRUE(files_in(work).empty());
}

// Under ulimit -v a map whose pixels the limit cannot hold is exit 4 with one line and no image,
// where the same scene with a map that fits renders. (Far below 2 GB the software renderer itself
// may run out, and below ~500 MB the libraries cannot load: README, "Exit codes and errors".)
TEST(NmviewLimits, UnderUlimitAMapTooBigForItIsExitFour) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "ulimit -v and AddressSanitizer do not mix (it reserves terabytes of shadow memory)";
#endif
  const SphereScene s = make_sphere_scene();
  // 20000^2 RGB in 4 MB of pixel data: a size the file could hold, 4.8 GB of floats.
  write_png_header(s.dir + "/plausible.png", 20000, 20000, 4u << 20);
  const std::string shot = s.dir + "/shot.png";
  const Finished big =
      run_nmview(s.dir, {s.low, "plausible.png", s.high, "--size", "200x100", "--screenshot", shot}, false, 2000);
  EXPECT_FALSE(big.signalled);
  EXPECT_EQ(big.code, 4) << big.err;
  EXPECT_FALSE(fs::exists(shot)) << "an image was left after exit 4";
  EXPECT_EQ(big.err.rfind("error: plausible.png: header says 20000x20000 pixels (4.8 GB; ", 0), 0u) << big.err;
  EXPECT_NE(big.err.find("exceeds the memory budget"), std::string::npos) << big.err;
  EXPECT_EQ(std::count(big.err.begin(), big.err.end(), '\n'), 1) << big.err;
  const Finished fits = run_nmview(s.dir, {s.low, s.map, s.high, "--size", "200x100", "--screenshot", shot}, false, 2000);
  EXPECT_EQ(fits.code, 0) << fits.err;
  EXPECT_TRUE(fs::exists(shot));
}

}  // namespace
