// Stiff and extreme geometry (issue 5): each case bakes the meshes in data/stability (written by
// tests/stability/make_cases.cpp) and states the expected result: a known map within a stated
// tolerance, or a specific refusal or warning, through bake_normal_map and, for warnings, report
// lines and refusals, through the nmbake binary. Measured figures are printed ("measured: ...")
// and recorded as test properties; data/stability/README.md tabulates them.
//
// Here: degenerate and sliver triangles, duplicated elements, mirrored and rotated UV islands
// (cases 1 to 4). Placement, rays, UV layout and map sizes: test_stability_scenes.cpp; hard edges
// and high-poly topology: test_stability_topology.cpp.
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "core/rasterize.h"
#include "stability_test_helpers.h"

using namespace nmbake;
using namespace nmbake::stability_test;

// ---------------------------------------------------------------------------------------------
// 1. Degenerate UV triangles next to good ones.

TEST(Stability, DegenerateUvTrianglesChangeNothing) {
  const Mesh high = load("bumps_high.obj");
  const BakeResult ref = bake_normal_map(load_low("flat_grid_low.obj"), high, nullptr, options(128, 0.1f));
  const BakeResult r = bake_normal_map(load_low("degenerate_uv_low.obj"), high, nullptr, options(128, 0.1f));
  EXPECT_EQ(r.stats.prepare.degenerate_uv_triangles, 3u);
  EXPECT_EQ(ref.stats.prepare.degenerate_uv_triangles, 0u);
  EXPECT_TRUE(all_finite(r.map));
  EXPECT_TRUE(r.coverage == ref.coverage);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < r.map.pixels.size(); ++i) differ += r.map.pixels[i] != ref.map.pixels[i];
  measured("degenerate_uv.texel_channels_differing_from_clean_grid", double(differ));
  EXPECT_EQ(differ, 0u);  // expected: bit-identical to the grid without them
}

