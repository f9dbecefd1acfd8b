// The texture set's maps (--maps, core/maps.h) against known answers: AO beside a wall, in a well
// and on a convex object over a ground plane, thickness of a slab, height of a sine field, position
// on a plane, material IDs; their noise against the standard error they report; thread counts.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "core/normals.h"
#include "pipeline/bake.h"
#include "pipeline/map_set.h"
#include "pipeline/udim.h"
#include "maps_test_helpers.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::baked;
using test::kPi;
using test::map_options;
using test::wall_ao;

// Flat-shaded triangles and quads (each face its own normal), UVs optional.
struct Builder {
  Mesh m;
  explicit Builder(const std::string& name) { m.source = name; }
  void tri(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec2 ua = {}, glm::vec2 ub = {}, glm::vec2 uc = {}) {
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    const std::uint32_t p = std::uint32_t(m.positions.size()), q = std::uint32_t(m.normals.size()),
                        u = std::uint32_t(m.uvs.size());
    for (const glm::vec3& v : {a, b, c}) m.positions.push_back(v);
    m.normals.push_back(n);
    for (const glm::vec2& t : {ua, ub, uc}) m.uvs.push_back(t);
    for (std::uint32_t k = 0; k < 3; ++k) {
      m.position_index.push_back(p + k);
      m.normal_index.push_back(q);
      m.uv_index.push_back(u + k);
    }
    m.source_face.push_back(std::uint32_t(m.source_face.size()));
  }
  // Counter-clockwise a, b, c, d.
  void quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    tri(a, b, c);
    tri(a, c, d);
  }
  Mesh done(bool uvs) {
    if (!uvs) m.uvs.clear(), m.uv_index.clear();
    return m;
  }
};

const Image& map_of(const BakeResult& r, MapKind kind) {
  for (const BakedMap& m : r.maps)
    if (m.kind == kind) return m.image;
  throw std::runtime_error("no such map");
}
// The ground [0, 4] x [-2, 2] (low-poly, UVs: u along x) beside a wall x = 0, y in [-4, 4], z in [0, 2].
TEST(MapsAo, BesideAWallMatchesTheAnalyticShare) {
  Builder high("wall_high");
  high.quad({0, -4, 0}, {4, -4, 0}, {4, 4, 0}, {0, 4, 0});
  high.quad({0, -4, 0}, {0, 4, 0}, {0, 4, 2}, {0, -4, 2});  // facing +x
  const Mesh low = test::make_grid(8, 8, 0, 4, -2, 2);
  BakeOptions o = map_options(128, {MapKind::normal, MapKind::ao});
  o.maps.ao_distance = 1.0;
  o.maps.ao_rays = 256;
  const BakeResult r = bake_normal_map(low, high.done(false), nullptr, o);
  const Image& ao = map_of(r, MapKind::ao);
  const Image& se = baked(r, MapKind::ao).error;
  double sq_resid = 0.0, sq_se = 0.0, n_partial = 0.0;
  for (int x = 0; x < 64; ++x) {  // d from 1/64 to 2
    const double d = (x + 0.5) * 4.0 / 128.0, expect = wall_ao(d, 1.0);
    double sum = 0.0;
    for (int y = 0; y < 128; ++y) {
      const std::size_t i = std::size_t(y) * 128 + std::size_t(x);
      const double v = ao.pixels[i];
      sum += v;
      if (d < 1.0) sq_resid += (v - expect) * (v - expect), sq_se += double(se.pixels[i]) * se.pixels[i], n_partial += 1.0;
    }
    // The column's mean: 128 texels of 256 rays, standard error at most 0.5 / sqrt(32768).
    EXPECT_NEAR(sum / 128.0, expect, 0.012) << "d = " << d;
  }
  EXPECT_NEAR(wall_ao(1e-9, 1.0), 0.5, 1e-6);
  // The noise is what the map reports it to be.
  const double ratio = std::sqrt(sq_resid / n_partial) / std::sqrt(sq_se / n_partial);
  EXPECT_GT(ratio, 0.7);
  EXPECT_LT(ratio, 1.3);
}

