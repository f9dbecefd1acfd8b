// The nmbake command's progress line (issue 22, item 5): its text (stage, fraction, time since the
// start, time left once the stage has run a second), and the command drawing it only on a terminal
// or with --progress, never with --quiet, naming every stage and leaving the line cleared.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/progress.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::contains;
using test::run_nmbake;

TEST(ProgressText, StageWithoutFractionGivesTheElapsedTime) {
  EXPECT_EQ(progress_text("building the BVH", -1.0, 1.234, 0.5), "nmbake: building the BVH, 1.2 s");
  EXPECT_EQ(progress_text("loading", -1.0, 0.0, 0.0), "nmbake: loading, 0.0 s");
  EXPECT_EQ(progress_text("writing", -1.0, 125.0, 3.0), "nmbake: writing, 2 min 5 s");
}

TEST(ProgressText, TimeLeftOnlyAfterTheFirstSecond) {
  // 25% done after 0.9 s of tracing: too early to say.
  EXPECT_EQ(progress_text("tracing", 0.25, 1.4, 0.9), "nmbake: tracing  25% [#######.......................] 1.4 s");
  // 25% after 2 s: 6 s left; 50% after 3 s: 3 s left.
  EXPECT_EQ(progress_text("tracing", 0.25, 2.5, 2.0),
            "nmbake: tracing  25% [#######.......................] 2.5 s, about 6.0 s left");
  EXPECT_EQ(progress_text("tracing", 0.5, 12.0, 30.0),
            "nmbake: tracing  50% [###############...............] 12 s, about 30 s left");
  // Done, or nothing done yet: no estimate.
  EXPECT_EQ(progress_text("tracing", 1.0, 4.0, 3.0), "nmbake: tracing 100% [##############################] 4.0 s");
  EXPECT_EQ(progress_text("tracing", 0.0, 4.0, 3.0), "nmbake: tracing   0% [..............................] 4.0 s");
  // Out of range fractions are clamped.
  EXPECT_EQ(progress_text("tracing", 7.0, 1.0, 0.5), progress_text("tracing", 1.0, 1.0, 0.5));
}

// The lines drawn, split at carriage returns, blanks left out.
std::vector<std::string> drawn(const std::string& err) {
  std::vector<std::string> lines;
  std::string line;
  for (char c : err + "\r") {
    if (c != '\r' && c != '\n') {
      line += c;
      continue;
    }
    if (line.find_first_not_of(' ') != std::string::npos) lines.push_back(line.substr(0, line.find_last_not_of(' ') + 1));
    line.clear();
  }
  return lines;
}

// What a terminal shows on its last line after `err`: a carriage return moves back to the start of
// the line, characters overwrite what is there.
std::string last_terminal_line(const std::string& err) {
  std::string line;
  std::size_t at = 0;
  for (char c : err) {
    if (c == '\n') {
      line.clear();
      at = 0;
    } else if (c == '\r') {
      at = 0;
    } else {
      if (at < line.size()) line[at] = c;
      else line += c;
      ++at;
    }
  }
  return line;
}

TEST(ProgressLine, WithProgressEveryStageIsNamedAndTheLineCleared) {
  const test::CliRun r =
      run_nmbake(test::sample_low() + " " + test::sample_high() + " -o out.png --size 256 --estimate-error --progress");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<std::string> lines = drawn(r.err);
  for (const char* stage : {"loading", "preparing", "building the BVH", "measuring distances", "tracing", "padding",
                            "estimating the error", "writing"}) {
    bool seen = false;
    for (const std::string& l : lines) seen = seen || l.rfind(std::string("nmbake: ") + stage, 0) == 0;
    EXPECT_TRUE(seen) << "no progress line names '" << stage << "':\n" << r.err;
  }
  EXPECT_TRUE(contains(r.err, "nmbake: tracing 100% [##############################] ")) << r.err;
  // The line is cleared at the end: on a terminal, the last line shows nothing.
  EXPECT_EQ(last_terminal_line(r.err).find_first_not_of(' '), std::string::npos)
      << "the progress line was left on stderr: '" << last_terminal_line(r.err) << "'";
  // The other lines are whole lines: the distances and the error estimate each start a line.
  EXPECT_TRUE(contains(r.err, "\rnmbake: automatic cage: ")) << r.err;
  EXPECT_TRUE(contains(r.err, "\rnmbake: error estimate: ")) << r.err;
}

TEST(ProgressLine, OffWhenStderrIsNotATerminalAndWithQuiet) {
  const test::CliRun plain = run_nmbake(test::sample_low() + " " + test::sample_high() + " -o out.png --size 64");
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_FALSE(contains(plain.err, "\r")) << plain.err;
  EXPECT_TRUE(contains(plain.err, "nmbake: automatic cage: ")) << plain.err;
  const test::CliRun quiet =
      run_nmbake(test::sample_low() + " " + test::sample_high() + " -o out.png --size 64 --progress --quiet");
  ASSERT_EQ(quiet.code, 0) << quiet.err;
  EXPECT_EQ(quiet.err, "");
}

}  // namespace
}  // namespace nmbake
