// Stiff and extreme geometry (issue 5): each case bakes the meshes in data/stability (written by
// tests/stability/make_cases.cpp) and states the expected result: a known map within a stated
// tolerance, or a specific refusal or warning, through bake_normal_map and, for warnings, report
// lines and refusals, through the nmbake binary. Measured figures are printed ("measured: ...")
// and recorded as test properties; data/stability/README.md tabulates them.
#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <functional>

#include <gtest/gtest.h>

#include "pipeline/bake.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "core/mesh_topology.h"
#include "core/rasterize.h"
#include "raycast.h"
#include "test_support.h"

using namespace nmbake;
using test::angle_deg;
using test::CliRun;
using test::contains;
using test::decode_rgb;
using test::run_nmbake;

namespace {

Mesh load(const std::string& name, bool uvs = false) {
  LoadOptions lo;
  lo.require_uvs = uvs;
  return load_mesh(test::data_path("stability/" + name), lo);
}
Mesh load_low(const std::string& name) { return load(name, true); }

BakeOptions options(int size, float distance) {
  BakeOptions o;
  o.width = o.height = size;
  o.padding = 0;
  o.front = o.rear = distance;
  return o;
}

long quantize8(float c) { return std::lround(double(c) * 255.0); }

void measured(const std::string& key, double value) {
  ::testing::Test::RecordProperty(key, std::to_string(value));
  std::printf("measured: %s = %.6g\n", key.c_str(), value);
}

bool all_finite(const Image& img) {
  for (float v : img.pixels)
    if (!std::isfinite(v)) return false;
  return true;
}

// The high-poly's interpolated normal where the ray from `origin` along `dir` first meets it.
struct HighProbe {
  explicit HighProbe(const Mesh& m) : mesh(m), pos(m.positions), scene(&pos[0].x, pos.size(), m.position_index.data(), m.triangle_count()) {}
  bool normal_at(const glm::dvec3& origin, const glm::dvec3& dir, float reach, glm::dvec3& n) const {
    const raycast::Hit h = scene.intersect({glm::vec3(origin), 0.0f, glm::vec3(dir), reach});
    if (!h.hit()) return false;
    const double w[3] = {1.0 - double(h.u) - double(h.v), double(h.u), double(h.v)};
    n = glm::dvec3(0.0);
    for (int c = 0; c < 3; ++c) n += w[c] * glm::dvec3(mesh.corner_normal(h.triangle, c));
    n = glm::normalize(n);
    return true;
  }
  const Mesh& mesh;
  std::vector<glm::vec3> pos;
  raycast::Scene scene;
};

// Largest angle (degrees) between two maps' texels, both decoded with the same layout.
double max_texel_angle(const BakeResult& a, const BakeResult& b, double* mean = nullptr) {
  double worst = 0.0, sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.coverage.size(); ++i) {
    if (!a.coverage[i] || !b.coverage[i]) continue;
    const double e = angle_deg(decode_rgb(&a.map.pixels[3 * i]), decode_rgb(&b.map.pixels[3 * i]));
    worst = std::max(worst, e);
    sum += e;
    ++n;
  }
  if (mean) *mean = n ? sum / double(n) : 0.0;
  return worst;
}

// Absolute path of a case in data/stability, for run_nmbake's command lines.
std::string data(const std::string& name) { return test::data_path("stability/" + name); }

}  // namespace

// ---------------------------------------------------------------------------------------------
// 1. Degenerate UV triangles next to good ones.

TEST(Stability, DegenerateUvTrianglesChangeNothing) {
  const Mesh high = load("bumps_high.obj");
  const BakeResult ref = bake_normal_map(load_low("flat_grid_low.obj"), high, nullptr, options(128, 0.1f));
  const BakeResult r = bake_normal_map(load_low("degenerate_uv_low.obj"), high, nullptr, options(128, 0.1f));
  EXPECT_EQ(r.stats.degenerate_uv_triangles, 3u);
  EXPECT_EQ(ref.stats.degenerate_uv_triangles, 0u);
  EXPECT_TRUE(all_finite(r.map));
  EXPECT_TRUE(r.coverage == ref.coverage);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < r.map.pixels.size(); ++i) differ += r.map.pixels[i] != ref.map.pixels[i];
  measured("degenerate_uv.texel_channels_differing_from_clean_grid", double(differ));
  EXPECT_EQ(differ, 0u);  // expected: bit-identical to the grid without them
}