// The bottom of a round well (radius r, depth h): r^2 / (r^2 + h^2) with no distance limit.
TEST(MapsAo, AtTheBottomOfARoundWell) {
  const double r = 1.0, h = 1.5;
  Builder high("well_high");
  const int sides = 256;
  for (int k = 0; k < sides; ++k) {
    const double a0 = 2 * kPi * k / sides, a1 = 2 * kPi * (k + 1) / sides;
    const glm::vec3 p0(float(r * std::cos(a0)), float(r * std::sin(a0)), 0.0f),
        p1(float(r * std::cos(a1)), float(r * std::sin(a1)), 0.0f);
    high.tri({0, 0, 0}, p0, p1);                                                        // the floor, facing up
    high.quad(p1, p0, p0 + glm::vec3(0, 0, float(h)), p1 + glm::vec3(0, 0, float(h)));  // the wall, facing in
  }
  const Mesh low = test::make_grid(1, 1, -0.02f, 0.02f, -0.02f, 0.02f);
  BakeOptions o = map_options(16, {MapKind::ao});
  o.maps.ao_distance = 100.0;
  o.maps.ao_rays = 1024;
  const BakeResult r2 = bake_normal_map(low, high.done(false), nullptr, o);
  const Image& ao = map_of(r2, MapKind::ao);
  double sum = 0.0;
  for (float v : ao.pixels) sum += v;
  EXPECT_NEAR(sum / double(ao.pixels.size()), r * r / (r * r + h * h), 0.01);
}

// A UV sphere (latitude-longitude) of radius 1 around `c`, smooth normals, UVs.
Mesh uv_sphere(int nu, int nv, glm::vec3 c) {
  Mesh m;
  m.source = "sphere";
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double th = kPi * j / nv, ph = 2 * kPi * i / nu;
      const glm::vec3 n(float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)), float(std::cos(th)));
      m.positions.push_back(c + n);
      m.normals.push_back(n);
      m.uvs.push_back({float(i) / float(nu), 1.0f - float(j) / float(nv)});
    }
  const auto at = [&](int i, int j) { return std::uint32_t(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const std::uint32_t a = at(i, j), b = at(i, j + 1), cc = at(i + 1, j + 1), d = at(i + 1, j);
      for (std::uint32_t v : {a, b, cc, a, cc, d}) m.position_index.push_back(v);
      m.source_face.push_back(std::uint32_t(m.source_face.size()));
      m.source_face.push_back(std::uint32_t(m.source_face.size()));
    }
  m.normal_index = m.uv_index = m.position_index;
  return m;
}

// A convex object on a ground plane, no distance limit: (1 + n.up) / 2.
TEST(MapsAo, ConvexObjectOnAGroundPlane) {
  const Mesh low = uv_sphere(96, 48, {0, 0, 1});
  Mesh high = low;
  Builder ground("ground");
  ground.quad({-400, -400, 0}, {400, -400, 0}, {400, 400, 0}, {-400, 400, 0});
  high = merge_meshes({high, ground.done(false)});
  BakeOptions o = map_options(96, {MapKind::ao, MapKind::object_normal}, 0.02f, 0.02f);
  o.maps.ao_distance = 1e4;
  o.maps.ao_rays = 256;
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  const Image& ao = map_of(r, MapKind::ao);
  const Image& n = map_of(r, MapKind::object_normal);
  const Image& se = baked(r, MapKind::ao).error;
  double resid = 0.0, sq_resid = 0.0, sq_se = 0.0, count = 0.0;
  for (std::size_t i = 0; i < r.coverage.size(); ++i) {
    if (!r.coverage[i]) continue;
    const double up = 2.0 * n.pixels[3 * i + 2] - 1.0, expect = (1.0 + up) / 2.0;
    if (expect > 0.98 || expect < 0.02) continue;  // open texels have no noise to compare
    const double d = ao.pixels[i] - expect;
    resid += d, sq_resid += d * d, sq_se += double(se.pixels[i]) * se.pixels[i], count += 1.0;
  }
  ASSERT_GT(count, 1000.0);
  EXPECT_NEAR(resid / count, 0.0, 0.005);  // no bias
  const double ratio = std::sqrt(sq_resid / sq_se);
  EXPECT_GT(ratio, 0.7);
  EXPECT_LT(ratio, 1.3);
}

