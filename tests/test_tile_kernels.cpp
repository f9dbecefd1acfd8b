// The trace loop's vector kernels (tile_kernels.h) give exactly the bits of their one-sample
// definitions: cover_rect against covers(), the default-policy ray and the cage ray (cage_ray and
// inward_ray), write_texel_row against the texel formula, including the cases each flags or
// special-cases.
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/rasterize.h"
#include "pipeline/rays.h"
#include "trace/shade_batch.h"
#include "test_support.h"
#include "trace/tile_kernels.h"

using namespace nmbake;

namespace {

using nmbake::test::same_bits;

// A rectangle of slots with the arrays SampleSlots points into (with `cage`, tfar, base and
// prefer_lo too).
struct Slots {
  explicit Slots(std::size_t n, bool cage = false)
      : tri(n, -1), b(3 * n), ray(6 * n), fallback(n, 9), tfar(cage ? n : 0), base(cage ? n : 0), prefer_lo(cage ? n : 0) {
    point_view();
  }
  // A copy's view points at the copy's own arrays.
  Slots(const Slots& o)
      : tri(o.tri), b(o.b), ray(o.ray), fallback(o.fallback), tfar(o.tfar), base(o.base), prefer_lo(o.prefer_lo) {
    point_view();
  }
  Slots& operator=(const Slots&) = delete;
  void point_view() {
    const std::size_t n = tri.size();
    view = {tri.data(),
            {&b[0], &b[n], &b[2 * n]},
            {&ray[0], &ray[n], &ray[2 * n]},
            {&ray[3 * n], &ray[4 * n], &ray[5 * n]},
            fallback.data(),
            tfar.empty() ? nullptr : tfar.data(),
            base.empty() ? nullptr : base.data(),
            prefer_lo.empty() ? nullptr : prefer_lo.data()};
  }
  std::vector<std::int32_t> tri;
  std::vector<double> b;
  std::vector<float> ray;
  std::vector<std::uint8_t> fallback;
  std::vector<float> tfar;
  std::vector<double> base;
  std::vector<float> prefer_lo;
  SampleSlots view{};
};

// The default-policy ray by its definition (the bake's sample_rays): P and the normalized ray
// normal interpolated in double, origin P + front N, direction -N, rounded to float.
void reference_ray(const LowTriangle& lt, const double b[3], float front, glm::vec3& org, glm::vec3& dir) {
  const glm::dvec3 p = b[0] * lt.p[0] + b[1] * lt.p[1] + b[2] * lt.p[2];
  glm::dvec3 n = b[0] * lt.ray_n[0] + b[1] * lt.ray_n[1] + b[2] * lt.ray_n[2];
  n = n * (1.0 / std::sqrt(glm::dot(n, n)));
  org = glm::vec3(p + double(front) * n);
  dir = glm::vec3(-n);
}

LowTriangle random_ray_triangle(std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  LowTriangle lt{};
  for (int c = 0; c < 3; ++c) {
    lt.p[c] = glm::dvec3(u(rng), u(rng), u(rng));
    lt.ray_n[c] = glm::dvec3(glm::normalize(glm::vec3(u(rng), u(rng), 1.0f)));
  }
  return lt;
}

// Whether covers() moved the sample of texel (x, y) in from an edge: its barycentrics b are not
// the ones the edges give at the sample point (the rays are made from those).
bool moved_in(const TexelTriangle& tt, int x, int y, double ox, double oy, const double b[3]) {
  double unmoved[3];
  const glm::dvec2 q = sample_point(x, y, ox, oy);
  for (int k = 0; k < 3; ++k) {
    const int e = (k + 1) % 3;  // w[k] comes from edge k + 1
    const double ev = tt.edge_d[e].x * (q.y - tt.edge_a[e].y) - tt.edge_d[e].y * (q.x - tt.edge_a[e].x);
    unmoved[k] = ev * tt.edge_inv_side[e];
  }
  const double sum = unmoved[0] + unmoved[1] + unmoved[2];
  bool moved = false;
  for (int k = 0; k < 3; ++k) moved |= !same_bits(unmoved[k] * (1.0 / sum), b[k]);
  return moved;
}

// Checks one cover_rect call over the triangle's whole box against covers() sample by sample.
// Returns the covered samples; `moved` counts those covers() moved in from an edge.
std::size_t check_triangle(const TexelTriangle& tt, const LowTriangle* low, float front, double ox, double oy,
                           std::size_t* moved) {
  const int w = tt.xmax - tt.xmin + 1, h = tt.ymax - tt.ymin + 1;
  if (w <= 0 || h <= 0) return 0;
  const std::size_t stride = std::size_t(w) + 3;  // rows not packed, as in a tile
  Slots slots(stride * std::size_t(h));
  const KernelRays rays{low, front};
  EXPECT_EQ(cover_rect(tt, 0, tt.xmin, tt.xmax, tt.ymin, tt.ymax, ox, oy, rays, slots.view, 0, stride), 0u);
  std::size_t covered = 0;
  for (int y = tt.ymin; y <= tt.ymax; ++y)
    for (int x = tt.xmin; x <= tt.xmax; ++x) {
      const std::size_t i = std::size_t(y - tt.ymin) * stride + std::size_t(x - tt.xmin);
      double b[3];
      const bool c = covers(tt, sample_point(x, y, ox, oy), b);
      EXPECT_EQ(slots.tri[i], c ? 0 : -1) << x << "," << y;
      if (!c) continue;
      ++covered;
      for (int k = 0; k < 3; ++k) EXPECT_TRUE(same_bits(slots.b[std::size_t(k) * slots.tri.size() + i], b[k])) << x << "," << y;
      if (!low) continue;
      // The ray is made from the unmoved barycentrics: a moved sample must be flagged.
      const bool was_moved = moved_in(tt, x, y, ox, oy, b);
      *moved += was_moved;
      if (was_moved) {
        EXPECT_EQ(slots.fallback[i], 1) << x << "," << y;
        continue;
      }
      EXPECT_EQ(slots.fallback[i], 0) << x << "," << y;
      glm::vec3 org, dir;
      reference_ray(*low, b, front, org, dir);
      const std::size_t n = slots.tri.size();
      for (int k = 0; k < 3; ++k) {
        EXPECT_TRUE(same_bits(slots.ray[std::size_t(k) * n + i], org[k])) << x << "," << y << " origin " << k;
        EXPECT_TRUE(same_bits(slots.ray[std::size_t(3 + k) * n + i], dir[k])) << x << "," << y << " direction " << k;
      }
    }
  return covered;
}

}  // namespace

