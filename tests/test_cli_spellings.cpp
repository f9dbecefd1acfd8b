// The common spellings nmbake accepts beside its own values (issue 36, item 6; cli/spellings.h):
// --size 1k, 2k, 4k, 8k (x 1024, any case, on either side of WxH) and --green dx/directx and
// gl/opengl (any case) for down and up. Other values are refused with the messages they had.
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <gtest/gtest.h>

#include "cli/args.h"
#include "cli/spellings.h"
#include "core/errors.h"
#include "test_support.h"

namespace {

using nmbake::test::CliRun;
using nmbake::test::contains;
using nmbake::test::read_file;
using nmbake::test::run_nmbake;

TEST(CliSpellings, SizeTakesMultiplesOf1024) {
  const struct {
    const char* text;
    int width, height;
  } cases[] = {{"1k", 1024, 1024},    {"2k", 2048, 2048},    {"4k", 4096, 4096}, {"8k", 8192, 8192},    {"4K", 4096, 4096},
               {"1kx512", 1024, 512}, {"4Kx2k", 4096, 2048}, {"512", 512, 512},  {"300X200", 300, 200}, {"16k", 16384, 16384}};
  for (const auto& c : cases) {
    nmbake::Args a;
    a.size = c.text;
    const nmbake::BakeOptions o = nmbake::bake_options(a);
    EXPECT_EQ(o.width, c.width) << c.text;
    EXPECT_EQ(o.height, c.height) << c.text;
  }
  for (const char* bad : {"4kk", "1.5k", "k", "-1k", "+4k", "4 k", " 4k", "4m", "4kb", "x4k", "4kx", "kx1"}) {
    nmbake::Args a;
    a.size = bad;
    try {
      nmbake::bake_options(a);
      ADD_FAILURE() << "--size " << bad << " accepted";
    } catch (const nmbake::UsageError& e) {
      EXPECT_EQ(std::string(e.what()), "--size: expected N or WxH with whole numbers, got '" + std::string(bad) + "'");
    }
  }
}

// --green's value after CLI11 has parsed `value`, or the parse error's text.
std::string parsed_green(const std::string& value) {
  CLI::App app;
  nmbake::Args a;
  nmbake::add_options(app, a);
  try {
    app.parse("low.obj high.obj -o m.png --green " + value, false);
  } catch (const CLI::ParseError& e) {
    return std::string("error: ") + e.what();
  }
  return a.green;
}

TEST(CliSpellings, GreenTakesDirectXAndOpenGlNames) {
  for (const char* down : {"down", "dx", "DX", "directx", "DirectX", "DOWN"}) EXPECT_EQ(parsed_green(down), "down") << down;
  for (const char* up : {"up", "gl", "GL", "opengl", "OpenGL", "Up"}) EXPECT_EQ(parsed_green(up), "up") << up;
  // Others: the message of before, the value as given.
  for (const char* bad : {"y-", "d", "dx11", "ogl"})
    EXPECT_EQ(parsed_green(bad), "error: --green: " + std::string(bad) + " not in {up,down}") << bad;
  EXPECT_EQ(nmbake::canonical_green("Y+"), "Y+");
}

// The whole command: the spellings bake what the values they stand for bake, and a refused one is
// exit 1 with one line.
TEST(CliSpellings, CommandBakesTheSameMapForEitherSpelling) {
  const std::string pair = "'" + nmbake::test::sample_low() + "' '" + nmbake::test::sample_high() + "'";
  const CliRun dx = run_nmbake(pair + " -o m.png --size 1kx16 --green DX --threads 2 --report r.json");
  ASSERT_EQ(dx.code, 0) << dx.err;
  EXPECT_EQ(dx.report["options"]["green"], "down") << dx.report["options"].dump();
  EXPECT_EQ(dx.report["options"]["size"], nlohmann::json::array({1024, 16})) << dx.report["options"].dump();
  const CliRun down = run_nmbake(pair + " -o m.png --size 1024x16 --green down --threads 2");
  ASSERT_EQ(down.code, 0) << down.err;
  EXPECT_EQ(read_file(dx.dir + "/m.png"), read_file(down.dir + "/m.png"));

  const CliRun bad = run_nmbake(pair + " -o m.png --size 2q");
  EXPECT_EQ(bad.code, 1);
  EXPECT_EQ(bad.err, "error: --size: expected N or WxH with whole numbers, got '2q'\n");
  const CliRun bad_green = run_nmbake(pair + " -o m.png --green yplus");
  EXPECT_EQ(bad_green.code, 1);
  EXPECT_EQ(bad_green.err, "error: --green: yplus not in {up,down} (see nmbake --help)\n");
}

// The jobs file --help shows is one nmbake --batch takes: valid JSON, its fields those of a jobs file.
TEST(CliHelp, BatchExampleIsAJobsFile) {
  const std::string text = nmbake::kBatchExample;
  const std::size_t begin = text.find('{'), end = text.rfind('}');
  ASSERT_NE(begin, std::string::npos);
  const nlohmann::json jobs = nlohmann::json::parse(text.substr(begin, end - begin + 1));
  ASSERT_TRUE(jobs["jobs"].is_array());
  EXPECT_EQ(jobs["jobs"].size(), 2u);
  EXPECT_TRUE(jobs["defaults"].is_object());
  for (const nlohmann::json& job : jobs["jobs"]) {
    EXPECT_TRUE(job["low"].is_string()) << job.dump();
    EXPECT_TRUE(job["output"].is_string()) << job.dump();
    EXPECT_TRUE(job.contains("high") || job.contains("highs")) << job.dump();
  }
  // Its fields and options pass the batch's checks: each job fails only on its missing meshes.
  const std::string dir = nmbake::test::scratch_dir();
  nmbake::test::write_file(dir + "/jobs.json", text.substr(begin, end - begin + 1));
  const CliRun run = run_nmbake("--batch jobs.json", "", dir);
  EXPECT_EQ(run.code, 2) << run.err;
  EXPECT_TRUE(contains(run.err, "job 1 (crate_normal.png): crate_low.fbx: cannot open")) << run.err;
  EXPECT_TRUE(contains(run.err, "job 2 (lid_dx.tga): lid_low.fbx: cannot open")) << run.err;
  EXPECT_TRUE(contains(run_nmbake("--help").out, text)) << "nmbake --help shows the example";
  EXPECT_TRUE(contains(run_nmbake("--batch --help").out, text)) << "nmbake --batch --help shows the example";
}

}  // namespace
