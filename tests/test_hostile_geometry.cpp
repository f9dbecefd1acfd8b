// Hostile geometry and options that reach the ray tracer (issue 21): values Embree cannot take
// (it asserts, aborting the process, on ray origins beyond 1.8e18) are refused with exit 2 and a
// message naming the file or the option; degenerate floods (duplicate faces, huge polygons,
// meshes collapsed to a point) bake in time that grows at most as n log n.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "io/mesh_io.h"
#include "pipeline/bake.h"
#include "pipeline/select.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::contains;
using test::run_nmbake;

TEST(HostileGeometry, DistancesBeyondTheRayTracerAreRefused) {
  for (const char* option : {"--front", "--rear"})
    for (const char* value : {"1.8e18", "1e19", "1e25"}) {
      const test::CliRun r =
          run_nmbake(test::sample_low() + " " + test::sample_high() + " -o out.png --size 32 " + option + " " + value);
      EXPECT_EQ(r.code, 2) << option << " " << value;
      EXPECT_TRUE(contains(r.err, std::string("error: ") + option + " ")) << r.err;
      EXPECT_TRUE(contains(r.err, "a bake takes coordinates up to 1e+17")) << r.err;
      EXPECT_FALSE(test::exists(r.dir + "/out.png"));
    }
  // Large but possible: taken (rays that far miss, with the usual warning).
  EXPECT_EQ(run_nmbake(test::sample_low() + " " + test::sample_high() + " -o out.png --size 32 --front 1e16").code, 0);
}

TEST(HostileGeometry, CoordinatesBeyondTheRayTracerAreRefused) {
  const std::string dir = test::scratch_dir();
  test::write_file(dir + "/big.obj", "v 0 0 0\nv 1.8e18 0 0\nv 0 1.8e18 0\nf 1 2 3\n");
  test::write_file(dir + "/max.obj", "v 0 0 0\nv 3e38 0 0\nv 0 3e38 0\nf 1 2 3\n");
  for (const char* name : {"big.obj", "max.obj"}) {
    const test::CliRun r = run_nmbake(test::sample_low() + " " + name + " -o out.png --size 32", "", dir);
    EXPECT_EQ(r.code, 2) << name;
    EXPECT_TRUE(contains(r.err, std::string(name) + ": coordinates reach")) << r.err;
    EXPECT_TRUE(contains(r.err, "a bake takes coordinates up to 1e+17")) << r.err;
    EXPECT_FALSE(test::exists(dir + "/out.png"));
  }
}

TEST(HostileGeometry, LibraryRefusesRayStartsBeyondTheLimit) {
  const Mesh low = test::make_grid(2, 2), high = test::make_grid(4, 4);
  BakeOptions o;
  o.width = o.height = 16;
  o.front = 2e17f;
  try {
    bake_normal_map(low, high, nullptr, o);
    FAIL() << "a bake with --front 2e17 ran";
  } catch (const InputError& e) {
    EXPECT_TRUE(contains(e.what(), "--front 2e+17: rays would start or end up to 2e+17 from the origin")) << e.what();
  }
}

// A million copies of one face took 586 s to bake at 64^2 (every ray met every copy); each stack
// of identical triangles now enters the BVH once, and the map is that of the face alone.
TEST(HostileGeometry, StacksOfIdenticalTrianglesEnterTheBvhOnce) {
  const Mesh low = test::make_grid(4, 4);
  Mesh high = test::make_height_field(
      16, 16, [](double x, double y) { return 0.05 * x * y; },
      [](double x, double y) { return glm::normalize(glm::dvec3(-0.05 * y, -0.05 * x, 1.0)); });
  BakeOptions o;
  o.width = o.height = 64;
  const BakeResult single = bake_normal_map(low, high, nullptr, o);
  EXPECT_EQ(single.stats.select.high_duplicates_skipped, 0u);
  // Every triangle 40 times over (the copies' corners rotated: the same triangle, same winding),
  // and one triangle 8 times, which is left alone (kDuplicateFlood).
  Mesh stacked = high;
  const std::size_t tris = high.triangle_count();
  for (int copy = 1; copy < 40; ++copy)
    for (std::size_t t = 0; t < tris; ++t)
      for (int c = 0; c < 3; ++c) {
        const std::size_t k = 3 * t + std::size_t(c + copy) % 3;
        stacked.position_index.push_back(high.position_index[k]);
        stacked.normal_index.push_back(high.normal_index[k]);
      }
  stacked.source_face.resize(stacked.triangle_count(), 0);
  const BakeResult r = bake_normal_map(low, stacked, nullptr, o);
  EXPECT_EQ(r.stats.select.high_duplicates_skipped, 39 * tris);
  EXPECT_TRUE(r.map.pixels == single.map.pixels);
  EXPECT_TRUE(r.coverage == single.coverage);
}

