// Meshes far from the origin (issue 21, item 1): georeferenced and CAD exports sit at 1e5-1e7 and
// beyond. load_mesh reads coordinates in double and re-centres a far mesh before rounding to
// float, so a pair saved with enough digits bakes as it does at the origin; a far pair whose values
// carry only float (or less than double) precision is refused with the offset and the step lost.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "io/mesh_io.h"
#include "pipeline/bake.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::scratch_dir;

// A torus low-poly and a bumpy, finer torus high-poly (computed normals) around the origin.
Mesh low_poly() { return test::make_torus(24, 12); }

Mesh high_poly() {
  Mesh m = test::make_torus(160, 80, 1.0f, 0.37f);
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const glm::dvec3 p(m.positions[i]), n(m.normals[i]);
    const double bump = 0.02 * std::sin(23.0 * p.x) * std::sin(19.0 * p.y) * std::cos(7.0 * p.z);
    m.positions[i] = glm::vec3(p + bump * n);
  }
  m.normals.clear();
  m.normal_index.clear();
  return m;
}

Mesh moved_in_float(Mesh m, const glm::dvec3& offset) {
  for (glm::vec3& p : m.positions) p = glm::vec3(glm::dvec3(p) + offset);
  return m;
}

// Writes `m` moved by `offset` as OBJ: with every digit of the sum in double (obj_text writes a
// mesh with an origin at %.17g), or rounded to float as a float-only exporter would.
std::string write_moved(const Mesh& m, const glm::dvec3& offset, const std::string& name, bool in_float = false) {
  static std::string dir, test;  // scratch_dir() empties the folder: once per test
  const std::string current = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  if (current != test) dir = scratch_dir(), test = current;
  Mesh moved = in_float ? moved_in_float(m, offset) : m;
  if (!in_float) moved.origin = offset;
  const std::string path = dir + "/" + name;
  std::FILE* f = std::fopen(path.c_str(), "w");
  EXPECT_NE(f, nullptr) << path;
  const std::string text = obj_text(moved, "moved");
  std::fwrite(text.data(), 1, text.size(), f);
  std::fclose(f);
  return path;
}

BakeOptions far_options() {
  BakeOptions o;
  o.width = o.height = 128;
  o.padding = 2;
  return o;
}

// Mean and largest angle between two bakes' covered texels, in degrees.
void compare(const BakeResult& a, const BakeResult& b, double& mean, double& worst) {
  double sum = 0.0;
  std::size_t n = 0;
  worst = 0.0;
  for (std::size_t i = 0; i < a.coverage.size(); ++i) {
    if (!a.coverage[i] || !b.coverage[i]) continue;
    const double angle = test::angle_deg(test::decode_rgb(&a.map.pixels[3 * i]), test::decode_rgb(&b.map.pixels[3 * i]));
    sum += angle;
    worst = std::max(worst, angle);
    ++n;
  }
  mean = n ? sum / double(n) : 0.0;
  EXPECT_GT(n, 1000u);
}

// Loads a pair as nmbake does: the high-poly takes the low-poly's origin.
BakeResult load_and_bake(const std::string& low_path, const std::string& high_path, glm::dvec3* origin = nullptr) {
  const test::MeshPair pair = test::load_pair(low_path, high_path);
  EXPECT_EQ(pair.high.origin, pair.low.origin);
  if (origin) *origin = pair.low.origin;
  return bake_normal_map(pair.low, pair.high, nullptr, far_options());
}

TEST(FarFromOrigin, SavedInDoubleBakesAsAtTheOrigin) {
  // Off-centre by odd amounts, so that the far meshes' centres are not their offsets plus zero.
  const glm::dvec3 shift(0.123456789, -0.2718281828, 0.0577);
  const Mesh low = moved_in_float(low_poly(), shift), high = moved_in_float(high_poly(), shift);
  const BakeResult base =
      load_and_bake(write_moved(low, glm::dvec3(0.0), "low_0.obj"), write_moved(high, glm::dvec3(0.0), "high_0.obj"));
  EXPECT_LT(base.stats.trace.misses, base.stats.trace.samples_covered / 100);
  const glm::dvec3 offsets[] = {{1e5, 1e5, 1e5}, {1e6, -1e6, 0.0}, {1e7, 1e7, 1e7}, {-3e7, 2e7, 1e7}, {3e9, 0.0, -3e9}};
  for (const glm::dvec3& offset : offsets) {
    const std::string tag = std::to_string(offset.x) + "," + std::to_string(offset.y) + "," + std::to_string(offset.z);
    glm::dvec3 origin;
    const BakeResult far = load_and_bake(write_moved(low, offset, "low.obj"), write_moved(high, offset, "high.obj"), &origin);
    EXPECT_LT(glm::length(origin - offset), 1.0) << tag;  // re-centred near the mesh
    double mean = 0.0, worst = 0.0;
    compare(far, base, mean, worst);
    std::printf("offset (%s): mean %.5f deg, max %.4f deg\n", tag.c_str(), mean, worst);
    EXPECT_TRUE(far.coverage == base.coverage) << tag;
    EXPECT_EQ(far.stats.trace.misses, base.stats.trace.misses) << tag;
    EXPECT_LE(mean, 0.01) << tag;  // the issue asks 0.1 at 1e5 and 1e6, 1 at 1e7 and beyond
    EXPECT_LE(worst, 1.0) << tag;
    EXPECT_LT(far.stats.prepare.coordinate_spacing, kCoordinateSpacingWarn) << tag;
  }
}