TEST(Stability, DegenerateUvTrianglesAreReportedByTheCli) {
  const CliRun r = run_nmbake(data("degenerate_uv_low.obj") + " " + data("bumps_high.obj") + " -o out.png --size 64 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["degenerate"]["uv_triangles"], 3);
  EXPECT_TRUE(contains(r.err, "warning: " + data("degenerate_uv_low.obj") + ": 3 triangles have zero UV area")) << r.err;
}

// ---------------------------------------------------------------------------------------------
// 2. Zero-area 3D triangles with good UVs; duplicated vertices; duplicated faces.

TEST(Stability, ZeroArea3dTrianglesDecodeToTheHighNormal) {
  const Mesh low = load_low("degenerate_3d_low.obj");
  const BakeResult r = bake_normal_map(low, load("tilted_plane_high.obj"), nullptr, options(128, 0.5f));
  EXPECT_EQ(r.stats.degenerate_3d_triangles, 2u);
  EXPECT_EQ(r.stats.misses, 0u);
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
  measured("zero_area_3d.corners_without_tangent", double(r.stats.corners_without_tangent));
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
  measured("duplicates_low.overlapping_samples", double(r.stats.overlapping_samples));
  EXPECT_EQ(r.stats.overlapping_samples, face1_texels);
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
  EXPECT_EQ(r.stats.degenerate_uv_triangles + r.stats.degenerate_3d_triangles + r.stats.corners_without_tangent, 0u);
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
    EXPECT_EQ(r.stats.misses, 0u) << name;
    EXPECT_EQ(r.stats.texels_covered, 128u * 128u) << name;
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
    test::for_each_decoded_texel(low, q, [&](int x, int y, const glm::dvec3& w, const glm::dvec3&, std::size_t) {
      world8[std::size_t(y) * S + x] = w;
    });
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

// ---------------------------------------------------------------------------------------------
// 5. Translated and scaled scenes.

namespace {

Mesh transformed(Mesh m, double scale, double offset) {
  for (glm::vec3& p : m.positions) p = glm::vec3(glm::dvec3(p) * scale + glm::dvec3(offset));
  return m;
}

}  // namespace

TEST(Stability, TranslatedAndScaledScenesMatchTheOriginal) {
  // The base pair is 100 units across (z from the dome, bumps 1.5 units). Rays +-10 units, scaled.
  const Mesh low = load_low("far_base_low.obj"), high = load("far_base_high.obj");
  const BakeResult base = bake_normal_map(low, high, nullptr, options(128, 10.0f));
  EXPECT_EQ(base.stats.misses, 0u);
  struct Case {
    std::string name;
    Mesh low, high;
    float distance;
    double max_deg;  // stated tolerance
  };
  std::vector<Case> cases;
  cases.push_back({"far_1e5", load_low("far_1e5_low.obj"), load("far_1e5_high.obj"), 10.0f, 0.01});
  cases.push_back({"far_1e6", transformed(low, 1.0, 1e6), transformed(high, 1.0, 1e6), 10.0f, 0.05});
  cases.push_back({"far_1e7", load_low("far_1e7_low.obj"), load("far_1e7_high.obj"), 10.0f, 1e9});
  cases.push_back({"scaled_1e-5", load_low("scaled_1e-5_low.obj"), load("scaled_1e-5_high.obj"), 10.0f * 1e-5f, 1e-4});
  cases.push_back({"scaled_1e5", load_low("scaled_1e5_low.obj"), load("scaled_1e5_high.obj"), 10.0f * 1e5f, 1e-4});
  for (double off : {1e3, 1e4, 3e4, 3e5, 3e6})
    cases.push_back({"far_" + std::to_string(int(off)), transformed(low, 1.0, off), transformed(high, 1.0, off), 10.0f, 1e9});
  for (const Case& c : cases) {
    const BakeResult r = bake_normal_map(c.low, c.high, nullptr, options(128, c.distance));
    double mean = 0.0;
    const double worst = max_texel_angle(r, base, &mean);
    measured(c.name + ".max_deg", worst);
    measured(c.name + ".mean_deg", mean);
    measured(c.name + ".coordinate_spacing", r.stats.coordinate_spacing);
    EXPECT_TRUE(all_finite(r.map)) << c.name;
    EXPECT_TRUE(r.coverage == base.coverage) << c.name;
    // Within the range nmbake does not warn about, the map matches within 0.05 deg (a quarter of
    // an 8-bit step) or the case's tighter bound; beyond it the CLI warns (next test).
    const bool warned = r.stats.coordinate_spacing > kCoordinateSpacingWarn;
    if (!warned) {
      EXPECT_LT(worst, std::min(c.max_deg, 0.05)) << c.name;
    }
    if (c.name == "far_1e7") {
      EXPECT_TRUE(warned);
    }
  }
}

TEST(Stability, FarFromOriginWarnsPastTheFloatLimit) {
  const CliRun ok = run_nmbake(data("far_1e5_low.obj") + " " + data("far_1e5_high.obj") + " -o out.png --size 64 --report r.json");
  ASSERT_EQ(ok.code, 0);
  EXPECT_FALSE(contains(ok.err, "float precision")) << ok.err;
  const CliRun far = run_nmbake(data("far_1e7_low.obj") + " " + data("far_1e7_high.obj") + " -o out.png --size 64 --report r.json");
  ASSERT_EQ(far.code, 0);
  EXPECT_TRUE(contains(far.err, "warning: coordinates reach 1e+07")) << far.err;
  EXPECT_TRUE(contains(far.err, "float precision")) << far.err;
  EXPECT_GT(far.report["coordinate_spacing"].get<double>(), 1e-3);
}

// ---------------------------------------------------------------------------------------------
// 6. High-poly coincident with the low-poly.

TEST(Stability, CoincidentMeshesBakeExactlyFlat) {
  for (const char* name : {"coincident_dome.obj", "coincident_cube.obj"}) {
    const Mesh m = load_low(name);
    for (RayPolicy policy : {RayPolicy::cage_first, RayPolicy::closest})
      for (float distance : {-1.0f, 0.05f})
        for (int samples : {1, 4}) {
          BakeOptions o = options(64, distance);
          o.policy = policy;
          o.samples = samples;
          const BakeResult r = bake_normal_map(m, m, nullptr, o);
          EXPECT_EQ(r.stats.misses, 0u) << name;
          std::size_t off = 0;
          for (std::size_t i = 0; i < r.coverage.size(); ++i) {
            if (!r.coverage[i]) continue;
            const float* c = &r.map.pixels[3 * i];
            off += !(c[0] == 0.5f && c[1] == 0.5f && c[2] == 1.0f);
          }
          EXPECT_EQ(off, 0u) << name << " policy " << int(policy) << " distance " << distance << " samples " << samples;
          EXPECT_GT(r.stats.texels_covered, 0u);
        }
  }
}

TEST(Stability, CoincidentCubeIsFlatThroughTheCli) {
  const CliRun r = run_nmbake(data("coincident_cube.obj") + " " + data("coincident_cube.obj") + " -o out.png --size 64");
  ASSERT_EQ(r.code, 0);
  const Image img = read_image(r.dir + "/out.png");
  std::size_t off = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const float* c = img.at(x, y);
      off += !(quantize8(c[0]) == 128 && quantize8(c[1]) == 128 && quantize8(c[2]) == 255);
    }
  EXPECT_EQ(off, 0u);
}

// ---------------------------------------------------------------------------------------------
// 7. Grazing rays, holes, high-poly inside or outside, two layers.

TEST(Stability, GrazingRaysHitTheSteepFacesWithoutLeaks) {
  const Mesh low = load_low("flat_grid_low.obj");
  const Mesh high = load("grazing_high.obj");
  const glm::dvec3 rising = glm::normalize(glm::dvec3(-50, 0, 1)), falling = glm::normalize(glm::dvec3(50, 0, 1));
  BakeOptions o = options(128, 0.1f);
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  EXPECT_EQ(r.stats.misses, 0u);
  EXPECT_TRUE(all_finite(r.map));
  double worst = 0.0;
  std::size_t n_rising = 0, n = 0;
  test::for_each_decoded_texel(low, r.map, [&](int, int, const glm::dvec3& w, const glm::dvec3&, std::size_t) {
    const double a = angle_deg(w, rising), b = angle_deg(w, falling);
    worst = std::max(worst, std::min(a, b));
    n_rising += a < b;
    ++n;
  });
  measured("grazing.worst_deg_vs_face_normal", worst);
  measured("grazing.share_rising", double(n_rising) / double(n));
  EXPECT_LT(worst, 0.01);
  EXPECT_NEAR(double(n_rising) / double(n), 0.5, 0.1);
  o.samples = 16;  // 262144 grazing rays: none may slip between the faces
  const BakeResult r16 = bake_normal_map(low, high, nullptr, o);
  measured("grazing.misses_16_samples", double(r16.stats.misses));
  EXPECT_EQ(r16.stats.misses, 0u);
  EXPECT_TRUE(all_finite(r16.map));
}

TEST(Stability, HolesAreCountedFlatFilledAndMasked) {
  const Mesh low = load_low("flat_grid_low.obj");
  BakeOptions o = options(64, 0.1f);
  o.miss_mask = true;
  const BakeResult r = bake_normal_map(low, load("holes_high.obj"), nullptr, o);
  const glm::dvec3 expect = glm::normalize(glm::dvec3(0.1, 0.2, 1.0));
  auto in_hole = [](double x, double y) {
    return (x > -0.6 && x < -0.4 && y > -0.6 && y < -0.2) || (x > 0.4 && x < 0.6 && y > 0.2 && y < 0.4);
  };
  std::size_t expected_misses = 0, wrong = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const double px = -1 + 2 * (x + 0.5) / 64, py = -1 + 2 * (1 - (y + 0.5) / 64);
      const float* c = r.map.at(x, y);
      const float mask = r.miss_mask.pixels[std::size_t(y) * 64 + x];
      if (in_hole(px, py)) {
        ++expected_misses;
        wrong += !(c[0] == 0.5f && c[1] == 0.5f && c[2] == 1.0f && mask == 1.0f);
      } else {
        wrong += !(angle_deg(decode_rgb(c), expect) < 1e-3 && mask == 0.0f);
      }
    }
  measured("holes.misses", double(r.stats.misses));
  EXPECT_EQ(expected_misses, 120u);  // texel centres in the holes: 6 x 13 + 6 x 7
  EXPECT_EQ(r.stats.misses, expected_misses);
  EXPECT_EQ(wrong, 0u);
}

