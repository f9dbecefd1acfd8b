// --ao-rays auto (MapOptions::ao_rays_auto) and the bent normal against known answers: beside a
// wall auto's AO reaches the standard error asked and its noise is what it reports; it spends its
// rays where occlusion is partial; at a fixed count, the stratified rays beat independent ones. The bent normal beside
// a tall wall tilts away from it by atan(2 / pi) (cosine-weighted rays, no distance limit), in
// tangent space with either green convention; on open ground it is the normal.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "pipeline/bake.h"
#include "pipeline/texel_maps.h"
#include "maps_test_helpers.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::baked;
using test::kPi;
using test::map_options;
using test::wall_ao;

// Two flat-shaded triangles a, b, c and a, c, d (counter-clockwise), no UVs.
void add_quad(Mesh& m, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
  const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  for (const auto& t : {std::array<glm::vec3, 3>{a, b, c}, std::array<glm::vec3, 3>{a, c, d}}) {
    const std::uint32_t p = std::uint32_t(m.positions.size());
    for (const glm::vec3& v : t) m.positions.push_back(v);
    m.normals.push_back(n);
    for (std::uint32_t k = 0; k < 3; ++k) {
      m.position_index.push_back(p + k);
      m.normal_index.push_back(std::uint32_t(m.normals.size() - 1));
    }
    m.source_face.push_back(std::uint32_t(m.source_face.size()));
  }
}

// The ground z = 0 for y in [0, 4] (x in [-half, half]) beside a wall y = 0 facing +y, `height` tall.
Mesh wall_scene(float half, float height) {
  Mesh m;
  m.source = "wall_high";
  add_quad(m, {-half, 0, 0}, {half, 0, 0}, {half, 4, 0}, {-half, 4, 0});
  add_quad(m, {half, 0, 0}, {-half, 0, 0}, {-half, 0, height}, {half, 0, height});
  return m;
}

// The low-poly [-2, 2] x [y0, y1] (u along x, v along y): row `row` of a `size` map lies at y.
double row_y(int row, int size, double y0, double y1) { return y0 + (y1 - y0) * (1.0 - (row + 0.5) / size); }

TEST(MapsAoAuto, BesideAWallReachesTheErrorAsked) {
  const double e = 0.02;
  BakeOptions o = map_options(64, {MapKind::ao});
  o.maps.ao_distance = 1.0;
  o.maps.ao_rays_auto = true;
  o.maps.max_ao_error = e;
  const BakeResult r = bake_normal_map(test::make_grid(8, 8, -2, 2, 0, 4), wall_scene(8, 2), nullptr, o);
  const BakedMap& ao = baked(r, MapKind::ao);
  double sq_resid = 0.0, sq_se = 0.0, n = 0.0;
  for (int y = 0; y < 64; ++y)
    for (int x = 16; x < 48; ++x) {  // away from the wall's ends
      const std::size_t i = std::size_t(y) * 64 + std::size_t(x);
      const double expect = wall_ao(row_y(y, 64, 0, 4), 1.0);
      EXPECT_LE(ao.error.pixels[i], e + 1e-6);  // every texel stopped at E (the cap, 1024 rays, is not reached here)
      if (expect > 0.9) continue;               // the partial texels, where rays were added
      const double d = ao.image.pixels[i] - expect;
      sq_resid += d * d, sq_se += double(ao.error.pixels[i]) * ao.error.pixels[i], n += 1.0;
    }
  ASSERT_GT(n, 300.0);
  const double rms = std::sqrt(sq_resid / n), reported = std::sqrt(sq_se / n);
  EXPECT_LT(rms, 1.15 * e);         // 300+ texels: the RMS of their errors is within 10% of its own value
  EXPECT_GT(rms / reported, 0.75);  // the noise is what the map reports it to be
  EXPECT_LT(rms / reported, 1.25);
  EXPECT_GT(ao.rays_mean, 32.0);
  EXPECT_LE(ao.rays_max, 1024.0);
}

