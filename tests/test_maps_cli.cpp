// The texture set on the command line: --maps, <MAP> in -o (with <UDIM>), each map's metadata and
// report entry, and the refusals (exit 1, one line, nothing written).
#include <gtest/gtest.h>

#include <filesystem>

#include "io/image_io.h"
#include "test_support.h"

namespace nmbake {
namespace {

namespace fs = std::filesystem;

std::string sample_args() { return test::sample_low() + " " + test::sample_high() + " --size 64 --threads 2"; }

TEST(MapsCli, EveryMapToItsFileWithItsMetadataAndReport) {
  const test::CliRun r =
      test::run_nmbake(sample_args() + " --maps normal,ao,height,object-id --ao-rays 8 -o 't_<MAP>.png' --report r.json");
  ASSERT_EQ(r.code, 0) << r.err;
  for (const char* name : {"normal", "ao", "height", "object-id"})
    EXPECT_TRUE(test::exists(r.dir + "/t_" + name + ".png")) << name;
  EXPECT_FALSE(test::exists(r.dir + "/t_<MAP>.png"));
  const auto ao = read_image_metadata(r.dir + "/t_ao.png");
  ASSERT_TRUE(ao.count("nmbake:map"));
  EXPECT_EQ(ao.at("nmbake:map"), "ao");
  EXPECT_TRUE(ao.count("nmbake:ao_distance"));
  const auto height = read_image_metadata(r.dir + "/t_height.png");
  ASSERT_TRUE(height.count("nmbake:height_range"));
  EXPECT_EQ(read_image_metadata(r.dir + "/t_normal.png").at("nmbake:map"), "normal");
  ASSERT_TRUE(r.report.contains("maps"));
  ASSERT_EQ(r.report["maps"].size(), 4u);
  EXPECT_EQ(r.report["maps"][1]["map"], "ao");
  EXPECT_TRUE(r.report["maps"][1].contains("standard_error"));
  EXPECT_EQ(r.report["maps"][2]["height_range"].size(), 2u);
  EXPECT_EQ(r.report["maps"][3]["colors"].size(), 1u);
  EXPECT_TRUE(test::contains(r.err, "height map in 8 bits")) << r.err;  // the warning for 8-bit height
}

// --ao-rays auto: the report's entries say the mode, the threshold and the rays spent per texel.
TEST(MapsCli, AoRaysAutoReportsItsThresholdAndRays) {
  const test::CliRun r = test::run_nmbake(
      sample_args() + " --maps ao,bent-normal,thickness --ao-rays auto --max-ao-error 0.05 -o 't_<MAP>.png' --report r.json");
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_EQ(r.report["maps"].size(), 3u);
  for (const auto& m : r.report["maps"]) {
    EXPECT_EQ(m["rays_per_texel"], "auto") << m.dump();
    EXPECT_EQ(m["max_ao_error"], 0.05) << m.dump();
    ASSERT_TRUE(m.contains("rays")) << m.dump();
    EXPECT_GT(m["rays"]["mean"].get<double>(), 0.0) << m.dump();
    EXPECT_LE(m["rays"]["max"].get<double>(), 1024.0) << m.dump();
    EXPECT_GE(m["rays"]["max"].get<double>(), m["rays"]["mean"].get<double>()) << m.dump();
  }
  EXPECT_LE(r.report["maps"][0]["standard_error"]["p95"].get<double>(), 0.05);
}

TEST(MapsCli, MapComposesWithUdim) {
  const test::CliRun r = test::run_nmbake(sample_args() + " --maps normal,position -o 't_<MAP>.<UDIM>.tif'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(test::exists(r.dir + "/t_normal.1001.tif"));
  EXPECT_TRUE(test::exists(r.dir + "/t_position.1001.tif"));
}

TEST(MapsCli, RefusalsWriteNothing) {
  const struct {
    const char* args;
    const char* says;
  } cases[] = {
      {"--maps normal,glossy -o 't_<MAP>.png'", "unknown map 'glossy' (maps: normal, object-normal, ao"},
      {"--maps normal,ao -o t.png", "needs <MAP>"},
      {"--maps ao,ao -o 't_<MAP>.png'", "given twice"},
      {"--maps height --height-range 1:0 -o t.png", "A must be below B"},
      {"--maps ao --ao-distance 0 -o t.png", "--ao-distance must be a distance above 0"},
      {"--maps thickness --thickness-distance -1 -o t.png", "--thickness-distance must be a distance above 0"},
      {"--maps ao --ao-rays 0 -o t.png", "--ao-rays takes a number of rays"},
      {"--maps normal --ao-rays 16 -o t.png", "--ao-rays applies to --maps with"},
      {"--maps ao --max-ao-error 0.01 -o t.png", "--max-ao-error applies to --ao-rays auto"},
      {"--maps ao --ao-rays auto --max-ao-error 0 -o t.png", "--max-ao-error must be a standard error above 0"},
      {"--maps ao --ao-rays auto --max-ao-error -0.1 -o t.png", "--max-ao-error must be a standard error above 0"},
      {"--maps ao --ao-rays auto --max-ao-error nan -o t.png", "--max-ao-error"},
      {"--maps ao --ao-rays auto --max-ao-error inf -o t.png", "--max-ao-error"},
      {"--maps curvature --curvature-scale 0 -o t.png", "--curvature-scale must be a distance above 0"},
  };
  for (const auto& c : cases) {
    const test::CliRun r = test::run_nmbake(sample_args() + " " + c.args + " --report r.json");
    EXPECT_EQ(r.code, 1) << c.args;
    EXPECT_TRUE(test::contains(r.err, c.says)) << c.args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    std::size_t files = 0;
    for (const auto& e : fs::directory_iterator(r.dir))
      files += e.path().filename() != "out.txt" && e.path().filename() != "err.txt";
    EXPECT_EQ(files, 0u) << c.args;
  }
}

}  // namespace
}  // namespace nmbake