TEST(Stability, HighPolyInsideOrOutsideTheLowPoly) {
  const Mesh low = load_low("sphere_low.obj");
  for (const char* name : {"inside_high.obj", "outside_high.obj"}) {
    const Mesh high = load(name);
    // Both spheres lie 0.6 away. Distances of 0.1 reach neither: nothing is hit, the map is flat,
    // every sample is counted as a miss. (The automatic cage's probes look 20% of the scene
    // diagonal, 0.69, far: they find both, and every sample hits.)
    BakeOptions o = options(64, 0.1f);
    const BakeResult a = bake_normal_map(low, high, nullptr, options(64, -1.0f));
    measured(std::string(name) + ".auto_misses", double(a.stats.misses));
    EXPECT_EQ(a.stats.misses, 0u) << name;
    const BakeResult r = bake_normal_map(low, high, nullptr, o);
    EXPECT_EQ(r.stats.misses, r.stats.samples_covered) << name;
    EXPECT_GT(r.stats.samples_covered, 0u);
    for (std::size_t i = 0; i < r.coverage.size(); ++i) {
      if (r.coverage[i]) {
        ASSERT_EQ(r.map.pixels[3 * i + 2], 1.0f) << name;
      }
    }
    // Distances that reach it: every sample hits, and the map decodes to the sphere's radial normal
    // where the ray meets it.
    const bool inside = std::string(name) == "inside_high.obj";
    o.front = inside ? 0.01f : 0.7f;
    o.rear = inside ? 0.5f : 0.01f;
    const BakeResult h = bake_normal_map(low, high, nullptr, o);
    EXPECT_EQ(h.stats.misses, 0u) << name;
    const HighProbe probe(high);
    double worst = 0.0;
    test::for_each_decoded_texel(low, h.map, [&](int, int, const glm::dvec3& w, const glm::dvec3& p, std::size_t) {
      // The ray direction is the interpolated position-averaged normal; on this sphere that is the
      // interpolated radial normal, close to normalize(p). Compare with the high normal along it.
      glm::dvec3 n;
      const glm::dvec3 d = glm::normalize(p);
      if (!probe.normal_at(p + double(o.front) * d, -d, o.front + o.rear, n)) {
        return;
      }
      worst = std::max(worst, angle_deg(w, n));
    });
    measured(std::string(name) + ".worst_deg_vs_radial_probe", worst);
    EXPECT_LT(worst, 1.0) << name;
  }
}