TEST(MapsAoAuto, FewerRaysOnOpenTexelsThanOnPartialOnes) {
  BakeOptions o = map_options(32, {MapKind::ao});
  o.maps.ao_distance = 1.0;
  o.maps.ao_rays_auto = true;
  const Mesh high = wall_scene(8, 2);
  // Open: beyond the AO distance from the wall. Partial: within half of it (AO 0.5 to 0.82).
  const BakeResult open = bake_normal_map(test::make_grid(4, 4, -2, 2, 1.5, 4), high, nullptr, o);
  const BakeResult partial = bake_normal_map(test::make_grid(4, 4, -2, 2, 0.01f, 0.5), high, nullptr, o);
  const BakedMap &a = baked(open, MapKind::ao), &b = baked(partial, MapKind::ao);
  // An open texel: 32 rays (8 chains of 4), all open; chains that agree are taken to be no finer
  // than one ray in 4 (standard error sqrt(1 / 96 / 8) = 0.036 > E = 0.02), so it adds the rays
  // that would reach E at the rate n^-0.7 (42, in whole rounds of 8 chains: 48); at 80 rays (10 a
  // chain) that floor is 0.0144: stop.
  EXPECT_EQ(a.rays_max, 80.0);
  EXPECT_EQ(a.rays_mean, 80.0);
  EXPECT_GT(b.rays_mean, 1.2 * a.rays_mean);
  EXPECT_GT(b.rays_max, 2.0 * a.rays_max);
  for (float v : a.image.pixels) EXPECT_EQ(v, 1.0f);
}

// Beside the wall at a fixed 64 rays: the texel's stratified chains give a smaller error than as
// many independent random rays (MapOptions::ao_independent_rays), and each reports its noise.
TEST(MapsAo, StratifiedRaysBeatIndependentOnesBesideAWall) {
  double rms[2];
  for (int independent = 0; independent < 2; ++independent) {
    BakeOptions o = map_options(64, {MapKind::ao});
    o.maps.ao_distance = 1.0;
    o.maps.ao_rays = 64;
    o.maps.ao_independent_rays = independent == 1;
    const BakeResult r = bake_normal_map(test::make_grid(8, 8, -2, 2, 0, 4), wall_scene(8, 2), nullptr, o);
    const BakedMap& ao = baked(r, MapKind::ao);
    double sq_resid = 0.0, sq_se = 0.0, n = 0.0;
    for (int y = 0; y < 64; ++y)
      for (int x = 16; x < 48; ++x) {
        const std::size_t i = std::size_t(y) * 64 + std::size_t(x);
        const double expect = wall_ao(row_y(y, 64, 0, 4), 1.0);
        if (expect > 0.9) continue;
        const double d = ao.image.pixels[i] - expect;
        sq_resid += d * d, sq_se += double(ao.error.pixels[i]) * ao.error.pixels[i], n += 1.0;
      }
    ASSERT_GT(n, 300.0);
    rms[independent] = std::sqrt(sq_resid / n);
    const double ratio = rms[independent] / std::sqrt(sq_se / n);
    EXPECT_GT(ratio, 0.7) << "independent " << independent;
    EXPECT_LT(ratio, 1.3) << "independent " << independent;
  }
  // Independent: about sqrt(p (1 - p) / 64) = 0.055 at p = 0.7 (measured 0.055). Stratified: 0.016
  // measured (one straight horizon per texel: the stratified case at its best).
  EXPECT_LT(rms[0], 0.4 * rms[1]) << rms[0] << " " << rms[1];
}