// The report says what was done to the input: the stacks entered once (high_mesh.
// duplicates_skipped) and the point far meshes were re-centred on (origin).
TEST(HostileGeometry, ReportGivesSkippedStacksAndTheOrigin) {
  const std::string dir = test::scratch_dir();
  const double x0 = 1e6 + 0.1, y0 = -2e6 + 0.3;  // far, and not float values: read in double
  std::string low = "", high = "";
  char line[160];
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) {
      std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\nvt %g %g\n", x0 + 0.25 * i, y0 + 0.25 * j, 5.0, 0.25 * i, 0.25 * j);
      low += line;
      std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", x0 + 0.25 * i, y0 + 0.25 * j, 5.0 + 0.01 * ((i + j) % 2));
      high += line;
    }
  int faces = 0;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) {
      const int a = 1 + i + 5 * j, b = a + 1, c = a + 6, d = a + 5;
      std::snprintf(line, sizeof line, "f %d/%d %d/%d %d/%d\nf %d/%d %d/%d %d/%d\n", a, a, b, b, c, c, a, a, c, c, d, d);
      low += line;
      for (int copy = 0; copy < 12; ++copy) {  // each triangle 12 times: stacks above kDuplicateFlood
        std::snprintf(line, sizeof line, "f %d %d %d\nf %d %d %d\n", a, b, c, a, c, d);
        high += line;
      }
      faces += 2;
    }
  test::write_file(dir + "/low.obj", low);
  test::write_file(dir + "/high.obj", high);
  const test::CliRun r = run_nmbake("low.obj high.obj -o out.png --size 32 --report r.json", "", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.report["high_mesh"]["duplicates_skipped"], 11 * faces);
  const nlohmann::json& origin = r.report["origin"];
  ASSERT_EQ(origin.size(), 3u) << r.report.dump();
  EXPECT_NEAR(origin[0].get<double>(), x0 + 0.5, 1e-9);
  EXPECT_NEAR(origin[1].get<double>(), y0 + 0.5, 1e-9);

  const test::CliRun near = run_nmbake(test::sample_low() + " " + test::sample_high() + " -o out.png --size 16 --report r.json");
  ASSERT_EQ(near.code, 0) << near.err;
  EXPECT_EQ(near.report["origin"], nlohmann::json::array({0.0, 0.0, 0.0}));
  EXPECT_EQ(near.report["high_mesh"]["duplicates_skipped"], 0);
}

TEST(HostileGeometry, SmallStacksAreLeftAlone) {
  const Mesh low = test::make_grid(1, 1);
  Mesh high = test::make_grid(1, 1);
  for (int copy = 1; copy < int(kDuplicateFlood); ++copy)
    for (int k = 0; k < 3; ++k) {
      high.position_index.push_back(high.position_index[k]);
      high.normal_index.push_back(high.normal_index[k]);
      high.uv_index.push_back(high.uv_index[k]);
    }
  high.source_face.resize(high.triangle_count(), 0);
  BakeOptions o;
  o.width = o.height = 16;
  EXPECT_EQ(bake_normal_map(low, high, nullptr, o).stats.select.high_duplicates_skipped, 0u);
}