TEST(FarFromOrigin, NearTheOriginNothingMoves) {
  const Mesh low = low_poly();
  const std::string path = write_moved(low, glm::dvec3(3.0, 0.0, 0.0), "low.obj");  // 3 units off: not far
  const Mesh loaded = load_mesh(path, {true});
  EXPECT_EQ(loaded.origin, glm::dvec3(0.0));
  ASSERT_EQ(loaded.positions.size(), low.positions.size());
  for (std::size_t i = 0; i < low.positions.size(); ++i)
    EXPECT_EQ(loaded.positions[i], glm::vec3(glm::dvec3(low.positions[i]) + glm::dvec3(3.0, 0.0, 0.0))) << i;
}

TEST(FarFromOrigin, SavedInFloatIsRefusedWithTheOffsetAndTheStep) {
  const Mesh low = low_poly();
  const std::string path = write_moved(low, glm::dvec3(1e7, 1e7, 1e7), "low.obj", true);
  try {
    load_mesh(path, {true});
    FAIL() << "a torus 2.7 units across saved in float at 1e7 loaded";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_TRUE(test::contains(message, path + ": coordinates reach 1e+07")) << message;
    EXPECT_TRUE(test::contains(message, "steps of 1 (saved in float precision)")) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  // At 1e3 float steps are 6e-5, well inside the limit: loaded and re-centred.
  const Mesh near = load_mesh(write_moved(low, glm::dvec3(1e3, 0.0, 0.0), "low_1e3.obj", true), {true});
  EXPECT_NE(near.origin, glm::dvec3(0.0));
}

TEST(FarFromOrigin, BeyondDoublePrecisionIsRefused) {
  const std::string path = write_moved(low_poly(), glm::dvec3(1e17, 0.0, 0.0), "low.obj");
  try {
    load_mesh(path, {true});
    FAIL() << "a torus saved at 1e17 loaded";
  } catch (const InputError& e) {
    EXPECT_TRUE(test::contains(e.what(), "coordinates reach 1e+17")) << e.what();
    EXPECT_TRUE(test::contains(e.what(), "beyond double precision")) << e.what();
  }
}

// PLY with double properties keeps its digits too (binary, little-endian).
TEST(FarFromOrigin, PlyDoublePropertiesKeepTheirDigits) {
  const std::string path = scratch_dir() + "/tri.ply";
  std::FILE* f = std::fopen(path.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  std::fprintf(f,
               "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty "
               "double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n");
  const double v[9] = {1e7 + 0.125, 1e7, 1e7, 1e7 + 1.0625, 1e7, 1e7, 1e7, 1e7 + 1.0078125, 1e7};
  std::fwrite(v, sizeof v, 1, f);
  const unsigned char n = 3;
  const int idx[3] = {0, 1, 2};
  std::fwrite(&n, 1, 1, f);
  std::fwrite(idx, sizeof idx, 1, f);
  std::fclose(f);
  const Mesh m = load_mesh(path);
  ASSERT_EQ(m.positions.size(), 3u);
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(double(m.positions[i][k]) + m.origin[k], v[3 * i + k]) << i << "," << k;
}

// obj_text puts a far mesh back where its file had it (the saved cage of a far bake).
TEST(FarFromOrigin, ObjTextWritesTheFileCoordinates) {
  Mesh m = test::make_grid(1, 1);
  m.origin = glm::dvec3(1e7, -2e6, 0.5);
  const std::string text = obj_text(m, "far");
  EXPECT_TRUE(test::contains(text, "v 9999999 -2000001 0.5\n")) << text;
}

}  // namespace
}  // namespace nmbake
