// Rasterization of a mesh's UV layout at texel sample points.
//
// Texel (x, y) of a W x H image has its centre at u = (x + 0.5) / W, v = 1 - (y + 0.5) / H
// (row 0 is the top, v = 1). A sample at offset (ox, oy) in [0,1)^2 inside the texel lies at
// u = (x + ox) / W, v = 1 - (y + oy) / H. Coverage uses exact edge functions in double precision
// with a tie rule that gives a point on an edge shared by two triangles to exactly one of them,
// so shared UV edges leave no cracks and count nothing twice. UV-degenerate triangles (zero area)
// cover nothing. Where UV islands overlap, the triangle with the lowest index wins.
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/codec.h"
#include "core/mesh.h"

namespace nmbake {

// Edge setup of one triangle in texel space (x right, y down, in texels).
struct TexelTriangle {
  glm::dvec2 p[3];     // corners in texel space
  double area2 = 0.0;  // twice the signed area in texel space (0: degenerate, covers nothing)
  // Edge k (corners k, k+1, opposite corner k+2) from its lexicographically smaller end `a` along
  // `d`, and the signed value of the opposite corner (`side`) in that edge function.
  glm::dvec2 edge_a[3], edge_d[3];
  double edge_side[3] = {0, 0, 0};
  double edge_inv_side[3] = {0, 0, 0};           // 1 / edge_side: the barycentric weights multiply by it
  int xmin = 0, xmax = -1, ymin = 0, ymax = -1;  // inclusive texel bounding box, clipped to image
  bool valid() const { return area2 != 0.0; }
};

TexelTriangle setup_texel_triangle(glm::vec2 uv0, glm::vec2 uv1, glm::vec2 uv2, int width, int height);

// A sample on an edge (a texel centre on a UV edge) lies on the 3D edge too, where a high-poly
// with the same edge (coincident, or hard-edged) ties between two triangles and the ray may take
// the neighbour's normal. Moving it kEdgeInset inside its own triangle breaks the tie; samples
// farther inside are untouched.
constexpr double kEdgeInset = 1e-5;
// Returns whether it moved the sample.
inline bool inset_from_edges(double bary[3]) {
  if (!(bary[0] < kEdgeInset || bary[1] < kEdgeInset || bary[2] < kEdgeInset)) return false;
  double s = 0.0;
  for (int k = 0; k < 3; ++k) s += (bary[k] = std::max(bary[k], kEdgeInset));
  for (int k = 0; k < 3; ++k) bary[k] /= s;
  return true;
}

// The coverage test, written once over the number type (double for one sample here, four lanes in
// trace/tile_kernels.cpp). Edge k's value at q is d.x * (q.y - a.y) - d.y * (q.x - a.x); `row` holds
// the first products (one per edge, shared by a row of samples). A sample is covered by edge k when
// strictly inside, or on the edge with this triangle on the edge's positive side: of two triangles
// sharing an edge exactly one covers it. `in` is and-ed with the result (a bool, or a lane mask);
// w receives the unnormalized barycentric weights. (`row` may also be per lane: samples of one
// texel at different heights.)
template <typename T, typename Mask, typename Row>
[[gnu::always_inline]] inline void edge_weights(Mask& in, T w[3], const TexelTriangle& tri, const Row row[3], const T& qx,
                                                const T& zero) {
  for (int k = 0; k < 3; ++k) {
    const T e = row[k] - tri.edge_d[k].y * (qx - tri.edge_a[k].x);
    // e < 0 rejects when the opposite corner is on the positive side, else e >= 0 (a NaN passes
    // both tests; the sum test rejects it).
    in &= codec::Ops<T>::invert(tri.edge_side[k] > 0.0 ? codec::Ops<T>::lt(e, zero) : codec::Ops<T>::ge(e, zero));
    w[(k + 2) % 3] = e * tri.edge_inv_side[k];
  }
}
// The weights' sum, which must be positive and finite (and-ed into `in`).
template <typename T, typename Mask>
[[gnu::always_inline]] inline void weight_sum(Mask& in, T& sum, const T w[3], const T& zero) {
  sum = w[0] + w[1] + w[2];
  in &= codec::Ops<T>::gt(sum, zero) & codec::Ops<T>::le(sum, zero + DBL_MAX);
}
// The barycentrics: the weights times 1 / sum.
template <typename T>
[[gnu::always_inline]] inline void normalize_weights(T bary[3], const T w[3], const T& sum) {
  const T inv_sum = 1.0 / sum;
  for (int k = 0; k < 3; ++k) bary[k] = w[k] * inv_sum;
}

// True when sample point q (texel space) is covered; then bary receives the weights of corners
// 0, 1, 2 (they sum to 1 and are each in [0,1]). A sample on an edge gets weights of at least 1e-5
// (moved just inside its triangle, so a coincident high-poly cannot tie with the neighbour).
// Inline: the bake calls it per sample.
inline bool covers(const TexelTriangle& tri, glm::dvec2 q, double bary[3]) {
  if (tri.area2 == 0.0) return false;
  double row[3], w[3], sum;
  for (int k = 0; k < 3; ++k) row[k] = tri.edge_d[k].x * (q.y - tri.edge_a[k].y);
  bool in = true;
  edge_weights(in, w, tri, row, q.x, 0.0);
  weight_sum(in, sum, w, 0.0);
  if (!in) return false;
  normalize_weights(bary, w, sum);
  inset_from_edges(bary);
  return true;
}

// Texel-space position of sample (ox, oy) of texel (x, y).
inline glm::dvec2 sample_point(int x, int y, double ox, double oy) { return {x + ox, y + oy}; }

// Per texel (row-major from the top), the index of the triangle covering its centre, or -1.
// `overlaps` (optional) receives the number of texel centres covered by more than one triangle.
std::vector<std::int32_t> rasterize_texel_triangles(const Mesh& mesh, int width, int height, std::size_t* overlaps = nullptr);

}  // namespace nmbake