TEST(TileKernels, CoverRectIsCoversBitForBit) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::size_t covered = 0, moved = 0;
  for (int i = 0; i < 200; ++i) {
    glm::vec2 uv[3];
    for (glm::vec2& c : uv) c = {u(rng), u(rng)};
    if (i % 4 == 0)  // corners on texel centres and edges through them: ties and edge insets
      for (glm::vec2& c : uv) c = (glm::floor(c * 40.0f) + 0.5f) / 40.0f;
    const TexelTriangle tt = setup_texel_triangle(uv[0], uv[1], uv[2], 40, 40);  // either winding
    const LowTriangle lt = random_ray_triangle(rng);
    covered += check_triangle(tt, &lt, 0.01f * float(i % 7), i % 3 ? 0.5 : 0.125, i % 5 ? 0.5 : 0.875, &moved);
    covered += check_triangle(tt, nullptr, 0.0f, 0.5, 0.5, &moved);  // coverage alone
  }
  EXPECT_GT(covered, 10000u);
  EXPECT_GT(moved, 20u);  // the edge cases were reached
}

TEST(TileKernels, CoverRectKeepsTheFirstTriangleAndCountsTheRest) {
  const TexelTriangle tt = setup_texel_triangle({0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}, 8, 8);
  Slots slots(64);
  const std::size_t first = cover_rect(tt, 3, 0, 7, 0, 7, 0.5, 0.5, KernelRays{}, slots.view, 0, 8);
  EXPECT_EQ(first, 0u);
  const std::vector<std::int32_t> after_first = slots.tri;
  std::size_t covered = 0;
  for (std::int32_t t : after_first) covered += t == 3;
  EXPECT_EQ(covered, 36u);  // texel centres strictly below the diagonal plus the tie-broken ones on it
  EXPECT_EQ(cover_rect(tt, 5, 0, 7, 0, 7, 0.5, 0.5, KernelRays{}, slots.view, 0, 8), covered);
  EXPECT_EQ(slots.tri, after_first);
}

