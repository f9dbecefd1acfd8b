#include "rasterize_batch.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace nmbake {
namespace {

// Four doubles, one per sample, and their comparison masks. Plain IEEE operations lane by lane:
// no reassociation and no fused multiply-add (ISO C++ builds do not contract), so each lane rounds
// exactly as covers() does.
typedef double V __attribute__((vector_size(32)));
typedef long long M __attribute__((vector_size(32)));
constexpr int kLanes = 4;

// The x extent [lo, hi] of the triangle on the line y = qy: the extreme crossings of the edges
// whose y range (widened by tol) holds qy. False when there is none.
bool row_span(const TexelTriangle& tt, double qy, double tol, double& lo, double& hi) {
  lo = std::numeric_limits<double>::infinity();
  hi = -lo;
  for (int e = 0; e < 3; ++e) {
    const glm::dvec2 a = tt.edge_a[e], d = tt.edge_d[e];
    if (qy < std::min(a.y, a.y + d.y) - tol || qy > std::max(a.y, a.y + d.y) + tol) continue;
    if (d.y == 0.0) {
      lo = std::min({lo, a.x, a.x + d.x});
      hi = std::max({hi, a.x, a.x + d.x});
    } else {
      const double xc = a.x + d.x * ((qy - a.y) / d.y);
      lo = std::min(lo, xc);
      hi = std::max(hi, xc);
    }
  }
  return lo <= hi;
}

}  // namespace

// Two versions, chosen once at load time by the CPU: AVX2 and the baseline (SSE2, two lanes per
// instruction). Neither uses FMA.
__attribute__((target_clones("avx2", "default"))) std::uint64_t cover_tile(
    const TexelTriangle& tt, std::int32_t t, int tx0, int ty0, int tile, int x0, int x1, int y0, int y1, const double* ox,
    const double* oy, int samples, const TileSlots& slots) {
  constexpr double kEdgeInset = 1e-5;  // as in covers()
  const V lane = {0.0, 1.0, 2.0, 3.0};
  // Rows are tested only between the triangle's edge crossings, widened by a margin far larger
  // than any rounding of the crossings or of covers()' edge functions: the exact test decides.
  double extent = 0.0;
  for (const glm::dvec2& c : tt.p) extent = std::max({extent, std::abs(c.x), std::abs(c.y)});
  const double tol = 1e-6 * (1.0 + extent), margin = 1.0 + tol;
  std::uint64_t overlaps = 0;
  for (int y = y0; y <= y1; ++y)
    for (int k = 0; k < samples; ++k) {
      const double qy = double(y) + oy[k];
      int xa = x0, xb = x1;
      if (x1 - x0 >= 2 * kLanes) {  // a short row costs less to test whole than to clip
        double lo, hi;
        if (!row_span(tt, qy, tol, lo, hi)) continue;  // the row misses the triangle
        xa = int(std::max(double(x0), std::ceil(lo - margin - ox[k])));
        xb = int(std::min(double(x1), std::floor(hi + margin - ox[k])));
      }
      for (int x = xa; x <= xb; x += kLanes) {
        // q.x = x + ox exactly as sample_point() forms it: int to double (exact), then one add.
        const V qx = (double(x) + lane) + ox[k];
        M fail = {0, 0, 0, 0};
        V w[3];
        for (int e = 0; e < 3; ++e) {
          const double side = tt.edge_side[e];
          const V ev = tt.edge_d[e].x * (qy - tt.edge_a[e].y) - tt.edge_d[e].y * (qx - tt.edge_a[e].x);
          fail |= side > 0.0 ? (ev < 0.0) : (ev >= 0.0);
          w[(e + 2) % 3] = ev / side;
        }
        const V sum = w[0] + w[1] + w[2];
        // !(sum > 0) or not finite (sum - sum is 0 exactly when sum is finite).
        fail |= ~(sum > 0.0) | ~((sum - sum) == 0.0);
        V b[3] = {w[0] / sum, w[1] / sum, w[2] / sum};
        const M inset = (b[0] < kEdgeInset) | (b[1] < kEdgeInset) | (b[2] < kEdgeInset);
        const M moved = inset & ~fail;
        if ((moved[0] | moved[1] | moved[2] | moved[3]) != 0) {
          V c[3];
          for (int i = 0; i < 3; ++i) c[i] = b[i] < kEdgeInset ? V{} + kEdgeInset : b[i];  // std::max(b, inset)
          const V s = c[0] + c[1] + c[2];
          for (int i = 0; i < 3; ++i) b[i] = inset ? c[i] / s : b[i];
        }
        for (int l = 0; l < kLanes && x + l <= xb; ++l) {
          if (fail[l]) continue;
          const std::size_t slot = (std::size_t(y - ty0) * tile + std::size_t(x + l - tx0)) * samples + k;
          if (slots.tri[slot] >= 0) {
            ++overlaps;
            continue;
          }
          slots.tri[slot] = t;
          slots.bary[3 * slot] = b[0][l];
          slots.bary[3 * slot + 1] = b[1][l];
          slots.bary[3 * slot + 2] = b[2][l];
        }
      }
    }
  return overlaps;
}

}  // namespace nmbake