// A 1000-corner disc is cut in halving passes, not fanned: n - 2 triangles covering the disc, and
// only a few of them have a box around its centre (a fan's every triangle does).
TEST(HostileGeometry, HugePolygonsAreNotFanned) {
  const int n = 1000;
  std::string text;
  for (int i = 0; i < n; ++i) {
    const double a = 2.0 * 3.14159265358979 * i / n;
    text += "v " + std::to_string(std::cos(a)) + " " + std::to_string(std::sin(a)) + " 0\n";
  }
  text += "f";
  for (int i = 1; i <= n; ++i) text += " " + std::to_string(i);
  text += "\n";
  const std::string dir = test::scratch_dir();
  test::write_file(dir + "/disc.obj", text);
  const Mesh m = load_mesh(dir + "/disc.obj");
  ASSERT_EQ(m.triangle_count(), std::size_t(n - 2));
  double area = 0.0;
  std::size_t around_centre = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const glm::dvec3 a(m.corner_position(t, 0)), b(m.corner_position(t, 1)), c(m.corner_position(t, 2));
    const double z = glm::cross(b - a, c - a).z;
    EXPECT_GT(z, 0.0) << "triangle " << t << " turned over or empty";
    area += 0.5 * z;
    const glm::dvec3 lo = glm::min(a, glm::min(b, c)), hi = glm::max(a, glm::max(b, c));
    around_centre += lo.x < 0.01 && hi.x > -0.01 && lo.y < 0.01 && hi.y > -0.01;
  }
  EXPECT_NEAR(area, 0.5 * n * std::sin(2.0 * 3.14159265358979 / n), 1e-4);  // the polygon's area
  EXPECT_LE(around_centre, 12u);
  // Up to kMaxFanCorners corners, the fan Blender makes.
  test::write_file(dir + "/hexagon.obj", "v 1 0 0\nv 2 0 0\nv 3 1 0\nv 2 2 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5 6\n");
  EXPECT_EQ(load_mesh(dir + "/hexagon.obj").position_index, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5}));
}

// Item 2: the ASCII STL reader read uninitialised memory (random maps, exit 0) in the audit. An
// ASCII STL of the sample's high-poly bakes exactly as the same triangles in OBJ (both without
// normals), every time.
TEST(HostileGeometry, AsciiStlBakesAsTheSameTrianglesInObj) {
  Mesh high = load_mesh(test::sample_high());
  high.normals.clear();
  high.normal_index.clear();
  const std::string dir = test::scratch_dir();
  std::string stl = "solid torus\n";
  char line[200];
  for (std::size_t t = 0; t < high.triangle_count(); ++t) {
    stl += " facet normal 0 0 0\n  outer loop\n";
    for (int c = 0; c < 3; ++c) {
      const glm::vec3 p = high.corner_position(t, c);
      std::snprintf(line, sizeof line, "   vertex %.9g %.9g %.9g\n", double(p.x), double(p.y), double(p.z));
      stl += line;
    }
    stl += "  endloop\n endfacet\n";
  }
  stl += "endsolid torus\n";
  test::write_file(dir + "/high.stl", stl);
  test::write_file(dir + "/high.obj", obj_text(high, "torus high, no normals"));
  LoadOptions low_options;
  low_options.require_uvs = true;
  const Mesh low = load_mesh(test::sample_low(), low_options);
  BakeOptions o;
  o.width = o.height = 128;
  const BakeResult from_obj = bake_normal_map(low, load_mesh(dir + "/high.obj"), nullptr, o);
  for (int run = 0; run < 3; ++run) {
    const Mesh from_file = load_mesh(dir + "/high.stl");
    EXPECT_EQ(from_file.triangle_count(), high.triangle_count());
    const BakeResult from_stl = bake_normal_map(low, from_file, nullptr, o);
    EXPECT_TRUE(from_stl.map.pixels == from_obj.map.pixels) << "run " << run;
  }
}