TEST(TileKernels, DegenerateRayNormalsAreFlagged) {
  LowTriangle lt{};
  for (int c = 0; c < 3; ++c) lt.p[c] = glm::dvec3(c, c * c, 1.0);  // ray normals all zero
  const TexelTriangle tt = setup_texel_triangle({0.1f, 0.1f}, {0.9f, 0.2f}, {0.3f, 0.8f}, 16, 16);
  Slots slots(256);
  cover_rect(tt, 0, tt.xmin, tt.xmax, tt.ymin, tt.ymax, 0.5, 0.5, KernelRays{&lt, 0.1f}, slots.view,
             std::size_t(tt.ymin) * 16 + std::size_t(tt.xmin), 16);
  std::size_t covered = 0;
  for (std::size_t i = 0; i < 256; ++i)
    if (slots.tri[i] >= 0) {
      ++covered;
      EXPECT_EQ(slots.fallback[i], 1) << i;
    }
  EXPECT_GT(covered, 40u);
}

TEST(TileKernels, CageRaysAreCageRayBitForBit) {
  // With a cage, each covered sample's ray, far end, base and preferred start are inward_ray's of
  // cage_ray's (pipeline/rays.h), or the sample is flagged: moved in from an edge, or its cage
  // point on the low-poly (cage_ray's fallback direction).
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), out(0.0f, 0.2f);
  const double diagonal = 3.0;
  std::size_t checked = 0, beyond = 0, on_low = 0;
  for (int i = 0; i < 150; ++i) {
    glm::vec2 uv[3];
    for (glm::vec2& c : uv) c = {u(rng), u(rng)};
    if (i % 4 == 0)
      for (glm::vec2& c : uv) c = (glm::floor(c * 32.0f) + 0.5f) / 32.0f;
    const TexelTriangle tt = setup_texel_triangle(uv[0], uv[1], uv[2], 32, 32);
    const LowTriangle lt = random_ray_triangle(rng);
    CageTriangle ct;
    for (int c = 0; c < 3; ++c) {
      // Every tenth cage lies on the low-poly (no direction); a third search no farther than the cage.
      ct.corner[c] = i % 10 == 5 ? lt.p[c] : lt.p[c] + double(out(rng)) * lt.ray_n[c];
      ct.rear[c] = double(out(rng));
      ct.search[c] = i % 3 == 0 ? 0.0 : 2.0 * double(out(rng));
    }
    const double ox = i % 3 ? 0.5 : 0.125, oy = i % 5 ? 0.5 : 0.875;
    const int w = tt.xmax - tt.xmin + 1, h = tt.ymax - tt.ymin + 1;
    if (w <= 0 || h <= 0) continue;
    const std::size_t stride = std::size_t(w) + 1, n = stride * std::size_t(h);
    Slots slots(n, true);
    cover_rect(tt, 0, tt.xmin, tt.xmax, tt.ymin, tt.ymax, ox, oy, KernelRays{&lt, 0.0f, &ct, diagonal}, slots.view, 0, stride);
    for (int y = tt.ymin; y <= tt.ymax; ++y)
      for (int x = tt.xmin; x <= tt.xmax; ++x) {
        const std::size_t s = std::size_t(y - tt.ymin) * stride + std::size_t(x - tt.xmin);
        if (slots.tri[s] < 0) continue;
        const double b[3] = {slots.b[s], slots.b[n + s], slots.b[2 * n + s]};
        const CageRay c = cage_ray(lt, ct, b, diagonal);
        if (moved_in(tt, x, y, ox, oy, b) || c.len == 0.0) {
          EXPECT_EQ(slots.fallback[s], 1) << i << ": " << x << "," << y;
          on_low += c.len == 0.0;
          continue;
        }
        ASSERT_EQ(slots.fallback[s], 0) << i << ": " << x << "," << y;
        double base = 0.0;
        float prefer_lo = -1.0f;
        const raycast::Ray r = inward_ray(c, &base, &prefer_lo);
        for (int k = 0; k < 3; ++k) {
          EXPECT_TRUE(same_bits(slots.ray[std::size_t(k) * n + s], r.origin[k])) << i << ": " << x << "," << y;
          EXPECT_TRUE(same_bits(slots.ray[std::size_t(3 + k) * n + s], r.direction[k])) << i << ": " << x << "," << y;
        }
        EXPECT_TRUE(same_bits(slots.tfar[s], r.tfar)) << i << ": " << x << "," << y;
        EXPECT_TRUE(same_bits(slots.base[s], base)) << i << ": " << x << "," << y;
        EXPECT_TRUE(same_bits(slots.prefer_lo[s], prefer_lo)) << i << ": " << x << "," << y;
        ++checked;
        beyond += prefer_lo > 0.0f;
      }
  }
  EXPECT_GT(checked, 5000u);
  EXPECT_GT(beyond, 500u);  // rays searching beyond their cage (a preferred part that starts later)
  EXPECT_GT(on_low, 50u);   // cage points on the low-poly were reached and flagged
}