TEST(Stability, AllMissedIsAWarningThroughTheCli) {
  const CliRun r =
      run_nmbake(data("sphere_low.obj") + " " + data("inside_high.obj") + " -o out.png --size 64 --front 0.1 --rear 0.1 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["misses"], r.report["samples_covered"]);
  EXPECT_TRUE(contains(r.err, "warning: 100.0% of samples missed " + data("inside_high.obj"))) << r.err;
}

TEST(Stability, TwoLayersFollowThePolicyDeterministically) {
  const Mesh low = load_low("flat_grid_low.obj");
  const glm::dvec3 upper = glm::normalize(glm::dvec3(0.3, 0, 1)), lower = glm::normalize(glm::dvec3(0, 0.3, 1));
  auto check_all = [&](const BakeResult& r, const glm::dvec3& expect, const char* what) {
    double worst = 0.0;
    test::for_each_decoded_texel(low, r.map, [&](int, int, const glm::dvec3& w, const glm::dvec3&, std::size_t) {
      worst = std::max(worst, angle_deg(w, expect));
    });
    EXPECT_LT(worst, 1e-3) << what;
    EXPECT_EQ(r.stats.misses, 0u) << what;
  };
  BakeOptions o = options(64, 0.2f);
  const Mesh two = load("two_layers_high.obj"), tie = load("two_layers_tie_high.obj");
  check_all(bake_normal_map(low, two, nullptr, o), upper, "cage-first: first hit from the front");
  o.policy = RayPolicy::closest;
  check_all(bake_normal_map(low, two, nullptr, o), lower, "closest: the layer 0.03 below beats 0.05 above");
  o.threads = 1;
  const BakeResult t1 = bake_normal_map(low, tie, nullptr, o);
  check_all(t1, upper, "closest, equal distances: the outside hit wins the tie");
  o.threads = 2;
  const BakeResult t2 = bake_normal_map(low, tie, nullptr, o);
  EXPECT_TRUE(t1.map.pixels == t2.map.pixels);
}

// ---------------------------------------------------------------------------------------------
// 8. UVs outside [0,1]; overlapping islands.

TEST(Stability, UvTilesBakeOnlyTheMapRegionAndWarn) {
  const Mesh low = load_low("uv_tiles_low.obj");
  const BakeResult r = bake_normal_map(low, load("tilted_plane_high.obj"), nullptr, options(64, 0.5f));
  EXPECT_EQ(r.stats.uv_outside_triangles, 4u);
  // Covered: island A's square and island C's part inside the map; island B (tile u in [1,2]) not at all.
  std::size_t wrong = 0, covered = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const double u = (x + 0.5) / 64, v = 1 - (y + 0.5) / 64;
      const bool a = u > 0.05 && u < 0.45 && v > 0.05 && v < 0.45, c = u > 0.8 && v > 0.5 && v < 0.9;
      wrong += r.coverage[std::size_t(y) * 64 + x] != (a || c);
      covered += a || c;
    }
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(r.stats.texels_covered, covered);
  const glm::dvec3 expect = glm::normalize(glm::dvec3(-0.2, -0.1, 1.0));
  double worst = 0.0;
  test::for_each_decoded_texel(low, r.map, [&](int, int, const glm::dvec3& w, const glm::dvec3&, std::size_t) {
    worst = std::max(worst, angle_deg(w, expect));
  });
  EXPECT_LT(worst, 1e-3);
  const CliRun cli = run_nmbake(data("uv_tiles_low.obj") + " " + data("tilted_plane_high.obj") + " -o out.png --size 64 --report r.json");
  ASSERT_EQ(cli.code, 0);
  EXPECT_TRUE(contains(cli.err, "4 triangles have UVs outside [0,1] (2 entirely outside, not baked)")) << cli.err;
  EXPECT_EQ(cli.report["uv_outside_triangles"], 4);
  EXPECT_EQ(cli.report["uv_outside_entirely_triangles"], 2);
}

