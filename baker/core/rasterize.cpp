#include "core/rasterize.h"

#include <algorithm>
#include <cmath>

namespace nmbake {

namespace {

// Clamp a texel-space coordinate before converting to int so huge or tiled UVs cannot overflow.
int clamp_floor(double x, int lo, int hi) {
  if (!(x > lo)) return lo;
  if (!(x < hi)) return hi;
  return int(std::floor(x));
}

bool less(const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }

}  // namespace

TexelTriangle setup_texel_triangle(glm::vec2 uv0, glm::vec2 uv1, glm::vec2 uv2, int width, int height) {
  TexelTriangle t;
  const glm::vec2 uv[3] = {uv0, uv1, uv2};
  for (int i = 0; i < 3; ++i) t.p[i] = glm::dvec2(double(uv[i].x) * width, (1.0 - double(uv[i].y)) * height);
  const glm::dvec2 e1 = t.p[1] - t.p[0], e2 = t.p[2] - t.p[0];
  t.area2 = e1.x * e2.y - e1.y * e2.x;
  if (!std::isfinite(t.area2)) t.area2 = 0.0;
  if (t.area2 == 0.0) return t;
  for (int k = 0; k < 3; ++k) {
    // Evaluating each edge from its lexicographically smaller end makes its value bit-identical
    // for both triangles sharing it.
    glm::dvec2 a = t.p[k], b = t.p[(k + 1) % 3];
    if (less(b, a)) std::swap(a, b);
    const glm::dvec2 c = t.p[(k + 2) % 3];
    t.edge_a[k] = a;
    t.edge_d[k] = b - a;
    t.edge_side[k] = t.edge_d[k].x * (c.y - a.y) - t.edge_d[k].y * (c.x - a.x);
    if (t.edge_side[k] == 0.0) {  // collinear in texel space after rounding: covers nothing
      t.area2 = 0.0;
      return t;
    }
    // Finite: edge_side is a difference of products of float-derived coordinates, never near 1e-308.
    t.edge_inv_side[k] = 1.0 / t.edge_side[k];
  }
  const double minx = std::min({t.p[0].x, t.p[1].x, t.p[2].x}), maxx = std::max({t.p[0].x, t.p[1].x, t.p[2].x});
  const double miny = std::min({t.p[0].y, t.p[1].y, t.p[2].y}), maxy = std::max({t.p[0].y, t.p[1].y, t.p[2].y});
  // Any sample x + ox with ox in [0,1) inside [minx, maxx] has x in [floor(minx), floor(maxx)].
  t.xmin = clamp_floor(minx, 0, width);
  t.xmax = clamp_floor(maxx, -1, width - 1);
  t.ymin = clamp_floor(miny, 0, height);
  t.ymax = clamp_floor(maxy, -1, height - 1);
  if (maxx < 0.0) t.xmax = -1;
  if (maxy < 0.0) t.ymax = -1;
  return t;
}

std::vector<std::int32_t> rasterize_texel_triangles(const Mesh& mesh, int width, int height, std::size_t* overlaps) {
  std::vector<std::int32_t> owner(std::size_t(width) * height, -1);
  std::size_t overlapped = 0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const TexelTriangle tri =
        setup_texel_triangle(mesh.corner_uv(t, 0), mesh.corner_uv(t, 1), mesh.corner_uv(t, 2), width, height);
    if (!tri.valid()) continue;
    for (int y = tri.ymin; y <= tri.ymax; ++y)
      for (int x = tri.xmin; x <= tri.xmax; ++x) {
        double bary[3];
        if (!covers(tri, sample_point(x, y, 0.5, 0.5), bary)) continue;
        std::int32_t& o = owner[std::size_t(y) * width + x];
        if (o < 0) o = std::int32_t(t);
        else ++overlapped;
      }
  }
  if (overlaps) *overlaps = overlapped;
  return owner;
}

}  // namespace nmbake