TEST(TileKernels, CoverRectSamplesIsCoverRectPerOffset) {
  // cover_rect_samples lays a texel's samples side by side; each slot must hold exactly what
  // cover_rect gives for that one offset (coverage, barycentrics, rays, fallback flags, cage
  // fields), including a second triangle over the first (slots kept, the rest counted). 1 to 17
  // samples: short last groups of four or eight; the bake's grids and Hammersley points; corners on
  // texel centres (ties and edge insets), with and without a cage; four lanes and eight.
  std::mt19937 rng(31);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), out(0.0f, 0.2f);
  std::size_t compared = 0, fallbacks = 0;
  for (int i = 0; i < 240; ++i) {
    const int count = 1 + i % 17;
    const int lanes = i % 4 < 2 ? 4 : 8;  // both versions (8 where the CPU runs it)
    if (lanes == 8 && !kernel_lanes_available(8)) continue;
    const std::vector<glm::dvec2> offsets = sample_offsets(count);
    std::vector<double> ox, oy;
    for (const glm::dvec2& o : offsets) ox.push_back(o.x), oy.push_back(o.y);
    glm::vec2 uv[2][3];
    for (auto& tri : uv)
      for (glm::vec2& c : tri) c = {u(rng), u(rng)};
    if (i % 3 == 0)
      for (auto& tri : uv)
        for (glm::vec2& c : tri) c = (glm::floor(c * 24.0f) + 0.5f) / 24.0f;
    const TexelTriangle tt[2] = {setup_texel_triangle(uv[0][0], uv[0][1], uv[0][2], 24, 24),
                                 setup_texel_triangle(uv[1][0], uv[1][1], uv[1][2], 24, 24)};
    const LowTriangle lt[2] = {random_ray_triangle(rng), random_ray_triangle(rng)};
    CageTriangle ct[2];
    for (int t = 0; t < 2; ++t)
      for (int c = 0; c < 3; ++c) {
        ct[t].corner[c] = i % 10 == 5 ? lt[t].p[c] : lt[t].p[c] + double(out(rng)) * lt[t].ray_n[c];
        ct[t].rear[c] = double(out(rng));
        ct[t].search[c] = i % 4 == 0 ? 0.0 : 2.0 * double(out(rng));
      }
    const bool cage = i % 2 == 1;
    const KernelRays rays = cage ? KernelRays{lt, 0.0f, ct, 3.0} : KernelRays{lt, 0.02f};
    // The whole 24 x 24 map as one rectangle; rows padded, as in a tile.
    constexpr int kSide = 24;
    const std::size_t stride = kSide + 2, n = stride * kSide * std::size_t(count);
    Slots together(n, cage);
    std::vector<Slots> apart(std::size_t(count), Slots(stride * kSide, cage));
    for (int t = 0; t < 2; ++t) {
      if (!tt[t].valid() || tt[t].xmax < tt[t].xmin || tt[t].ymax < tt[t].ymin) continue;
      const int x0 = tt[t].xmin, x1 = tt[t].xmax, y0 = tt[t].ymin, y1 = tt[t].ymax;
      std::size_t taken = 0;
      for (int k = 0; k < count; ++k)
        taken += cover_rect(tt[t], t, x0, x1, y0, y1, ox[std::size_t(k)], oy[std::size_t(k)], rays, apart[std::size_t(k)].view,
                            std::size_t(y0) * stride + std::size_t(x0), stride);
      EXPECT_EQ(cover_rect_samples(tt[t], t, x0, x1, y0, y1, ox.data(), oy.data(), count, rays, together.view,
                                   (std::size_t(y0) * stride + std::size_t(x0)) * std::size_t(count), stride * std::size_t(count),
                                   lanes),
                taken)
          << i;
    }
    for (std::size_t s = 0; s < stride * kSide; ++s)
      for (std::size_t k = 0; k < std::size_t(count); ++k) {
        const Slots& a = apart[k];
        const std::size_t j = s * std::size_t(count) + k, m = stride * kSide;
        ASSERT_EQ(together.tri[j], a.tri[s]) << i << ": slot " << s << " sample " << k;
        if (a.tri[s] < 0) continue;
        ++compared;
        for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(together.b[std::size_t(c) * n + j], a.b[std::size_t(c) * m + s])) << i;
        EXPECT_EQ(together.fallback[j], a.fallback[s]) << i;
        fallbacks += a.fallback[s];
        if (a.fallback[s]) continue;  // the caller makes that ray
        for (int c = 0; c < 6; ++c)
          EXPECT_TRUE(same_bits(together.ray[std::size_t(c) * n + j], a.ray[std::size_t(c) * m + s])) << i;
        if (cage) {
          EXPECT_TRUE(same_bits(together.tfar[j], a.tfar[s])) << i;
          EXPECT_TRUE(same_bits(together.base[j], a.base[s])) << i;
          EXPECT_TRUE(same_bits(together.prefer_lo[j], a.prefer_lo[s])) << i;
        }
      }
  }
  EXPECT_GT(compared, 50000u);
  EXPECT_GT(fallbacks, 100u);  // edge insets and cage points on the low-poly were reached
}