TEST(Stability, OverlappingIslandsAreCountedAndTheFirstWins) {
  const Mesh low = load_low("uv_overlap_low.obj");
  const Mesh high = load("bumps_high.obj");
  const BakeResult r = bake_normal_map(low, high, nullptr, options(64, 0.1f));
  EXPECT_EQ(r.stats.overlapping_samples, 144u);  // texel centres in (0.4,0.6)^2: 12 x 12
  Mesh first = low;  // island 1 alone
  first.position_index.resize(6);
  first.uv_index.resize(6);
  first.normal_index.resize(6);
  const BakeResult f = bake_normal_map(first, high, nullptr, options(64, 0.1f));
  double worst = 0.0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const double u = (x + 0.5) / 64, v = 1 - (y + 0.5) / 64;
      if (!(u > 0.4 && u < 0.6 && v > 0.4 && v < 0.6)) continue;
      worst = std::max(worst, angle_deg(decode_rgb(r.map.at(x, y)), decode_rgb(f.map.at(x, y))));
    }
  EXPECT_LT(worst, 1e-3);
  const CliRun cli = run_nmbake(data("uv_overlap_low.obj") + " " + data("bumps_high.obj") + " -o out.png --size 64 --report r.json");
  ASSERT_EQ(cli.code, 0);
  EXPECT_TRUE(contains(cli.err, "UV islands overlap (144 samples covered twice")) << cli.err;
  EXPECT_EQ(cli.report["overlapping_samples"], 144);
}

// ---------------------------------------------------------------------------------------------
// 9. Hard edges: rays follow position-averaged normals, frames use the file's split normals.