// Item 6: with a cage, --policy closest is honoured. A tilted strap floats between the cage
// (0.5 above the low-poly) and the surface (0.05 above): cage-first rays meet the strap first,
// closest ones take the surface nearer the low-poly.
TEST(HostileGeometry, ClosestPolicyIsHonouredWithACage) {
  const Mesh low = test::make_grid(4, 4);
  Mesh cage = low;
  for (glm::vec3& p : cage.positions) p.z += 0.5f;
  Mesh high = test::make_grid(8, 8, -1.2f, 1.2f, -1.2f, 1.2f);
  for (glm::vec3& p : high.positions) p.z = 0.05f;
  Mesh strap = test::make_grid(2, 2, -0.5f, 0.5f, -0.5f, 0.5f);  // z = 0.4 + 0.2 x: normal (-0.2, 0, 1)
  const std::uint32_t base = std::uint32_t(high.positions.size());
  for (glm::vec3 p : strap.positions) high.positions.push_back({p.x, p.y, 0.4f + 0.2f * p.x});
  for (std::uint32_t i : strap.position_index) high.position_index.push_back(base + i);
  high.source_face.resize(high.triangle_count(), 0);
  high.normals.clear();
  high.normal_index.clear();
  high.uvs.clear();
  high.uv_index.clear();
  BakeOptions o;
  o.width = o.height = 32;
  o.rear = 0.2f;
  const BakeResult first = bake_normal_map(low, high, &cage, o);
  o.policy = RayPolicy::closest;
  const BakeResult closest = bake_normal_map(low, high, &cage, o);
  // The texel at the centre (u = v = 0.5: x = y = 0), under the strap.
  const std::size_t centre = std::size_t(16) * 32 + 16;
  const glm::dvec3 n_first = test::decode_rgb(&first.map.pixels[3 * centre]);
  const glm::dvec3 n_closest = test::decode_rgb(&closest.map.pixels[3 * centre]);
  const glm::dvec3 strap_normal = glm::normalize(glm::dvec3(-0.2, 0.0, 1.0));
  EXPECT_LT(test::angle_deg(n_first, strap_normal), 1.0) << n_first.x << " " << n_first.z;
  EXPECT_LT(test::angle_deg(n_closest, glm::dvec3(0, 0, 1)), 0.5) << n_closest.x << " " << n_closest.z;
}

}  // namespace
}  // namespace nmbake

// The stacks found on several threads (past 2 x 65536 triangles each thread counts the buckets it
// owns): the same triangles left out as on one, of a kept list or of all.
TEST(HostileGeometry, StacksAreFoundAlikeOnAnyNumberOfThreads) {
  const int n = 280;  // n x n quads: 156800 triangles, then stacks
  Prepared s;
  Mesh high;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) s.high_pos.push_back({float(i), float(j), 0.01f * float((i * j) % 7)});
  auto v = [&](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      for (std::uint32_t k : {v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j), v(i + 1, j + 1), v(i, j + 1)})
        high.position_index.push_back(k);
  // Stacks: triangle 5 and 20 copies, 1000 and 9 (both past kDuplicateFlood), 7 and 7 (not).
  for (auto [t, copies] : {std::pair<std::size_t, int>{5, 20}, {1000, 9}, {7, 7}})
    for (int c = 0; c < copies; ++c)
      for (int k = 0; k < 3; ++k) high.position_index.push_back(high.position_index[3 * t + std::size_t(k)]);
  high.positions = s.high_pos;
  std::vector<std::uint32_t> all_one, kept_one(high.triangle_count() / 2);
  for (std::size_t i = 0; i < kept_one.size(); ++i) kept_one[i] = std::uint32_t(2 * i + 1);
  const std::vector<std::uint32_t> kept_start = kept_one;
  EXPECT_EQ(drop_duplicate_floods(s, high, 1, all_one), 20u + 9u);
  const std::size_t kept_dropped = drop_duplicate_floods(s, high, 1, kept_one);
  EXPECT_GT(kept_dropped, 0u);
  for (int threads : {2, 3}) {
    std::vector<std::uint32_t> all, kept = kept_start;
    EXPECT_EQ(drop_duplicate_floods(s, high, threads, all), 20u + 9u) << threads;
    EXPECT_TRUE(all == all_one) << threads;
    EXPECT_EQ(drop_duplicate_floods(s, high, threads, kept), kept_dropped) << threads;
    EXPECT_TRUE(kept == kept_one) << threads;
  }
}