TEST(Stability, DegenerateUvTrianglesAreReportedByTheCli) {
  const CliRun r =
      run_nmbake(data("degenerate_uv_low.obj") + " " + data("bumps_high.obj") + " -o out.png --size 64 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["degenerate"]["uv_triangles"], 3);
  EXPECT_TRUE(contains(r.err, "warning: " + data("degenerate_uv_low.obj") + ": 3 triangles have zero UV area")) << r.err;
}

// ---------------------------------------------------------------------------------------------
// 2. Zero-area 3D triangles with good UVs; duplicated vertices; duplicated faces.

TEST(Stability, ZeroArea3dTrianglesDecodeToTheHighNormal) {
  const Mesh low = load_low("degenerate_3d_low.obj");
  const BakeResult r = bake_normal_map(low, load("tilted_plane_high.obj"), nullptr, options(128, 0.5f));
  EXPECT_EQ(r.stats.prepare.degenerate_3d_triangles, 2u);
  EXPECT_EQ(r.stats.trace.misses, 0u);
  EXPECT_TRUE(all_finite(r.map));
  const glm::dvec3 expect = glm::normalize(glm::dvec3(-0.2, -0.1, 1.0));
  double worst = 0.0;
  std::size_t on_degenerate = 0;
  test::for_each_decoded_texel(low, r.map, [&](int, int, const glm::dvec3& world, const glm::dvec3&, std::size_t t) {
    worst = std::max(worst, angle_deg(world, expect));
    on_degenerate += t >= 32;
  });
  measured("zero_area_3d.texels_on_zero_area_triangles", double(on_degenerate));
  measured("zero_area_3d.worst_deg", worst);
  measured("zero_area_3d.corners_without_tangent", double(r.stats.prepare.corners_without_tangent));
  EXPECT_GT(on_degenerate, 200u);  // their UV triangles are baked too
  EXPECT_LT(worst, 1e-3);
}

TEST(Stability, DuplicatedLowPolyVerticesAndFacesChangeNothing) {
  const Mesh high = load("bumps_high.obj");
  const BakeResult ref = bake_normal_map(load_low("flat_grid_low.obj"), high, nullptr, options(128, 0.1f));
  const BakeResult r = bake_normal_map(load_low("duplicates_low.obj"), high, nullptr, options(128, 0.1f));
  // Face 1 written twice: every texel centre of its UV triangle is covered twice.
  Mesh face1 = load_low("duplicates_low.obj");
  face1.position_index.resize(3);
  face1.uv_index.resize(3);
  face1.normal_index.resize(3);
  std::size_t face1_texels = 0;
  for (std::int32_t t : rasterize_texel_triangles(face1, 128, 128)) face1_texels += t == 0;
  measured("duplicates_low.overlapping_samples", double(r.stats.trace.overlapping_samples));
  EXPECT_EQ(r.stats.trace.overlapping_samples, face1_texels);
  EXPECT_GT(face1_texels, 500u);
  EXPECT_TRUE(r.coverage == ref.coverage);
  EXPECT_TRUE(r.map.pixels == ref.map.pixels);
}

TEST(Stability, DuplicatedHighPolyVerticesAndFacesChangeNothing) {
  // Without file normals, normals are computed: a vertex written twice must not crease them and a
  // face written twice must not weigh twice.
  const Mesh low = load_low("flat_grid_low.obj");
  const BakeResult ref = bake_normal_map(low, load("bumps_nonormals_high.obj"), nullptr, options(128, 0.1f));
  const BakeResult r = bake_normal_map(low, load("duplicates_high.obj"), nullptr, options(128, 0.1f));
  double mean = 0.0;
  const double worst = max_texel_angle(r, ref, &mean);
  measured("duplicates_high.max_deg_vs_clean", worst);
  measured("duplicates_high.mean_deg_vs_clean", mean);
  EXPECT_LT(worst, 1e-3);
}

// ---------------------------------------------------------------------------------------------
// 3. Slivers of aspect ratio 1e6 in 3D and in UV.

TEST(Stability, SliverInBothSpacesBakesLikeTheCleanSquare) {
  // UVs are an affine image of the positions, so the true tangent is +X everywhere and the map must
  // equal the clean grid's (same P, same frame) up to float noise.
  const Mesh high = load("bumps_high.obj");
  const Mesh low = load_low("sliver_both_low.obj");
  const BakeResult ref = bake_normal_map(load_low("flat_grid_low.obj"), high, nullptr, options(128, 0.1f));
  const BakeResult r = bake_normal_map(low, high, nullptr, options(128, 0.1f));
  EXPECT_EQ(
      r.stats.prepare.degenerate_uv_triangles + r.stats.prepare.degenerate_3d_triangles + r.stats.prepare.corners_without_tangent,
      0u);
  const TangentFrames f = compute_tangent_frames(low);
  double worst_t = 0.0;
  for (const glm::vec4& t : f.tangent) worst_t = std::max(worst_t, angle_deg(glm::dvec3(t), glm::dvec3(1, 0, 0)));
  double mean = 0.0;
  const double worst = max_texel_angle(r, ref, &mean);
  measured("sliver_both.worst_tangent_deg", worst_t);
  measured("sliver_both.max_deg_vs_clean", worst);
  measured("sliver_both.mean_deg_vs_clean", mean);
  // The sliver's UVs are floats: its UV area (1e-6 of the square) carries a few % rounding, which
  // tilts its tangent; angle-weighted into the shared corners that is < 0.1 deg, below one 8-bit step.
  EXPECT_LT(worst_t, 0.1);
  EXPECT_LT(worst, 0.05);
  EXPECT_TRUE(r.coverage == ref.coverage);
}

TEST(Stability, SliversInOneSpaceDecodeToTheHighNormal) {
  const Mesh high = load("bumps_high.obj");
  const HighProbe probe(high);
  for (const char* name : {"sliver_3d_low.obj", "sliver_uv_low.obj"}) {
    const Mesh low = load_low(name);
    const BakeResult r = bake_normal_map(low, high, nullptr, options(128, 0.1f));
    EXPECT_TRUE(all_finite(r.map)) << name;
    EXPECT_EQ(r.stats.trace.misses, 0u) << name;
    EXPECT_EQ(r.stats.trace.texels_covered, 128u * 128u) << name;
    const TangentFrames f = compute_tangent_frames(low);
    for (std::size_t c = 0; c < f.tangent.size(); ++c) {
      EXPECT_NEAR(glm::length(glm::vec3(f.tangent[c])), 1.0f, 1e-5f) << name;
      EXPECT_NEAR(glm::dot(glm::vec3(f.tangent[c]), f.normal[c]), 0.0f, 1e-5f) << name;
    }
    double worst = 0.0;
    test::for_each_decoded_texel(low, r.map, [&](int, int, const glm::dvec3& world, const glm::dvec3& p, std::size_t) {
      glm::dvec3 n;
      ASSERT_TRUE(probe.normal_at(p + glm::dvec3(0, 0, 0.1), {0, 0, -1}, 0.2f, n));
      worst = std::max(worst, angle_deg(world, n));
    });
    measured(std::string(name) + ".worst_deg_vs_high_normal", worst);
    EXPECT_LT(worst, 0.01) << name;
  }
}

// ---------------------------------------------------------------------------------------------
// 4. Mirrored and rotated UV islands decode to the same world normals.

TEST(Stability, MirroredAndRotatedIslandsDecodeToTheSameWorldNormals) {
  const Mesh high = load("dome_bumps_high.obj");
  const int S = 128;
  const Mesh base_low = load_low("island_low.obj");
  const BakeResult base = bake_normal_map(base_low, high, nullptr, options(S, 0.2f));
  std::vector<glm::dvec3> base_world(std::size_t(S) * S, glm::dvec3(0.0));
  test::for_each_decoded_texel(base_low, base.map, [&](int x, int y, const glm::dvec3& w, const glm::dvec3&, std::size_t) {
    base_world[std::size_t(y) * S + x] = w;
  });
  struct Variant {
    const char* file;
    std::function<glm::dvec2(glm::dvec2)> uv;  // the variant's UV of the base's UV
  };
  for (const Variant& v : {Variant{"island_mirrored_low.obj", [](glm::dvec2 t) { return glm::dvec2(1 - t.x, t.y); }},
                           Variant{"island_rot90_low.obj", [](glm::dvec2 t) { return glm::dvec2(1 - t.y, t.x); }},
                           Variant{"island_rot180_low.obj", [](glm::dvec2 t) { return glm::dvec2(1 - t.x, 1 - t.y); }}}) {
    const Mesh low = load_low(v.file);
    const BakeResult r = bake_normal_map(low, high, nullptr, options(S, 0.2f));
    std::vector<glm::dvec3> world(std::size_t(S) * S, glm::dvec3(0.0));
    test::for_each_decoded_texel(low, r.map, [&](int x, int y, const glm::dvec3& w, const glm::dvec3&, std::size_t) {
      world[std::size_t(y) * S + x] = w;
    });
    // 8-bit copy of the variant map, decoded the same way.
    Image q = r.map;
    for (float& c : q.pixels) c = float(double(quantize8(c)) / 255.0);
    std::vector<glm::dvec3> world8(std::size_t(S) * S, glm::dvec3(0.0));
    test::for_each_decoded_texel(
        low, q, [&](int x, int y, const glm::dvec3& w, const glm::dvec3&, std::size_t) { world8[std::size_t(y) * S + x] = w; });
    double worst = 0.0, worst8 = 0.0;
    std::size_t compared = 0;
    for (int y = 0; y < S; ++y)
      for (int x = 0; x < S; ++x) {
        const glm::dvec2 t = v.uv({(x + 0.5) / S, 1.0 - (y + 0.5) / S});
        const int vx = int(std::lround(t.x * S - 0.5)), vy = int(std::lround((1.0 - t.y) * S - 0.5));
        const glm::dvec3 a = base_world[std::size_t(y) * S + x], b = world[std::size_t(vy) * S + vx];
        if (glm::length(a) == 0.0 || glm::length(b) == 0.0) continue;
        worst = std::max(worst, angle_deg(a, b));
        worst8 = std::max(worst8, angle_deg(a, world8[std::size_t(vy) * S + vx]));
        ++compared;
      }
    measured(std::string(v.file) + ".worst_deg_float", worst);
    measured(std::string(v.file) + ".worst_deg_8bit", worst8);
    EXPECT_EQ(compared, std::size_t(S) * S) << v.file;
    EXPECT_LT(worst, 0.01) << v.file;
    EXPECT_LT(worst8, 0.5) << v.file;
  }
}