TEST(Stability, HardEdgesOpenNoGapsAndNoCracks) {
  const Mesh high = load("cylinder_high.obj");
  for (const char* name : {"hard_edges_low.obj", "hard_edges_split_low.obj"}) {
    const Mesh low = load_low(name);
    BakeOptions o = options(128, 0.5f);
    o.height = 32;
    const BakeResult r = bake_normal_map(low, high, nullptr, o);
    EXPECT_EQ(r.stats.misses, 0u) << name;
    EXPECT_EQ(r.stats.texels_covered, 128u * 32u) << name;  // the strip covers the map: no cracks
    EXPECT_TRUE(all_finite(r.map)) << name;
    // Along a row, the azimuth of the decoded normal (the cylinder's radial normal where the ray
    // hit) must rise steadily through 360 degrees: split rays at an edge would jump back ~23 deg.
    test::for_each_decoded_texel(low, r.map, [](int, int, const glm::dvec3&, const glm::dvec3&, std::size_t) {});
    std::vector<double> az(128, 0.0);
    std::vector<double> z(128, 0.0);
    test::for_each_decoded_texel(low, r.map, [&](int x, int y, const glm::dvec3& w, const glm::dvec3&, std::size_t) {
      if (y != 16) return;
      az[std::size_t(x)] = std::atan2(w.y, w.x) * 180.0 / 3.14159265358979323846;
      z[std::size_t(x)] = w.z;
    });
    double worst_step = 0.0, min_step = 1e9, worst_z = 0.0;
    for (int x = 0; x < 128; ++x) {
      double step = az[std::size_t((x + 1) % 128)] - az[std::size_t(x)];
      if (step < -180) step += 360;
      if (step > 180) step -= 360;
      if (x != 127) {
        worst_step = std::max(worst_step, step);
        min_step = std::min(min_step, step);
      }
      worst_z = std::max(worst_z, std::abs(z[std::size_t(x)]));
    }
    measured(std::string(name) + ".largest_azimuth_step_deg", worst_step);
    measured(std::string(name) + ".smallest_azimuth_step_deg", min_step);
    measured(std::string(name) + ".worst_vertical_component", worst_z);
    EXPECT_GT(min_step, 0.0) << name;   // monotonic: no overlap, no jump back
    EXPECT_LT(worst_step, 6.0) << name;  // 360/128 = 2.8 on average: no gap
    EXPECT_LT(worst_z, 1e-3) << name;
  }
}

// ---------------------------------------------------------------------------------------------
// 10. Non-manifold edges, isolated vertices, inconsistent winding, inverted normals.

TEST(Stability, HighPolyTopologyIsInspected) {
  struct Expect {
    const char* file;
    std::size_t non_manifold, isolated, inconsistent, duplicates;
  };
  for (const Expect& e : {Expect{"nonmanifold_high.obj", 2, 0, 0, 0}, Expect{"isolated_vertices_high.obj", 0, 3, 0, 0},
                          Expect{"inconsistent_winding_high.obj", 0, 0, 264, 0}, Expect{"duplicates_high.obj", 0, 0, 0, 293},
                          Expect{"bumps_high.obj", 0, 0, 0, 0}}) {
    const MeshTopology t = inspect_topology(load(e.file));
    EXPECT_EQ(t.non_manifold_edges, e.non_manifold) << e.file;
    EXPECT_EQ(t.isolated_vertices, e.isolated) << e.file;
    EXPECT_EQ(t.inconsistent_winding_faces, e.inconsistent) << e.file;
    EXPECT_EQ(t.duplicate_faces, e.duplicates) << e.file;
  }
}

TEST(Stability, NonManifoldFinsGiveTheFirstHit) {
  // 0 < x < 0.2: the slanted fin lies above the plane; elsewhere the plane (+Z). The fin's normal
  // points down, into the low-poly: by default the plane beneath it is taken (a hit whose normal
  // points away is taken only for want of another); with back faces kept, the first hit, the fin.
  const Mesh low = load_low("flat_grid_low.obj");
  const glm::dvec3 fin = glm::normalize(glm::dvec3(0.9, 0, -0.6));
  for (bool keep : {false, true}) {
    BakeOptions o = options(64, 0.6f);
    o.keep_backfaces = keep;
    const BakeResult r = bake_normal_map(low, load("nonmanifold_high.obj"), nullptr, o);
    EXPECT_EQ(r.stats.misses, 0u);
    EXPECT_TRUE(all_finite(r.map));
    std::size_t wrong = 0, on_fin = 0;
    test::for_each_decoded_texel(low, r.map, [&](int, int, const glm::dvec3& w, const glm::dvec3& p, std::size_t) {
      const bool under_fin = p.x > 0.0 && p.x < 0.2;
      on_fin += under_fin;
      const glm::dvec3 expect = under_fin && keep ? fin : glm::dvec3(0, 0, 1);
      wrong += angle_deg(w, expect) > 1e-3;
    });
    EXPECT_GT(on_fin, 100u);
    EXPECT_EQ(wrong, 0u) << "keep_backfaces " << keep;
    EXPECT_EQ(r.stats.hits_facing_away, 0u);
  }
}

