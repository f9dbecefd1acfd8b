// The shell of the three commands (cli/shell.h): one mapping from errors to exit statuses and one
// error line, and the one-line form of a message (core/errors.h).
#include <gtest/gtest.h>

#include <new>
#include <stdexcept>
#include <system_error>
#include <CLI/CLI.hpp>

#include "cli/shell.h"
#include "core/errors.h"

using namespace nmbake;

namespace {

template <typename E>
Failure fail_with(const E& error, const ExitStatuses& statuses = {}, const char* const* doing = nullptr) {
  return failure_of(std::make_exception_ptr(error), statuses, doing);
}

const ExitStatuses kNmdiff{2, 2, 3, 4};  // nmdiff: 1 is "outside tolerance"

}  // namespace

TEST(Shell, EachErrorKindHasItsStatus) {
  EXPECT_EQ(fail_with(UsageError("--size: bad")).status, 1);
  EXPECT_EQ(fail_with(InputError("low.obj: line 3: bad")).status, 2);
  EXPECT_EQ(fail_with(OutputError("out.png: cannot write")).status, 3);
  EXPECT_EQ(fail_with(ResourceError("--size 65536 refused")).status, 4);
  EXPECT_EQ(fail_with(Error(ExitCode::strict, "--strict: 1 warning")).status, 5);
  EXPECT_EQ(fail_with(std::bad_alloc()).status, 4);
  EXPECT_EQ(fail_with(std::system_error(std::make_error_code(std::errc::resource_unavailable_try_again))).status, 4);
  EXPECT_EQ(fail_with(std::system_error(std::make_error_code(std::errc::not_enough_memory))).status, 4);
  EXPECT_EQ(fail_with(std::system_error(std::make_error_code(std::errc::permission_denied))).status, 2);
  EXPECT_EQ(fail_with(std::logic_error("x")).status, 2);
  EXPECT_EQ(failure_of(std::make_exception_ptr(42)).status, 2);
}

TEST(Shell, NmdiffMapsABadCommandLineToTwo) {
  EXPECT_EQ(fail_with(UsageError("bad"), kNmdiff).status, 2);
  EXPECT_EQ(fail_with(InputError("bad"), kNmdiff).status, 2);
  EXPECT_EQ(fail_with(OutputError("bad"), kNmdiff).status, 3);
  EXPECT_EQ(fail_with(std::bad_alloc(), kNmdiff).status, 4);
}

TEST(Shell, MessagesAreOneLine) {
  EXPECT_EQ(fail_with(InputError("a.png: bad\nheader\r\n")).message, "a.png: bad header");
  EXPECT_EQ(fail_with(std::runtime_error("")).message, "unknown error");
  EXPECT_EQ(failure_of(std::make_exception_ptr(42)).message, "unknown error");
  EXPECT_EQ(fail_with(std::bad_alloc()).message, "out of memory");
  const char* doing = "writing the outputs";
  EXPECT_EQ(fail_with(std::bad_alloc(), {}, &doing).message, "out of memory while writing the outputs");
  const char* nothing = nullptr;
  EXPECT_EQ(fail_with(std::bad_alloc(), {}, &nothing).message, "out of memory");
  EXPECT_EQ(fail_with(std::system_error(std::make_error_code(std::errc::not_enough_memory), "thread"))
                .message.rfind("out of memory: thread", 0),
            0u);
}

TEST(Shell, RunCommandReturnsTheWorksStatusOrTheErrors) {
  EXPECT_EQ(run_command([] { return 7; }), 7);
  EXPECT_EQ(run_command([]() -> int { throw OutputError("x"); }), 3);
  EXPECT_EQ(run_command([]() -> int { throw UsageError("x"); }, kNmdiff), 2);
}

TEST(Shell, ParsingStopsForHelpAndRefusesBadCommandLines) {
  CLI::App app{"test"};
  int n = 0;
  app.add_option("--n", n);
  char tool[] = "tool", help[] = "--help", opt[] = "--n", three[] = "3", bad[] = "--bad";
  char* argv_ok[] = {tool, opt, three};
  EXPECT_EQ(parse_command_line(app, 3, argv_ok, "tool"), std::nullopt);
  EXPECT_EQ(n, 3);
  char* argv_help[] = {tool, help};
  testing::internal::CaptureStdout();
  EXPECT_EQ(parse_command_line(app, 2, argv_help, "tool"), std::optional<int>(0));
  testing::internal::GetCapturedStdout();
  char* argv_bad[] = {tool, bad};
  try {
    parse_command_line(app, 2, argv_bad, "tool");
    FAIL() << "no UsageError";
  } catch (const UsageError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("--bad"), std::string::npos) << what;
    EXPECT_NE(what.find("(see tool --help)"), std::string::npos) << what;
  }
}

TEST(OneLine, CollapsesBlanksAndCutsOnlyWithALimit) {
  EXPECT_EQ(one_line("  a\n\n b\t\tc \r\n"), "a b c");
  EXPECT_EQ(one_line(std::string("x\x01y", 3)), "x?y");
  EXPECT_EQ(one_line(std::string(300, 'x')), std::string(300, 'x'));
  EXPECT_EQ(one_line("abcdefgh", 6), "abc...");
  EXPECT_EQ(one_line(""), "");
}
