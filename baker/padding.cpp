#include "padding.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace nmbake {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// 1D squared distance transform of sampled function f (Felzenszwalb and Huttenlocher 2012):
// d[q] = min_p (f[p] + (q - p)^2), arg[q] = the minimizing p (or -1 when all f are infinite).
void distance_1d(const double* f, int n, double* d, int* arg, int* v, double* z) {
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] == kInf) continue;
    if (k < 0) {
      k = 0;
      v[0] = q;
      z[0] = -kInf;
      z[1] = kInf;
      continue;
    }
    // z[0] = -inf stops the loop at k = 0, since s is finite.
    double s = 0.0;
    while (true) {
      const int p = v[k];
      s = ((f[q] + double(q) * q) - (f[p] + double(p) * p)) / (2.0 * (q - p));
      if (s <= z[k]) {
        --k;
        continue;
      }
      break;
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = kInf;
  }
  if (k < 0) {
    for (int q = 0; q < n; ++q) {
      d[q] = kInf;
      arg[q] = -1;
    }
    return;
  }
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while (z[j + 1] < q) ++j;
    const int p = v[j];
    d[q] = double(q - p) * (q - p) + f[p];
    arg[q] = p;
  }
}

}  // namespace

std::size_t pad_islands(Image& image, const std::vector<std::uint8_t>& covered, int padding) {
  if (padding <= 0) return 0;
  const int w = image.width, h = image.height;
  const std::size_t n = std::size_t(w) * h;
  // Nothing to fill from, or nothing to fill: skip the distance transform.
  const std::size_t covered_count = std::size_t(std::count_if(covered.begin(), covered.end(), [](std::uint8_t c) { return c != 0; }));
  if (covered_count == 0 || covered_count == n) return 0;
  // Pass 1, columns: squared distance to the nearest covered texel in the same column.
  std::vector<double> g(n);
  std::vector<int> gy(n);
  {
    const int m = std::max(w, h);
    std::vector<double> f(m), d(m), z(m + 1);
    std::vector<int> arg(m), v(m);
    for (int x = 0; x < w; ++x) {
      for (int y = 0; y < h; ++y) f[y] = covered[std::size_t(y) * w + x] ? 0.0 : kInf;
      distance_1d(f.data(), h, d.data(), arg.data(), v.data(), z.data());
      for (int y = 0; y < h; ++y) {
        g[std::size_t(y) * w + x] = d[y];
        gy[std::size_t(y) * w + x] = arg[y];
      }
    }
    // Pass 2, rows: combine into the exact Euclidean nearest covered texel, then copy it.
    const double limit = double(padding) * padding;
    std::size_t filled = 0;
    for (int y = 0; y < h; ++y) {
      const double* row = &g[std::size_t(y) * w];
      distance_1d(row, w, d.data(), arg.data(), v.data(), z.data());
      for (int x = 0; x < w; ++x) {
        if (covered[std::size_t(y) * w + x] || arg[x] < 0 || d[x] > limit) continue;
        const int sx = arg[x], sy = gy[std::size_t(y) * w + sx];
        const float* src = image.at(sx, sy);
        float* dst = image.at(x, y);
        for (int c = 0; c < image.channels; ++c) dst[c] = src[c];
        ++filled;
      }
    }
    return filled;
  }
}

}  // namespace nmbake