TEST(Stability, IsolatedVerticesChangeNothing) {
  // Auto distances and the re-centring must ignore vertices no face uses (one is 1e6 away).
  const Mesh low = load_low("flat_grid_low.obj");
  const BakeResult ref = bake_normal_map(low, load("bumps_nonormals_high.obj"), nullptr, options(128, -1.0f));
  const BakeResult r = bake_normal_map(low, load("isolated_vertices_high.obj"), nullptr, options(128, -1.0f));
  double mean = 0.0;
  const double worst = max_texel_angle(r, ref, &mean);
  measured("isolated_vertices.max_deg_vs_clean", worst);
  measured("isolated_vertices.front", r.stats.front);
  EXPECT_EQ(r.stats.front, ref.stats.front);
  EXPECT_EQ(r.stats.rear, ref.stats.rear);
  EXPECT_TRUE(r.map.pixels == ref.map.pixels);
}

TEST(Stability, InconsistentWindingDoesNotFlipComputedNormals) {
  const Mesh low = load_low("flat_grid_low.obj");
  const BakeResult ref = bake_normal_map(low, load("bumps_nonormals_high.obj"), nullptr, options(128, 0.1f));
  const BakeResult r = bake_normal_map(low, load("inconsistent_winding_high.obj"), nullptr, options(128, 0.1f));
  double mean = 0.0;
  const double worst = max_texel_angle(r, ref, &mean);
  measured("inconsistent_winding.max_deg_vs_clean", worst);
  measured("inconsistent_winding.faces_reoriented", double(r.stats.high_faces_reoriented));
  EXPECT_EQ(r.stats.high_faces_reoriented, 264u);
  EXPECT_LT(worst, 1e-3);
}

TEST(Stability, InvertedNormalsAreBakedAsGivenAndReported) {
  // A file's inverted normals are baked as given (the faces' fronts follow them, so the hit rule
  // changes nothing); normals computed from an inverted winding are turned outwards. Both are
  // reported as an inverted high-poly.
  const Mesh low = load_low("flat_grid_low.obj");
  for (bool keep : {false, true}) {
    BakeOptions o = options(64, 0.1f);
    o.keep_backfaces = keep;
    const BakeResult r = bake_normal_map(low, load("inverted_normals_high.obj"), nullptr, o);
    measured(std::string("inverted_normals.texels_facing_away.keep") + (keep ? "1" : "0"), double(r.stats.texels_facing_away));
    EXPECT_EQ(r.stats.texels_facing_away, r.stats.texels_covered);
    EXPECT_EQ(r.stats.high_facing, keep ? BakeStats::HighFacing::sound : BakeStats::HighFacing::inverted);
    EXPECT_TRUE(all_finite(r.map));
    const BakeResult w = bake_normal_map(low, load("inverted_winding_high.obj"), nullptr, o);
    EXPECT_TRUE(all_finite(w.map));
    if (keep) {
      EXPECT_EQ(w.stats.texels_facing_away, w.stats.texels_covered);
    } else {
      EXPECT_EQ(w.stats.high_facing, BakeStats::HighFacing::inverted);
      EXPECT_GT(w.stats.backface_probe_share, 0.99);
      EXPECT_EQ(w.stats.texels_facing_away, 0u);
      // The same map as the correctly wound field's.
      const BakeResult ref = bake_normal_map(low, load("bumps_nonormals_high.obj"), nullptr, o);
      double mean = 0.0;
      EXPECT_LT(max_texel_angle(w, ref, &mean), 1e-3);
      EXPECT_EQ(ref.stats.high_facing, BakeStats::HighFacing::sound);
    }
  }
  const BakeResult ok = bake_normal_map(low, load("bumps_high.obj"), nullptr, options(64, 0.1f));
  EXPECT_EQ(ok.stats.texels_facing_away, 0u);
  EXPECT_EQ(ok.stats.backface_probe_share, 0.0);
}

