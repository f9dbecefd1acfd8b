// The bake's many-at-a-time steps give exactly the bits of their one-at-a-time definitions:
// cover_tile against covers(), surface_rays against the point / ray-normal formulas of the bake,
// encode_hits_per_pixel against interpolate_frame + encode_tangent_normal. Random triangles
// include slivers, axis-aligned edges, edges through sample points and far-away coordinates.
#include <cstring>
#include <random>

#include <gtest/gtest.h>

#include "ray_batch.h"
#include "rasterize_batch.h"
#include "raycast.h"
#include "shade_batch.h"
#include "tangent_frames.h"

using namespace nmbake;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// UV corners of a random test triangle inside or around a W x H image; `kind` picks the shape.
void random_uvs(std::mt19937& rng, int kind, glm::vec2 uv[3]) {
  std::uniform_real_distribution<float> u(-0.1f, 1.1f), small(-1e-4f, 1e-4f);
  for (int c = 0; c < 3; ++c) uv[c] = {u(rng), u(rng)};
  switch (kind % 5) {
    case 1:  // sliver: third corner almost on the first edge
      uv[2] = 0.5f * (uv[0] + uv[1]) + glm::vec2(small(rng), small(rng));
      break;
    case 2:  // axis-aligned edges on texel-centre lines (64 x 48 image)
      uv[0] = {10.5f / 64, 1.0f - 7.5f / 48};
      uv[1] = {40.5f / 64, 1.0f - 7.5f / 48};
      uv[2] = {10.5f / 64, 1.0f - 30.5f / 48};
      break;
    case 3:  // far outside the image in u
      for (int c = 0; c < 3; ++c) uv[c].x += 3e4f;
      break;
    default:
      break;
  }
}

}  // namespace

TEST(Batch, CoverTileClaimsExactlyWhatCoversDoes) {
  const int W = 64, H = 48, tile = 16;
  const double offsets[][2] = {{0.5, 0.5}, {0.125, 0.375}, {0.625, 0.875}, {0.0, 0.0}};
  std::mt19937 rng(12111);
  std::size_t claimed_total = 0;
  for (int samples : {1, 4}) {
    double ox[4], oy[4];
    for (int k = 0; k < samples; ++k) ox[k] = offsets[samples == 1 ? 0 : k][0], oy[k] = offsets[samples == 1 ? 0 : k][1];
    for (int trial = 0; trial < 400; ++trial) {
      // Two overlapping triangles per tile: the first claims, the second counts overlaps.
      TexelTriangle tt[2];
      for (auto& t : tt) {
        glm::vec2 uv[3];
        random_uvs(rng, trial, uv);
        t = setup_texel_triangle(uv[0], uv[1], uv[2], W, H);
      }
      for (int ty0 = 0; ty0 < H; ty0 += tile)
        for (int tx0 = 0; tx0 < W; tx0 += tile) {
          const std::size_t slots = std::size_t(tile) * tile * samples;
          std::vector<std::int32_t> tri(slots, -1), ref_tri(slots, -1);
          std::vector<double> bary(3 * slots, -1.0), ref_bary(3 * slots, -1.0);
          std::uint64_t overlaps = 0, ref_overlaps = 0;
          for (int i = 0; i < 2; ++i) {
            const TexelTriangle& t = tt[i];
            if (!t.valid()) continue;
            const int x0 = std::max(t.xmin, tx0), x1 = std::min(t.xmax, tx0 + tile - 1);
            const int y0 = std::max(t.ymin, ty0), y1 = std::min(t.ymax, ty0 + tile - 1);
            if (x0 > x1 || y0 > y1) continue;
            overlaps += cover_tile(t, i, tx0, ty0, tile, x0, x1, y0, y1, ox, oy, samples, {tri.data(), bary.data()});
            for (int y = y0; y <= y1; ++y)
              for (int x = x0; x <= x1; ++x)
                for (int k = 0; k < samples; ++k) {
                  double b[3];
                  if (!covers(t, sample_point(x, y, ox[k], oy[k]), b)) continue;
                  const std::size_t s = (std::size_t(y - ty0) * tile + std::size_t(x - tx0)) * samples + k;
                  if (ref_tri[s] >= 0) {
                    ++ref_overlaps;
                    continue;
                  }
                  ref_tri[s] = i;
                  for (int c = 0; c < 3; ++c) ref_bary[3 * s + c] = b[c];
                }
          }
          ASSERT_EQ(overlaps, ref_overlaps) << "trial " << trial;
          for (std::size_t s = 0; s < slots; ++s) {
            ASSERT_EQ(tri[s], ref_tri[s]) << "trial " << trial << " slot " << s;
            claimed_total += tri[s] >= 0;
            for (int c = 0; c < 3; ++c) ASSERT_TRUE(same_bits(bary[3 * s + c], ref_bary[3 * s + c])) << "trial " << trial;
          }
        }
    }
  }
  EXPECT_GT(claimed_total, 100000u);  // the comparison saw real coverage
}

namespace {

LowTriangle random_low_triangle(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  LowTriangle lt;
  for (int c = 0; c < 3; ++c) {
    lt.p[c] = {u(rng), u(rng), u(rng)};
    lt.ray_n[c] = glm::dvec3(glm::normalize(glm::vec3(u(rng), u(rng), 1.0f)));
    const glm::vec3 n = glm::normalize(glm::vec3(u(rng), u(rng), 1.0f));
    const glm::vec3 t = glm::normalize(glm::cross(n, glm::vec3(0.3f, 1.0f, 0.2f)));
    lt.n[c] = glm::dvec3(n);
    lt.t[c] = glm::dvec4(glm::dvec3(t), u(rng) < 0.0 ? -1.0 : 1.0);
  }
  return lt;
}

}  // namespace