// A slab of thickness T under its top face, distance D > T: (2T - T^2 / D) / D.
TEST(MapsThickness, OfASlab) {
  const double t = 0.2, d = 0.5;
  Builder high("slab");
  high.quad({-5, -5, 0}, {5, -5, 0}, {5, 5, 0}, {-5, 5, 0});                                  // top, facing up
  high.quad({-5, -5, float(-t)}, {-5, 5, float(-t)}, {5, 5, float(-t)}, {5, -5, float(-t)});  // bottom, facing down
  const Mesh low = test::make_grid(4, 4, -1, 1, -1, 1);
  BakeOptions o = map_options(32, {MapKind::thickness});
  o.maps.thickness_distance = d;
  o.maps.ao_rays = 256;
  const BakeResult r = bake_normal_map(low, high.done(false), nullptr, o);
  const Image& th = map_of(r, MapKind::thickness);
  double sum = 0.0;
  for (float v : th.pixels) sum += v;
  EXPECT_NEAR(sum / double(th.pixels.size()), (2 * t - t * t / d) / d, 0.005);
}

// The height of z = A sin(2 pi x / L) over the plane z = 0, by the range given.
TEST(MapsHeight, OfASineField) {
  const double a = 0.05, len = 1.0;
  const Mesh high = test::make_height_field(
      400, 4, [&](double x, double) { return a * std::sin(2 * kPi * x / len); },
      [&](double x, double) {
        const glm::dvec3 n(-a * 2 * kPi / len * std::cos(2 * kPi * x / len), 0.0, 1.0);
        return glm::normalize(n);
      });
  const Mesh low = test::make_grid(4, 4);
  BakeOptions o = map_options(64, {MapKind::height}, 0.2f, 0.2f);
  o.maps.height_range_given = true;
  o.maps.height_min = -0.1, o.maps.height_max = 0.1;
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  const Image& h = map_of(r, MapKind::height);
  double worst = 0.0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const double px = -1.0 + 2.0 * (x + 0.5) / 64.0, expect = a * std::sin(2 * kPi * px / len);
      worst = std::max(worst, std::fabs((h.pixels[std::size_t(y) * 64 + std::size_t(x)] * 0.2 - 0.1) - expect));
    }
  EXPECT_LT(worst, 2e-4);
  EXPECT_EQ(baked(r, MapKind::height).range_min, -0.1);
}

// Without a range, the bake's own, symmetric about 0: 0.5 is the low-poly surface.
TEST(MapsHeight, OwnRangeIsSymmetric) {
  const Mesh high = test::make_height_field(
      64, 64, [](double x, double) { return 0.03 * x + 0.01; }, [](double, double) { return glm::dvec3(0, 0, 1); });
  const BakeResult r = bake_normal_map(test::make_grid(4, 4), high, nullptr, map_options(32, {MapKind::height}, 0.1f, 0.1f));
  const BakedMap& m = baked(r, MapKind::height);
  EXPECT_NEAR(m.range_max, 0.04, 1e-3);
  EXPECT_EQ(m.range_min, -m.range_max);
  for (float v : m.image.pixels) EXPECT_TRUE(v >= 0.0f && v <= 1.0f);
}

// Position on a plane: R follows x, G follows y over the high-poly's box; B (a flat box) is 0.5.
TEST(MapsPosition, NormalisedToTheHighPolysBox) {
  const Mesh plane = test::make_grid(4, 4);
  const BakeResult r = bake_normal_map(plane, plane, nullptr, map_options(16, {MapKind::position}, 0.1f, 0.1f));
  const BakedMap& m = baked(r, MapKind::position);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const float* p = &m.image.pixels[3 * (std::size_t(y) * 16 + std::size_t(x))];
      EXPECT_NEAR(p[0], (x + 0.5) / 16.0, 1e-5);
      EXPECT_NEAR(p[1], 1.0 - (y + 0.5) / 16.0, 1e-5);  // row 0 is the top: v = 1
      EXPECT_EQ(p[2], 0.5f);
    }
  EXPECT_NEAR(m.box_min.x, -1.0, 1e-6);
  EXPECT_NEAR(m.box_max.y, 1.0, 1e-6);
}

