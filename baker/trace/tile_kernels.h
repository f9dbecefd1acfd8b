// The trace loop's first steps for a tile, four samples per vector operation (eight for a texel's
// samples on an AVX-512 CPU): which samples of a rectangle of texels one triangle covers, with
// their barycentrics, and, for the cage-first policy (default rays or a cage), their rays.
//
// Each result has exactly the bits of its one-sample definition, computed in the same order of
// operations: covers() in rasterize.h for the coverage and barycentrics, and for the rays the
// bake's sample_rays (pipeline/rays.h): without a cage from P + front N along -N over front + rear,
// where P and N interpolate the triangle's corners and N is normalized, rounded to float; with one
// cage_ray and inward_ray. tests/test_tile_kernels.cpp checks them bit for bit. A ray the
// definition makes by a special case (a degenerate ray normal, a cage point on the low-poly, a
// sample moved in from an edge) is flagged for the caller instead.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/rasterize.h"
#include "trace/shade_batch.h"

namespace nmbake {

// A tile's sample slots as arrays. Slot i holds the covering triangle tri[i] (-1: none yet), its
// barycentrics b[0][i], b[1][i], b[2][i], and, when rays are made, the ray's origin and direction
// in org[0..2][i], dir[0..2][i] (float), or ray_fallback[i] = 1 where the caller must make it.
// With cage rays also each ray's far end tfar[i], the distance from P back to its origin base[i]
// (sample_rays' signed_base) and where its preferred part begins, prefer_lo[i].
struct SampleSlots {
  std::int32_t* tri;
  double* b[3];
  float* org[3];
  float* dir[3];
  std::uint8_t* ray_fallback;
  float* tfar = nullptr;
  double* base = nullptr;
  float* prefer_lo = nullptr;
};

// The rays cover_rect makes. Null `low`: none. Else per triangle low[t] and, with `cage`, cage[t]
// (the cage-first policy's inward rays, which reach a sample's own length; `diagonal` the
// scene's, for the degenerate case), or without one the default rays from `front`.
struct KernelRays {
  const LowTriangle* low = nullptr;
  float front = 0.0f;
  const CageTriangle* cage = nullptr;
  double diagonal = 1.0;
};

// For each texel (x, y), x0 <= x <= x1 and y0 <= y <= y1 (texel coordinates), the sample at
// offset (ox, oy) in it: when triangle `t` (set up in `tt`) covers it, slot
// first + (y - y0) * row_stride + (x - x0) takes t, the barycentrics covers() gives and, with
// rays.low, the ray of low[t] there, unless the slot already holds a triangle. Returns how many
// covered samples found their slot taken.
std::size_t cover_rect(const TexelTriangle& tt, std::int32_t t, int x0, int x1, int y0, int y1, double ox, double oy,
                       const KernelRays& rays, const SampleSlots& slots, std::size_t first, std::size_t row_stride);

// cover_rect for `count` samples per texel at once, sample k at offset (ox[k], oy[k]): slot
// first + (y - y0) * row_stride + (x - x0) * count + k, so a texel's samples lie side by side in
// sample order. Each slot gets the bits cover_rect gives it for that one offset (four samples of a
// texel per vector operation instead of four texels; eight on an AVX-512 CPU when `count` is a
// multiple of 8). `lanes`: 0 for the fastest version, 4 or 8 to ask for one (tests; 8 only where
// kernel_lanes_available(8), shade_batch.h).
std::size_t cover_rect_samples(const TexelTriangle& tt, std::int32_t t, int x0, int x1, int y0, int y1, const double* ox,
                               const double* oy, int count, const KernelRays& rays, const SampleSlots& slots, std::size_t first,
                               std::size_t row_stride, int lanes = 0);

// A tile's covered samples, in order, as arrays: triangle, barycentrics, texel of the tile and,
// with rays, the ray's origin and direction and whether the caller must make the ray itself.
struct CoveredSamples {
  std::int32_t* tri;
  double* b[3];
  std::uint16_t* texel;
  float* org[3];
  float* dir[3];
  std::uint8_t* ray_fallback;
  float* tfar = nullptr;  // with cage rays (and SampleSlots' own)
  double* base = nullptr;
  float* prefer_lo = nullptr;
};

// Copies each slot i < slot_count that holds a triangle, in increasing i, to the next entry of
// `out`: triangle, barycentrics, texel i / per_texel and, with `rays`, the ray and its fallback
// flag (and tfar, base and prefer_lo where the slots have them). Returns how many. Slot
// t * per_texel + k is sample k of texel t (cover_rect_samples' layout; cover_rect's with one), so
// each texel's samples come together, in sample order. Texels must number at most 65536. `out`
// may be the slots' own arrays (except texel): the compaction then works in place.
std::size_t compact_samples(const SampleSlots& slots, std::size_t slot_count, std::size_t per_texel, bool rays,
                            const CoveredSamples& out);

// A tile's texels as arrays: per texel, the sums of its samples' values and how many it has.
struct TexelSums {
  double* sum[3];
  double* count;
};

// For each sample i < count, in order: sums.sum[c][texel[i]] += value[c][i] (c = 0, 1, 2) and
// sums.count[texel[i]] += 1.
void accumulate_samples(const double* const value[3], const std::uint16_t* texel, std::size_t count, const TexelSums& sums);

// Texels first .. first + width - 1 of `sums` (one row): each with a positive count is written as
// v * 0.5 + 0.5 (float) to rgb[3x], rgb[3x + 1], rgb[3x + 2] with covered[x] = 1, where v is its
// sum normalized (v * (1 / |v|), or (0, 0, 1) for a zero sum), y negated when flip_y, and each
// component smaller in magnitude than `snap` made exactly 0. Others are left untouched.
void write_texel_row(const TexelSums& sums, std::size_t first, int width, bool flip_y, double snap, float* rgb,
                     std::uint8_t* covered);

}  // namespace nmbake
