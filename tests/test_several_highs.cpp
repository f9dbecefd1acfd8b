// Several high-poly files (issue 20, item 2, first step): `nmbake LOW HIGH HIGH...` bakes them as
// one mesh. A sculpt split into two files bakes the map of the whole; the report lists every file
// with its triangles; each file is an input that no output may overwrite.
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "io/mesh_io.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::contains;
using test::run_nmbake;

// Triangles [first, last) of `m` as OBJ text, with the mesh's normals when `normals`.
std::string obj_part(const Mesh& m, std::size_t first, std::size_t last, bool normals) {
  std::string text;
  char line[160];
  for (const glm::vec3& p : m.positions) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", double(p.x), double(p.y), double(p.z));
    text += line;
  }
  if (normals)
    for (const glm::vec3& n : m.normals) {
      std::snprintf(line, sizeof line, "vn %.9g %.9g %.9g\n", double(n.x), double(n.y), double(n.z));
      text += line;
    }
  for (std::size_t t = first; t < last; ++t) {
    text += "f";
    for (int c = 0; c < 3; ++c) {
      if (normals) std::snprintf(line, sizeof line, " %u//%u", m.position_index[3 * t + c] + 1, m.normal_index[3 * t + c] + 1);
      else std::snprintf(line, sizeof line, " %u", m.position_index[3 * t + c] + 1);
      text += line;
    }
    text += "\n";
  }
  return text;
}

TEST(SeveralHighs, ASculptSplitInTwoFilesBakesTheWholeMap) {
  const std::string dir = test::scratch_dir();
  const Mesh high = load_mesh(test::sample_high());
  ASSERT_TRUE(high.has_normals());
  const std::size_t half = high.triangle_count() / 2;
  test::write_file(dir + "/front.obj", obj_part(high, 0, half, true));
  test::write_file(dir + "/back.obj", obj_part(high, half, high.triangle_count(), true));
  const test::CliRun one = run_nmbake(test::sample_low() + " " + test::sample_high() + " -o one.png --size 128", "", dir);
  ASSERT_EQ(one.code, 0) << one.err;
  const test::CliRun two = run_nmbake(test::sample_low() + " front.obj back.obj -o two.png --size 128 --report r.json", "", dir);
  ASSERT_EQ(two.code, 0) << two.err;
  EXPECT_TRUE(test::read_file(dir + "/one.png") == test::read_file(dir + "/two.png")) << "the split sculpt baked another map";
  EXPECT_EQ(two.report["highs"], nlohmann::json::array({"front.obj", "back.obj"}));
  ASSERT_EQ(two.report["high_files"].size(), 2u);
  EXPECT_EQ(two.report["high_files"][0]["triangles"], half);
  EXPECT_EQ(two.report["high_files"][1]["file"], "back.obj");
  EXPECT_EQ(two.report["high_mesh"]["triangles"], high.triangle_count());
  EXPECT_EQ(two.report["options"]["high"], "front.obj");
}

// A file without normals gets the ones computed for it alone; the other keeps its own.
TEST(SeveralHighs, FilesWithAndWithoutNormalsMix) {
  const std::string dir = test::scratch_dir();
  const Mesh high = load_mesh(test::sample_high());
  const std::size_t half = high.triangle_count() / 2;
  test::write_file(dir + "/front.obj", obj_part(high, 0, half, true));
  test::write_file(dir + "/back.obj", obj_part(high, half, high.triangle_count(), false));
  const test::CliRun r = run_nmbake(test::sample_low() + " front.obj back.obj -o m.png --size 64 --report r.json", "", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(r.report["high_normals_computed"].get<bool>()) << "the front file's normals were dropped";
}

TEST(SeveralHighs, NoOutputMayOverwriteAnyOfThem) {
  const std::string dir = test::scratch_dir();
  const Mesh high = load_mesh(test::sample_high());
  test::write_file(dir + "/a.obj", obj_part(high, 0, 10, false));
  test::write_file(dir + "/b.obj", obj_part(high, 10, 20, false));
  const std::string before = test::read_file(dir + "/b.obj");
  const test::CliRun r = run_nmbake(test::sample_low() + " a.obj b.obj -o m.png --size 16 --report b.obj", "", dir);
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_TRUE(contains(r.err, "b.obj")) << r.err;
  EXPECT_EQ(test::read_file(dir + "/b.obj"), before);
  EXPECT_FALSE(test::exists(dir + "/m.png"));
}

}  // namespace
}  // namespace nmbake