TEST(TileKernels, WriteTexelRowIsTheTexelFormula) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int width = 1; width <= 16; ++width)
    for (int flip = 0; flip < 2; ++flip) {
      std::vector<double> acc(4 * 16);
      const TexelSums sums{{&acc[0], &acc[16], &acc[32]}, &acc[48]};
      for (int x = 0; x < 16; ++x) {
        for (int c = 0; c < 3; ++c) sums.sum[c][x] = u(rng);
        sums.count[x] = x < 8 ? double(1 + x % 3) : double(x % 5);               // two blocks all with samples, then some without
        if (x % 7 == 3) sums.sum[0][x] = sums.sum[1][x] = sums.sum[2][x] = 0.0;  // zero sum
        if (x % 6 == 2) sums.sum[1][x] = 1e-9 * sums.sum[0][x];                  // snaps to 0
        if (x % 8 == 5) sums.sum[2][x] = -0.0;                                   // a negative zero
      }
      std::vector<float> rgb(3 * 16, -7.0f);
      std::vector<std::uint8_t> covered(16, 0);
      write_texel_row(sums, 0, width, flip != 0, 1e-6, rgb.data(), covered.data());
      for (int x = 0; x < 16; ++x) {
        if (x >= width || sums.count[x] == 0.0) {
          EXPECT_EQ(covered[x], 0) << x;
          for (int c = 0; c < 3; ++c) EXPECT_EQ(rgb[3 * x + c], -7.0f) << x;
          continue;
        }
        EXPECT_EQ(covered[x], 1) << x;
        glm::dvec3 v(sums.sum[0][x], sums.sum[1][x], sums.sum[2][x]);
        const double len = glm::length(v);
        v = len > 0.0 ? v * (1.0 / len) : glm::dvec3(0, 0, 1);
        if (flip) v.y = -v.y;
        for (int c = 0; c < 3; ++c)
          if (std::abs(v[c]) < 1e-6) v[c] = 0.0;
        for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(rgb[3 * x + c], float(v[c] * 0.5 + 0.5))) << x << " " << c;
      }
    }
}