TEST(Batch, SurfaceRaysMatchTheOneAtATimeRay) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<LowTriangle> low;
  for (int i = 0; i < 8; ++i) low.push_back(random_low_triangle(rng));
  low[3].ray_n[1] = -low[3].ray_n[0];  // opposite corner normals: cancel at the edge midpoint
  low[3].ray_n[2] = -low[3].ray_n[0];
  const std::size_t n = 103;  // not a multiple of the lane count
  std::vector<std::uint32_t> tri(n);
  std::vector<double> b0(n), b1(n), b2(n);
  for (std::size_t i = 0; i < n; ++i) {
    tri[i] = std::uint32_t(i < 40 ? 2 : (i * 7) % low.size());  // runs of one triangle, then mixed
    b0[i] = u(rng), b1[i] = (1.0 - b0[i]) * u(rng), b2[i] = 1.0 - b0[i] - b1[i];
  }
  b0[50] = 0.5, b1[50] = 0.25, b2[50] = 0.25, tri[50] = 3;  // n cancels: 0.5 n - 0.25 n - 0.25 n
  std::vector<float> f(8 * n);
  std::vector<std::uint8_t> fallback(n);
  const RayArrays rays{&f[0], &f[n], &f[2 * n], &f[3 * n], &f[4 * n], &f[5 * n], &f[6 * n], &f[7 * n]};
  const float front = 0.0371f, rear = 0.0123f;
  surface_rays(low.data(), {tri.data(), b0.data(), b1.data(), b2.data()}, n, front, rear, rays, fallback.data());
  for (std::size_t i = 0; i < n; ++i) {
    const LowTriangle& lt = low[tri[i]];
    const double b[3] = {b0[i], b1[i], b2[i]};
    // The bake's low_point, low_ray_normal and cage-first ray (bake.cpp), written out with glm.
    const glm::dvec3 p = b[0] * lt.p[0] + b[1] * lt.p[1] + b[2] * lt.p[2];
    const glm::dvec3 nr = b[0] * lt.ray_n[0] + b[1] * lt.ray_n[1] + b[2] * lt.ray_n[2];
    const double len2 = glm::dot(nr, nr);
    ASSERT_EQ(fallback[i] != 0, !(len2 > 1e-24)) << i;
    if (fallback[i]) continue;
    const glm::dvec3 unit = nr / std::sqrt(len2);
    const glm::vec3 org(p + double(front) * unit), dir(-unit);
    EXPECT_TRUE(same_bits(rays.org_x[i], org.x) && same_bits(rays.org_y[i], org.y) && same_bits(rays.org_z[i], org.z)) << i;
    EXPECT_TRUE(same_bits(rays.dir_x[i], dir.x) && same_bits(rays.dir_y[i], dir.y) && same_bits(rays.dir_z[i], dir.z)) << i;
    EXPECT_EQ(rays.tnear[i], 0.0f);
    EXPECT_TRUE(same_bits(rays.tfar[i], front + rear));
  }
  EXPECT_TRUE(fallback[50]);
}

TEST(Batch, EncodeMatchesFrameAndEncodeOneAtATime) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_real_distribution<float> uf(-1.0f, 1.0f);
  std::vector<LowTriangle> low;
  for (int i = 0; i < 6; ++i) low.push_back(random_low_triangle(rng));
  std::vector<glm::vec3> high_normals;
  for (int i = 0; i < 3 * 50; ++i) high_normals.push_back(glm::normalize(glm::vec3(uf(rng), uf(rng), 1.0f)));
  high_normals[3 * 7] = high_normals[3 * 7 + 1] = high_normals[3 * 7 + 2] = glm::vec3(0.0f);  // degenerate hit normal
  const std::size_t n = 77;
  std::vector<std::uint32_t> tri(n), hit(n);
  std::vector<double> b0(n), b1(n), b2(n);
  std::vector<float> hu(n), hv(n);
  for (std::size_t i = 0; i < n; ++i) {
    tri[i] = std::uint32_t(i < 30 ? 1 : i % low.size());
    b0[i] = u(rng), b1[i] = (1.0 - b0[i]) * u(rng), b2[i] = 1.0 - b0[i] - b1[i];
    hit[i] = i % 11 == 5 ? raycast::no_hit : std::uint32_t((i * 13) % 50);
    hu[i] = float(u(rng)), hv[i] = float((1.0 - hu[i]) * u(rng));
  }
  std::vector<double> value(3 * n);
  std::vector<std::uint8_t> other(n);
  encode_hits_per_pixel(low.data(), high_normals.data(), {tri.data(), b0.data(), b1.data(), b2.data()},
                        {hit.data(), hu.data(), hv.data()}, n, value.data(), other.data());
  std::size_t checked = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (hit[i] == raycast::no_hit || hit[i] == 7) {
      EXPECT_TRUE(other[i]) << i;
      continue;
    }
    ASSERT_FALSE(other[i]) << i;
    const LowTriangle& lt = low[tri[i]];
    const double b[3] = {b0[i], b1[i], b2[i]};
    const PixelFrame frame = interpolate_frame(lt.n, lt.t, b);
    const double w[3] = {1.0 - double(hu[i]) - double(hv[i]), double(hu[i]), double(hv[i])};
    glm::dvec3 nh(0.0);
    for (int c = 0; c < 3; ++c) nh += w[c] * glm::dvec3(high_normals[3 * hit[i] + c]);
    const glm::dvec3 expect = encode_tangent_normal(frame, nh / glm::length(nh));
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(value[3 * i + c], expect[c])) << i;
    ++checked;
  }
  EXPECT_GT(checked, 50u);
}