// Beside a tall, long wall (no distance limit) the unoccluded rays are those heading away from it:
// the mean of cosine-weighted directions over that half of the hemisphere is (0, 4 / (3 pi), 2 / 3),
// tilted atan(2 / pi) = 32.48 degrees from the normal, away from the wall (+y: green up, G > 0.5).
TEST(MapsBentNormal, BesideATallWallTiltsAwayByTheAnalyticAngle) {
  const double tilt = std::atan(2.0 / kPi);
  EXPECT_NEAR(tilt * 180.0 / kPi, 32.48, 0.01);
  for (bool green_down : {false, true}) {
    BakeOptions o = map_options(32, {MapKind::bent_normal});
    o.maps.ao_distance = 1e4;
    o.maps.ao_rays = 256;
    o.green_down = green_down;
    // Ground within 0.05 to 0.25 of a wall 100 long and 50 tall: the rays passing it are about 0.5%.
    const BakeResult r = bake_normal_map(test::make_grid(4, 4, -2, 2, 0.05f, 0.25f), wall_scene(50, 50), nullptr, o);
    const Image& b = baked(r, MapKind::bent_normal).image;
    glm::dvec3 mean(0.0);
    for (std::size_t i = 0; i < b.pixels.size() / 3; ++i) {
      const glm::dvec3 v(2.0 * b.pixels[3 * i] - 1.0, 2.0 * b.pixels[3 * i + 1] - 1.0, 2.0 * b.pixels[3 * i + 2] - 1.0);
      EXPECT_NEAR(glm::length(v), 1.0, 2e-3);
      // Each texel's 256 rays: its lateral noise about 0.25 / sqrt(128) of a unit.
      EXPECT_NEAR(std::atan2(green_down ? -v.y : v.y, v.z), tilt, 0.15) << i;
      mean += v;
    }
    mean /= double(b.pixels.size() / 3);
    EXPECT_NEAR(mean.x, 0.0, 0.01);
    EXPECT_NEAR(std::atan2(green_down ? -mean.y : mean.y, mean.z), tilt, 0.01) << "green down " << green_down;
    EXPECT_EQ(mean.y > 0.0, !green_down);
  }
}

TEST(MapsBentNormal, OnOpenGroundIsTheNormal) {
  BakeOptions o = map_options(32, {MapKind::bent_normal, MapKind::ao});
  o.maps.ao_distance = 1.0;
  o.maps.ao_rays = 256;
  const BakeResult r = bake_normal_map(test::make_grid(4, 4, -2, 2, 1.5, 4), wall_scene(8, 2), nullptr, o);
  const Image& b = baked(r, MapKind::bent_normal).image;
  glm::dvec3 mean(0.0);
  for (std::size_t i = 0; i < b.pixels.size() / 3; ++i) {
    const glm::dvec3 v(2.0 * b.pixels[3 * i] - 1.0, 2.0 * b.pixels[3 * i + 1] - 1.0, 2.0 * b.pixels[3 * i + 2] - 1.0);
    EXPECT_GT(v.z, std::cos(0.2)) << i;  // within the noise of 256 rays' mean
    mean += v;
  }
  mean = glm::normalize(mean);
  EXPECT_NEAR(mean.x, 0.0, 0.01);
  EXPECT_NEAR(mean.y, 0.0, 0.01);
  for (float v : baked(r, MapKind::ao).image.pixels) EXPECT_EQ(v, 1.0f);
}

}  // namespace
}  // namespace nmbake

// The memory check counts auto's per-texel ray counts: one float per texel for AO's rays (ao or
// bent-normal) and one for thickness's, the images allocate_map_targets makes.
TEST(MapsAoAuto, MemoryEstimateCountsTheRaysPerTexel) {
  BakeOptions o;
  o.width = 64;
  o.height = 32;
  const std::uint64_t texels = 64 * 32;
  const std::pair<std::vector<MapKind>, std::uint64_t> cases[] = {{{MapKind::normal, MapKind::ao}, 1},
                                                                  {{MapKind::normal, MapKind::bent_normal}, 1},
                                                                  {{MapKind::normal, MapKind::ao, MapKind::thickness}, 2},
                                                                  {{MapKind::normal, MapKind::thickness}, 1},
                                                                  {{MapKind::normal, MapKind::height}, 0}};
  for (const auto& [maps, ray_images] : cases) {
    o.maps.maps = maps;
    o.maps.ao_rays_auto = false;
    const std::uint64_t fixed = estimate_bake_bytes(o);
    o.maps.ao_rays_auto = true;
    const MapTargets targets = allocate_map_targets(o.maps, o.width, o.height);
    EXPECT_EQ(targets.ao_rays.pixels.size() + targets.thickness_rays.pixels.size(), ray_images * texels) << maps.size();
    EXPECT_EQ(estimate_bake_bytes(o) - fixed, 4 * ray_images * texels) << maps.size();
  }
}