// compact_samples keeps the covered slots in slot order with their texels; accumulate_samples then
// sums each texel's values in that order, as one addition after another would.
TEST(TileKernels, CompactAndAccumulateKeepSampleOrder) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  constexpr std::size_t kTexels = 64;
  for (int samples = 1; samples <= 5; ++samples) {
    const std::size_t n = kTexels * std::size_t(samples);
    const bool cage = samples % 2 == 0;  // with a cage's per-ray arrays too
    Slots slots(n, cage);
    for (std::size_t i = 0; i < n; ++i) {
      // Runs of covered slots, gaps, and single ones: both the four-at-a-time and the one-by-one paths.
      const bool covered = (i / 9) % 3 != 1 && i % 13 != 4;
      slots.tri[i] = covered ? std::int32_t(i % 7) : -1;
      for (int c = 0; c < 3; ++c) slots.b[std::size_t(c) * n + i] = u(rng);
      for (int c = 0; c < 6; ++c) slots.ray[std::size_t(c) * n + i] = float(u(rng));
      slots.fallback[i] = std::uint8_t(i % 3 == 0);
      if (cage) slots.tfar[i] = float(u(rng)), slots.base[i] = u(rng), slots.prefer_lo[i] = float(u(rng));
    }
    std::vector<std::int32_t> tri(n);
    std::vector<double> b(3 * n);
    std::vector<std::uint16_t> texel(n);
    std::vector<float> ray(6 * n);
    std::vector<std::uint8_t> fallback(n);
    std::vector<float> tfar(n), prefer_lo(n);
    std::vector<double> base(n);
    const CoveredSamples out{tri.data(),
                             {&b[0], &b[n], &b[2 * n]},
                             texel.data(),
                             {&ray[0], &ray[n], &ray[2 * n]},
                             {&ray[3 * n], &ray[4 * n], &ray[5 * n]},
                             fallback.data(),
                             cage ? tfar.data() : nullptr,
                             cage ? base.data() : nullptr,
                             cage ? prefer_lo.data() : nullptr};
    const std::size_t count = compact_samples(slots.view, n, std::size_t(samples), true, out);
    std::size_t r = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (slots.tri[i] < 0) continue;
      ASSERT_LT(r, count);
      EXPECT_EQ(tri[r], slots.tri[i]) << i;
      EXPECT_EQ(texel[r], i / std::size_t(samples)) << i;
      EXPECT_EQ(fallback[r], slots.fallback[i]) << i;
      for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(b[std::size_t(c) * n + r], slots.b[std::size_t(c) * n + i])) << i;
      for (int c = 0; c < 6; ++c) EXPECT_TRUE(same_bits(ray[std::size_t(c) * n + r], slots.ray[std::size_t(c) * n + i])) << i;
      if (cage) {
        EXPECT_TRUE(same_bits(tfar[r], slots.tfar[i])) << i;
        EXPECT_TRUE(same_bits(base[r], slots.base[i])) << i;
        EXPECT_TRUE(same_bits(prefer_lo[r], slots.prefer_lo[i])) << i;
      }
      ++r;
    }
    EXPECT_EQ(count, r);

    // In place (the bake's use): the same entries as the copy, in the slots' own arrays. The
    // pattern starts with a fully covered block (left where it is), then single gaps, where the
    // four-at-a-time moves overlap their source.
    Slots same = slots;
    std::vector<std::uint16_t> same_texel(n, 0xffff);
    const CoveredSamples in_place{same.view.tri,
                                  {same.view.b[0], same.view.b[1], same.view.b[2]},
                                  same_texel.data(),
                                  {same.view.org[0], same.view.org[1], same.view.org[2]},
                                  {same.view.dir[0], same.view.dir[1], same.view.dir[2]},
                                  same.view.ray_fallback,
                                  same.view.tfar,
                                  same.view.base,
                                  same.view.prefer_lo};
    ASSERT_EQ(compact_samples(same.view, n, std::size_t(samples), true, in_place), count);
    for (std::size_t k = 0; k < count; ++k) {
      EXPECT_EQ(same.tri[k], tri[k]) << k;
      EXPECT_EQ(same_texel[k], texel[k]) << k;
      EXPECT_EQ(same.fallback[k], fallback[k]) << k;
      for (int c = 0; c < 3; ++c) EXPECT_TRUE(same_bits(same.b[std::size_t(c) * n + k], b[std::size_t(c) * n + k])) << k;
      for (int c = 0; c < 6; ++c) EXPECT_TRUE(same_bits(same.ray[std::size_t(c) * n + k], ray[std::size_t(c) * n + k])) << k;
      if (cage) {
        EXPECT_TRUE(same_bits(same.tfar[k], tfar[k])) << k;
        EXPECT_TRUE(same_bits(same.base[k], base[k])) << k;
        EXPECT_TRUE(same_bits(same.prefer_lo[k], prefer_lo[k])) << k;
      }
    }

    std::vector<double> value(3 * n);
    for (double& v : value) v = u(rng);
    const double* const value_c[3] = {&value[0], &value[n], &value[2 * n]};
    std::vector<double> acc(4 * kTexels, 0.0), expect(4 * kTexels, 0.0);
    const TexelSums sums{{&acc[0], &acc[kTexels], &acc[2 * kTexels]}, &acc[3 * kTexels]};
    accumulate_samples(value_c, texel.data(), count, sums);
    for (std::size_t i = 0; i < count; ++i) {
      for (int c = 0; c < 3; ++c) expect[std::size_t(c) * kTexels + texel[i]] += value_c[c][i];
      expect[3 * kTexels + texel[i]] += 1.0;
    }
    for (std::size_t i = 0; i < acc.size(); ++i) EXPECT_TRUE(same_bits(acc[i], expect[i])) << samples << " samples, " << i;
  }
}