// Two materials: two colours, every texel exactly one of them, none mixed, even with 16 samples.
TEST(MapsIds, TwoMaterialsGiveTwoFlatColours) {
  Mesh high = test::make_grid(16, 16);
  high.materials = {"paint", "rubber"};
  for (std::size_t t = 0; t < high.triangle_count(); ++t) {
    const float cx = (high.corner_position(t, 0).x + high.corner_position(t, 1).x + high.corner_position(t, 2).x) / 3.0f;
    high.triangle_material.push_back(cx < 0.1f ? 0u : 1u);
  }
  BakeOptions o = map_options(32, {MapKind::material_id}, 0.1f, 0.1f);
  o.samples = 16;
  const BakeResult r = bake_normal_map(test::make_grid(4, 4), high, nullptr, o);
  const BakedMap& m = baked(r, MapKind::material_id);
  ASSERT_EQ(m.colors.size(), 2u);
  const glm::vec3 a = m.colors[0].second, b = m.colors[1].second;
  EXPECT_NE(a, b);
  // Held as palette indices (1 channel: 1 + the material's index), written as their colours.
  ASSERT_EQ(m.image.channels, 1);
  const Image rgb = expand_palette(m.image, id_palette(m));
  std::size_t na = 0, nb = 0, ia = 0, ib = 0;
  for (std::size_t i = 0; i < r.coverage.size(); ++i) {
    const glm::vec3 c(rgb.pixels[3 * i], rgb.pixels[3 * i + 1], rgb.pixels[3 * i + 2]);
    na += c == a;
    nb += c == b;
    ia += m.image.pixels[i] == 1.0f;
    ib += m.image.pixels[i] == 2.0f;
  }
  EXPECT_EQ(na + nb, r.coverage.size());
  EXPECT_EQ(ia, na);
  EXPECT_EQ(ib, nb);
  EXPECT_GT(na, 300u);
  EXPECT_GT(nb, 300u);
  EXPECT_EQ(id_color("paint"), id_color("paint"));  // from the name alone
}

// Curvature from the high-poly's geometry: a plane 0.5; a sphere uniform and above it; the inside
// of a cylinder below it.
TEST(MapsCurvature, PlaneSphereAndTheInsideOfACylinder) {
  const Mesh plane = test::make_grid(8, 8);
  const BakeResult flat = bake_normal_map(plane, plane, nullptr, map_options(16, {MapKind::curvature}, 0.1f, 0.1f));
  for (float v : baked(flat, MapKind::curvature).image.pixels) EXPECT_EQ(v, 0.5f);

  const Mesh sphere = uv_sphere(64, 32, {0, 0, 0});
  BakeOptions o = map_options(64, {MapKind::curvature}, 0.05f, 0.05f);
  o.maps.curvature_scale = 2.0;  // mean curvature 1 (radius 1): 0.75
  const BakeResult round = bake_normal_map(sphere, sphere, nullptr, o);
  const Image& k = baked(round, MapKind::curvature).image;
  for (int y = 8; y < 56; ++y)  // away from the poles' fans
    for (int x = 0; x < 64; ++x) EXPECT_NEAR(k.pixels[std::size_t(y) * 64 + std::size_t(x)], 0.75, 0.01) << x << "," << y;

  // A cylinder of radius 1 seen from inside (wound and lit inwards): mean curvature -1/2.
  Mesh tube = uv_sphere(64, 32, {0, 0, 0});
  for (std::size_t i = 0; i < tube.positions.size(); ++i) {
    const double a = std::atan2(tube.positions[i].y, tube.positions[i].x);
    const float z = 2.0f * (tube.uvs[i].y - 0.5f);
    tube.positions[i] = {float(std::cos(a)), float(std::sin(a)), z};
    tube.normals[i] = {float(-std::cos(a)), float(-std::sin(a)), 0.0f};
  }
  for (std::size_t t = 0; t < tube.triangle_count(); ++t)
    std::swap(tube.position_index[3 * t + 1], tube.position_index[3 * t + 2]);
  tube.normal_index = tube.uv_index = tube.position_index;
  // The tube ends open, where the curvature is off; smoothing carries that a ring further in per
  // pass, so the middle half is checked unsmoothed and with the default smoothing.
  for (const int smoothing : {0, kDefaultCurvatureSmoothing}) {
    o.maps.curvature_smoothing = smoothing;
    const BakeResult inside = bake_normal_map(tube, tube, nullptr, o);
    const Image& c = baked(inside, MapKind::curvature).image;
    for (int y = 16; y < 48; ++y)
      for (int x = 0; x < 64; ++x)
        EXPECT_NEAR(c.pixels[std::size_t(y) * 64 + std::size_t(x)], 0.5 - 0.125, 0.01)
            << x << "," << y << " smoothing " << smoothing;
  }
}

