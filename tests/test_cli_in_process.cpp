// The tests run the nmbake command in their own process (test_support.h, run_nmbake; the lists of
// hostile inputs through nmbake_cases): check that this is the binary's behaviour, and that the
// command line is split as bash splits it.
#include <cstdlib>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"

namespace {

using nmbake::test::CliRun;
using nmbake::test::read_file;
using nmbake::test::run_nmbake;
using nmbake::test::shell_words;

TEST(ShellWords, SplitsAsBashDoes) {
  EXPECT_EQ(shell_words("a  b\tc"), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(shell_words("-o 't_<MAP>.png' \"x y\" ''"), (std::vector<std::string>{"-o", "t_<MAP>.png", "x y", ""}));
  EXPECT_EQ(shell_words("a\\ b 'c'd"), (std::vector<std::string>{"a b", "cd"}));
  EXPECT_TRUE(shell_words("   ").empty());
  for (const char* bad : {"a | b", "a > f", "a; b", "$HOME", "*.png", "'open", "\"$x\""})
    EXPECT_THROW(shell_words(bad), std::invalid_argument) << bad;
}

// A command's printout without its stage times.
std::string untimed(const std::string& text) { return std::regex_replace(text, std::regex(", seconds:[^\n]*"), ""); }

// The same bake and the same refusals, in this process and through the binary: same status, same
// stdout and stderr (but for the stage times), same map bytes.
TEST(CliInProcess, SameAsTheBinary) {
  const std::string pair = "'" + nmbake::test::sample_low() + "' '" + nmbake::test::sample_high() + "'";
  for (const std::string& args : {pair + " -o m.png --size 64 --threads 2", pair + " -o m.png --size 0",
                                  "missing.obj " + pair.substr(pair.find(' ') + 1) + " -o m.png"}) {
    const CliRun here = run_nmbake(args);
    const std::string map_here = read_file(here.dir + "/m.png");
    ::setenv("NMBAKE_TEST_PROCESS", "1", 1);
    const CliRun binary = run_nmbake(args);
    ::unsetenv("NMBAKE_TEST_PROCESS");
    EXPECT_EQ(here.code, binary.code) << args;
    EXPECT_EQ(untimed(here.out), untimed(binary.out)) << args;
    EXPECT_EQ(here.err, binary.err) << args;
    EXPECT_EQ(map_here, read_file(binary.dir + "/m.png")) << args;
  }
  const CliRun ok = run_nmbake(pair + " -o m.png --size 64");
  EXPECT_EQ(ok.code, 0);
  EXPECT_GT(read_file(ok.dir + "/m.png").size(), 100u);
}

}  // namespace
