// The output contract of the three commands (baker/io/output_files.h; nmbake's set with its
// interruption check, baker/cli/outputs.h): files compared by identity, outputs that are refused,
// temporaries removed, all renamed together or none, stale temporaries cleaned; the standard
// streams and a file size limit (ulimit -f) that cannot break it.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/outputs.h"
#include "core/errors.h"
#include "io/text_file.h"
#include "pipeline/bake.h"
#include "test_support.h"

namespace nmbake {
namespace {

namespace fs = std::filesystem;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void put(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// The names in a folder, sorted.
std::vector<std::string> listing(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// A pid no process has: a child that has exited and been reaped.
pid_t dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return child;
}

TEST(Outputs, SameFileByIdentity) {
  const std::string d = test::scratch_dir();
  put(d + "/a.obj", "a");
  fs::create_symlink("a.obj", d + "/link.obj");
  fs::create_hard_link(d + "/a.obj", d + "/hard.obj");
  fs::create_directory(d + "/sub");
  EXPECT_TRUE(same_file(d + "/a.obj", d + "/link.obj"));
  EXPECT_TRUE(same_file(d + "/a.obj", d + "/hard.obj"));
  EXPECT_TRUE(same_file(d + "/a.obj", d + "/sub/../a.obj"));
  EXPECT_TRUE(same_file(d + "/new.png", d + "/./new.png"));       // neither exists yet
  EXPECT_TRUE(same_file(d + "/new.png", d + "/sub/../new.png"));  // nor here
  EXPECT_FALSE(same_file(d + "/a.obj", d + "/b.obj"));
  EXPECT_FALSE(same_file(d + "/new.png", d + "/new2.png"));
}

TEST(Outputs, RefusedOutputs) {
  const std::string d = test::scratch_dir();
  put(d + "/low.obj", "low");
  fs::create_symlink("/dev/full", d + "/full.png");
  fs::create_symlink("nothing.png", d + "/dangling.png");
  const std::vector<NamedFile> inputs{{"", d + "/low.obj", "the low-poly"}};
  auto code_of = [&](const std::vector<NamedFile>& outputs, std::string* message) {
    try {
      check_output_files(inputs, outputs);
    } catch (const Error& e) {
      *message = e.what();
      return int(e.code());
    }
    return 0;
  };
  std::string m;
  EXPECT_EQ(code_of({{"--report", d + "/low.obj", "the report"}}, &m), 1);
  EXPECT_EQ(m, "--report " + d + "/low.obj is the same file as " + d + "/low.obj; nothing written");
  EXPECT_EQ(code_of({{"--output", d + "/m.png", "the map"}, {"--miss-mask", d + "/./m.png", "the miss mask"}}, &m), 1);
  EXPECT_EQ(m, "--miss-mask " + d + "/./m.png is the same file as " + d + "/m.png; nothing written");
  EXPECT_EQ(code_of({{"--output", d + "/full.png", "the map"}}, &m), 3);
  EXPECT_NE(m.find("it is a symbolic link to a character device (/dev/full)"), std::string::npos) << m;
  EXPECT_EQ(code_of({{"--output", d + "/dangling.png", "the map"}}, &m), 3);
  EXPECT_NE(m.find("a symbolic link to a missing file"), std::string::npos) << m;
  EXPECT_EQ(code_of({{"--output", d, "the map"}}, &m), 3);
  EXPECT_NE(m.find("it is a directory"), std::string::npos) << m;
  EXPECT_EQ(code_of({{"--output", d + "/" + std::string(236, 'x') + ".png", "the map"}}, &m), 3);
  EXPECT_NE(m.find("its name is 240 bytes long, more than the 235 that leave room for its temporary file"), std::string::npos)
      << m;
  EXPECT_EQ(code_of({{"--output", d + "/" + std::string(235, 'x'), "the map"}}, &m), 0) << m;
  EXPECT_EQ(code_of({{"--output", d + "/no/such/m.png", "the map"}}, &m), 3);
  EXPECT_NE(m.find("does not exist"), std::string::npos) << m;
  EXPECT_EQ(code_of({{"--output", d + "/m.png", "the map"}, {"--report", "", "the report"}}, &m), 0) << m;
}

TEST(Outputs, CommitRenamesAllTogether) {
  const std::string d = test::scratch_dir();
  put(d + "/a.png", "old a");
  ::chmod((d + "/a.png").c_str(), 0640);
  fs::create_symlink("a.png", d + "/link.png");
  {
    OutputSet set;
    write_text_file(d + "/link.png", set.add(d + "/link.png"), "new a");
    write_text_file(d + "/b.json", set.add(d + "/b.json"), "new b");
    EXPECT_EQ(slurp(d + "/a.png"), "old a");  // nothing visible before the commit
    EXPECT_FALSE(test::exists(d + "/b.json"));
    set.commit([] { return false; });
  }
  EXPECT_EQ(slurp(d + "/a.png"), "new a");
  EXPECT_EQ(slurp(d + "/b.json"), "new b");
  EXPECT_TRUE(fs::is_symlink(d + "/link.png"));  // written through
  struct stat st {};
  ASSERT_EQ(::stat((d + "/a.png").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0640u);  // the old file's permissions
  EXPECT_EQ(listing(d), (std::vector<std::string>{"a.png", "b.json", "link.png"}));
}

TEST(Outputs, UncommittedOrCancelledSetChangesNothing) {
  const std::string d = test::scratch_dir();
  put(d + "/a.png", "old a");
  {
    OutputSet set;
    write_text_file(d + "/a.png", set.add(d + "/a.png"), "new a");
    write_text_file(d + "/b.json", set.add(d + "/b.json"), "new b");
  }
  EXPECT_EQ(listing(d), (std::vector<std::string>{"a.png"}));
  EXPECT_EQ(slurp(d + "/a.png"), "old a");
  {
    OutputSet set;
    write_text_file(d + "/a.png", set.add(d + "/a.png"), "new a");
    EXPECT_THROW(set.commit([] { return true; }), Cancelled);
  }
  EXPECT_EQ(listing(d), (std::vector<std::string>{"a.png"}));
  EXPECT_EQ(slurp(d + "/a.png"), "old a");
}

// A rename that fails half way (the last output's name is taken by a folder with a file in it,
// made after the checks) puts back the old files of those already renamed.
TEST(Outputs, FailedRenameRollsBack) {
  const std::string d = test::scratch_dir();
  put(d + "/a.png", "old a");
  OutputSet set;
  write_text_file(d + "/a.png", set.add(d + "/a.png"), "new a");
  write_text_file(d + "/b.png", set.add(d + "/b.png"), "new b");  // no old b
  write_text_file(d + "/c.json", set.add(d + "/c.json"), "new c");
  fs::create_directory(d + "/c.json");
  put(d + "/c.json/keep", "x");
  try {
    set.commit([] { return false; });
    ADD_FAILURE() << "the commit should fail";
  } catch (const OutputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(d + "/c.json: cannot write: ", 0), 0u) << e.what();
  }
  EXPECT_EQ(slurp(d + "/a.png"), "old a");
  EXPECT_FALSE(test::exists(d + "/b.png"));
  EXPECT_EQ(listing(d), (std::vector<std::string>{"a.png", "c.json"}));
}

// Temporaries of a process that no longer exists are removed when the same output is written;
// a live process's, and other outputs', are not. An old copy that is a second name of the output
// goes too; one that differs from it is the only copy of an old output and stays.
TEST(Outputs, StaleTemporariesRemoved) {
  const std::string d = test::scratch_dir();
  const std::string dead = std::to_string(dead_pid()), alive = std::to_string(::getppid());
  const std::string dead2 = std::to_string(dead_pid());
  put(d + "/m.png", "current");
  ASSERT_EQ(::link((d + "/m.png").c_str(), (d + "/.m.png.nmbake-old." + dead).c_str()), 0);
  put(d + "/.m.png.nmbake-old." + dead2, "the only old copy");
  for (const std::string& name : {".m.png.nmbake-tmp." + dead, ".m.png.nmbake-tmp." + dead + ".3", ".m.png.nmbake-tmp." + alive,
                                  ".n.png.nmbake-tmp." + dead, ".m.png.nmbake-tmp.x" + dead})
    put(d + "/" + name, "stale");
  OutputSet set;
  const std::string temp = set.add(d + "/m.png");
  EXPECT_EQ(temp, d + "/.m.png.nmbake-tmp." + std::to_string(::getpid()));
  std::vector<std::string> kept{".m.png.nmbake-tmp." + alive, ".m.png.nmbake-tmp." + dead + ".3", ".m.png.nmbake-tmp.x" + dead,
                                ".n.png.nmbake-tmp." + dead,  ".m.png.nmbake-old." + dead2,       "m.png"};
  std::sort(kept.begin(), kept.end());
  EXPECT_EQ(listing(d), kept);
}

// The exit status of `body` run in a child process (0..255), or 128 + the signal that killed it.
template <typename Body>
int in_child(Body body) {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(body());
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// Closed stdout and stderr are reopened on /dev/null: the next file opened does not get their
// numbers (it would receive the messages), and SIGPIPE and SIGXFSZ are ignored.
TEST(Outputs, ClosedStandardStreamsAreReopened) {
  const std::string d = test::scratch_dir();
  const int code = in_child([&] {
    ::close(1);
    ::close(2);
    protect_standard_streams();
    const int fd = ::open((d + "/file").c_str(), O_WRONLY | O_CREAT, 0644);
    if (fd <= 2) return 1;                                             // took a standard stream's number
    if (::write(1, "x", 1) != 1 || ::write(2, "x", 1) != 1) return 2;  // not /dev/null
    struct sigaction pipe {
    }, size{};
    ::sigaction(SIGPIPE, nullptr, &pipe);
    ::sigaction(SIGXFSZ, nullptr, &size);
    return pipe.sa_handler == SIG_IGN && size.sa_handler == SIG_IGN ? 0 : 3;
  });
  EXPECT_EQ(code, 0);
  EXPECT_EQ(test::read_file(d + "/file"), "");
}

// Under a file size limit (ulimit -f) a write past it is an OutputError naming the file, not a
// SIGXFSZ death: the temporary removed, the old file as it was.
TEST(Outputs, FileSizeLimitIsAnOutputError) {
  const std::string d = test::scratch_dir();
  put(d + "/r.json", "old");
  const int code = in_child([&] {
    protect_standard_streams();
    const struct rlimit limit { 1024, 1024 };
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) return 10;
    OutputFiles set;
    try {
      write_text_file(d + "/r.json", set.add(d + "/r.json"), std::string(4096, 'x'));
    } catch (const OutputError& e) {
      return std::string(e.what()) == d + "/r.json: cannot write: File too large" ? 0 : 1;
    }
    return 2;
  });
  EXPECT_EQ(code, 0) << "1: another message, 2: no error, 128 + 25: killed by SIGXFSZ";
  EXPECT_EQ(listing(d), std::vector<std::string>{"r.json"});
  EXPECT_EQ(slurp(d + "/r.json"), "old");
}

// A file written from spans: more of them than one writev takes (1024), empty ones among them, and
// spans that are parts of one buffer, in order; the same bytes as the buffer joined. Under a file
// size limit that cuts it inside a later call, an error and no file.
TEST(Outputs, SpansWrittenInOrder) {
  const std::string d = test::scratch_dir();
  std::string joined;
  std::vector<std::string> parts;
  for (int i = 0; i < 3000; ++i)
    parts.push_back(i % 7 == 3 ? std::string() : std::string(std::size_t(i % 13 + 1), char('a' + i % 26)));
  std::vector<ByteSpan> spans;
  for (const std::string& p : parts) {
    spans.push_back({p.data(), p.size()});
    joined += p;
  }
  write_spans_file(d + "/s.bin", d + "/s.bin", spans);
  EXPECT_EQ(slurp(d + "/s.bin"), joined);
  write_spans_file(d + "/e.bin", d + "/e.bin", {});
  EXPECT_EQ(slurp(d + "/e.bin"), "");
  const int code = in_child([&] {
    protect_standard_streams();
    const struct rlimit limit { 9000, 9000 };  // past the first call's spans
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) return 10;
    try {
      write_spans_file(d + "/c.bin", d + "/.c.tmp", spans);
    } catch (const OutputError& e) {
      return std::string(e.what()) == d + "/c.bin: cannot write: File too large" ? 0 : 1;
    }
    return 2;
  });
  EXPECT_EQ(code, 0) << "1: another message, 2: no error";
  EXPECT_FALSE(fs::exists(d + "/.c.tmp"));
  EXPECT_FALSE(fs::exists(d + "/c.bin"));
}

// In a child process that removes temporaries on signals (nmdiff's and nmview's;
// remove_temporaries_on_signals): `before`, then `path` written to a set not committed, then
// SIGTERM. The child's status: 128 + SIGTERM when the signal ended it.
template <typename Before>
int sigterm_while_writing(const std::string& path, Before before) {
  return in_child([&] {
    remove_temporaries_on_signals();
    before();
    OutputFiles set;
    write_text_file(path, set.add(path), "new");
    ::raise(SIGTERM);
    return 0;
  });
}

// SIGTERM while an output is written removes its temporary and ends the process; the old file stays.
TEST(Outputs, SignalRemovesTheTemporaries) {
  const std::string d = test::scratch_dir();
  put(d + "/m.png", "old");
  EXPECT_EQ(sigterm_while_writing(d + "/m.png", [] {}), 128 + SIGTERM);
  EXPECT_EQ(listing(d), std::vector<std::string>{"m.png"});
  EXPECT_EQ(slurp(d + "/m.png"), "old");
}

// A set committed or discarded is forgotten (the handler's room is fixed): after many sets, the
// temporary of the one being written is still removed.
TEST(Outputs, SignalAfterManySetsStillRemovesTheTemporary) {
  const std::string d = test::scratch_dir();
  const int code = sigterm_while_writing(d + "/n.png", [&] {
    for (int i = 0; i < 100; ++i) {
      OutputFiles set;
      write_text_file(d + "/m.png", set.add(d + "/m.png"), "new m");
      if (i % 2 == 0) set.commit();
    }
  });
  EXPECT_EQ(code, 128 + SIGTERM);
  EXPECT_EQ(listing(d), std::vector<std::string>{"m.png"});
  EXPECT_EQ(slurp(d + "/m.png"), "new m");
}

}  // namespace
}  // namespace nmbake