TEST(Stability, TopologyAndInversionAreReportedByTheCli) {
  const std::string low = data("flat_grid_low.obj");
  CliRun r = run_nmbake(low + " " + data("nonmanifold_high.obj") + " -o out.png --size 32 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["high_mesh"]["non_manifold_edges"], 2);
  EXPECT_TRUE(contains(r.err, "2 non-manifold edges")) << r.err;
  r = run_nmbake(low + " " + data("isolated_vertices_high.obj") + " -o out.png --size 32 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["high_mesh"]["isolated_vertices"], 3);
  EXPECT_TRUE(contains(r.err, "3 isolated vertices")) << r.err;
  r = run_nmbake(low + " " + data("inconsistent_winding_high.obj") + " -o out.png --size 32 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["high_mesh"]["inconsistent_winding_faces"], 264);
  EXPECT_EQ(r.report["high_faces_reoriented"], 264);
  EXPECT_TRUE(contains(r.err, "264 faces wound against their neighbours")) << r.err;
  r = run_nmbake(low + " " + data("inverted_normals_high.obj") + " -o out.png --size 32 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["texels_facing_away"], 32 * 32);
  EXPECT_EQ(r.report["high_facing"], "inverted");
  EXPECT_TRUE(contains(r.err, "warning: 100.0% of covered texels point into the low-poly")) << r.err;
  EXPECT_TRUE(contains(r.err, "inverted_normals_high.obj: its faces look inverted (100% of the surfaces nearest the low-poly face "
                              "into it): their fronts were taken the other way round; the file's normals are kept"))
      << r.err;
  r = run_nmbake(low + " " + data("inverted_winding_high.obj") + " -o out.png --size 32 --report r.json");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["texels_facing_away"], 0);
  EXPECT_EQ(r.report["high_facing"], "inverted");
  EXPECT_TRUE(contains(r.err, "inverted_winding_high.obj: its faces look inverted (100% of the surfaces nearest the low-poly face "
                              "into it): their fronts were taken the other way round and the computed normals turned outwards"))
      << r.err;
  // --keep-backfaces: the first hit, as it lies.
  r = run_nmbake(low + " " + data("inverted_winding_high.obj") + " -o out.png --size 32 --report r.json --keep-backfaces");
  ASSERT_EQ(r.code, 0);
  EXPECT_EQ(r.report["texels_facing_away"], 32 * 32);
  EXPECT_EQ(r.report["options"]["keep_backfaces"], true);
  EXPECT_EQ(r.report["backfaces_skipped"], false);
}

// ---------------------------------------------------------------------------------------------
// 11. Sizes 1x1, 7x3 and 16384^2.

TEST(Stability, TinyAndOddMapSizes) {
  const Mesh low = load_low("flat_grid_low.obj"), high = load("tilted_plane_high.obj");
  const glm::dvec3 n = glm::normalize(glm::dvec3(-0.2, -0.1, 1.0));
  for (auto [w, h] : {std::pair<int, int>{1, 1}, {7, 3}, {3, 7}}) {
    for (int padding : {0, 16}) {
      BakeOptions o = options(w, 0.5f);
      o.height = h;
      o.padding = padding;
      o.samples = 4;
      const BakeResult r = bake_normal_map(low, high, nullptr, o);
      EXPECT_EQ(r.stats.texels_covered, std::size_t(w) * h);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          for (int k = 0; k < 3; ++k) EXPECT_EQ(quantize8(r.map.at(x, y)[k]), std::lround((n[k] * 0.5 + 0.5) * 255.0)) << w << "x" << h;
    }
  }
  const CliRun r = run_nmbake(data("flat_grid_low.obj") + " " + data("tilted_plane_high.obj") + " -o out.png --size 7x3");
  ASSERT_EQ(r.code, 0);
  const Image img = read_image(r.dir + "/out.png");
  EXPECT_EQ(img.width, 7);
  EXPECT_EQ(img.height, 3);
}

TEST(Stability, HugeMapIsRefusedBeforeAllocatingWhenItWouldNotFit) {
  const Mesh low = load_low("flat_grid_low.obj"), high = load("tilted_plane_high.obj");
  BakeOptions o = options(16384, 0.5f);
  o.padding = 16;
  const std::uint64_t need = estimate_bake_bytes(o);
  measured("size_16384.estimated_bytes", double(need));
  o.memory_limit = 1ull << 30;  // a machine with 1 GiB free
  rusage before{}, after{};
  getrusage(RUSAGE_SELF, &before);
  try {
    bake_normal_map(low, high, nullptr, o);
    FAIL() << "16384^2 must be refused with 1 GiB";
  } catch (const ResourceError& e) {
    EXPECT_TRUE(contains(e.what(), "--size 16384x16384 needs about")) << e.what();
    EXPECT_TRUE(contains(e.what(), "1024 MiB")) << e.what();
  }
  getrusage(RUSAGE_SELF, &after);
  EXPECT_LT(after.ru_maxrss - before.ru_maxrss, 64 * 1024);  // KiB: nothing big was allocated
}

TEST(Stability, HugeMapIsRefusedByTheCliUnderAMemoryLimit) {
  // The budget honours the process's address-space limit (ulimit -v), not only MemAvailable.
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space for its shadow memory, so a process "
                  "cannot start under ulimit -v; the in-process test above covers the budget";
#endif
  const CliRun r = run_nmbake(data("flat_grid_low.obj") + " " + data("tilted_plane_high.obj") + " -o out.png --size 16384",
                              "ulimit -v 3000000 &&");
  EXPECT_EQ(r.code, 4);
  EXPECT_TRUE(contains(r.err, "error: --size 16384x16384 needs about")) << r.err;
  EXPECT_FALSE(test::exists(r.dir + "/out.png"));
}