// Vertex colours interpolated at the hit; a high-poly without them: the map is not made.
TEST(MapsVertexColor, InterpolatedAtTheHit) {
  Mesh high = test::make_grid(8, 8);
  for (const glm::vec3& p : high.positions) high.colors.push_back({(p.x + 1.0f) / 2.0f, (p.y + 1.0f) / 2.0f, 0.25f, 1.0f});
  high.color_index = high.position_index;
  const Mesh low = test::make_grid(2, 2);
  const BakeResult r = bake_normal_map(low, high, nullptr, map_options(16, {MapKind::vertex_color}, 0.1f, 0.1f));
  const Image& c = baked(r, MapKind::vertex_color).image;
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) {
      const float* p = &c.pixels[3 * (std::size_t(y) * 16 + std::size_t(x))];
      EXPECT_NEAR(p[0], (x + 0.5) / 16.0, 1e-5);
      EXPECT_NEAR(p[1], 1.0 - (y + 0.5) / 16.0, 1e-5);
      EXPECT_NEAR(p[2], 0.25, 1e-6);
    }
  const BakeResult none =
      bake_normal_map(low, test::make_grid(8, 8), nullptr, map_options(16, {MapKind::vertex_color}, 0.1f, 0.1f));
  EXPECT_FALSE(baked(none, MapKind::vertex_color).skipped.empty());
  EXPECT_TRUE(baked(none, MapKind::vertex_color).image.pixels.empty());
}

// Every map the same whatever the thread count, with fixed rays and with --ao-rays auto (its rays
// per texel too).
TEST(MapsThreads, IdenticalAcrossThreadCounts) {
  const Mesh low = test::make_torus(24, 12), high = test::make_torus(96, 48);
  for (bool automatic : {false, true}) {
    BakeOptions o = map_options(48,
                                {MapKind::normal, MapKind::ao, MapKind::bent_normal, MapKind::height, MapKind::thickness,
                                 MapKind::position, MapKind::object_id},
                                -1.0f, -1.0f);
    o.samples = 4;
    o.maps.ao_rays = 16;
    o.maps.ao_rays_auto = automatic;
    o.maps.max_ao_error = 0.05;
    o.threads = 1;
    const BakeResult one = bake_normal_map(low, high, nullptr, o);
    o.threads = 2;
    const BakeResult two = bake_normal_map(low, high, nullptr, o);
    ASSERT_EQ(one.maps.size(), two.maps.size());
    for (std::size_t k = 0; k < one.maps.size(); ++k) {
      EXPECT_TRUE(one.maps[k].image.pixels == two.maps[k].image.pixels) << map_name(one.maps[k].kind) << " auto " << automatic;
      EXPECT_EQ(one.maps[k].rays_mean, two.maps[k].rays_mean) << map_name(one.maps[k].kind);
    }
    if (automatic) {
      EXPECT_GT(one.maps[1].rays_max, one.maps[1].rays_mean);  // ao: more rays where occlusion is partial
    }
  }
}

// A UDIM bake of a layout in one tile gives the single bake's maps.
TEST(MapsUdim, OneTileEqualsTheSingleBake) {
  const Mesh low = test::make_torus(24, 12), high = test::make_torus(96, 48);
  BakeOptions o = map_options(32, {MapKind::normal, MapKind::ao, MapKind::height, MapKind::curvature}, -1.0f, -1.0f);
  o.maps.ao_rays = 8;
  const BakeResult single = bake_normal_map(low, high, nullptr, o);
  const UdimBake udim = bake_udim_tiles(low, high, nullptr, o);
  ASSERT_EQ(udim.tiles.size(), 1u);
  for (std::size_t k = 0; k < single.maps.size(); ++k)
    EXPECT_TRUE(single.maps[k].image.pixels == udim.tiles[0].result.maps[k].image.pixels) << map_name(single.maps[k].kind);
}

}  // namespace
}  // namespace nmbake
