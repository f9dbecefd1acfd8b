#include "core/padding.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <thread>

#include "core/parallel.h"

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

// pad_islands with the column pass's rows kept as offsets of type G (a signed integer type that
// holds -padding - 1 .. padding + 1 and one more value, kNone).
template <typename G>
std::size_t pad_with(const std::vector<Image*>& images, const std::vector<std::uint8_t>& covered, int padding, int threads, int w,
                     int h) {
  const std::size_t n = std::size_t(w) * h;
  constexpr G kNone = std::numeric_limits<G>::min();
  // The row an offset from row y stands for (-1: none).
  const auto row = [](G o, int y) { return o == kNone ? -1 : y + int(o); };
  // Both passes split into independent parts (columns, then rows) shared out to the threads; each
  // part's result is the same whichever thread computes it.
  //
  // Pass 1, columns: the row of the nearest covered texel in the same column (its squared distance
  // follows from it, and is worked out row by row in pass 2: 8 bytes per texel fewer), as its offset
  // from the texel's row; none (kNone) when it lies more than `padding` rows away, as then every
  // texel it could give is further than `padding` from the texel and is not filled.
  // With every covered texel at 0 and the rest infinite, that is the nearest covered row above or
  // below, the upper one on a tie (as distance_1d, where the parabolas' crossings are the exact
  // midpoints between covered rows, chooses): two scans, one down counting the rows since the last
  // covered one (saturating at kFar, none within `padding`), one up doing the same from below and
  // taking the nearer. Columns go in blocks of up to kBlock neighbours, so the image is read and
  // written a row segment at a time (long enough segments that the next row's is fetched while
  // this one's is worked: 16 columns took twice as long; 1024 or more, longer at 2 threads), and the
  // segment's loop has no branch (what the compiler vectorizes).
  constexpr int kBlock = 256;
  const G kFar = G(padding + 1);
  // Left unset: pass 1 writes every texel's. Its pages are first touched on every thread, in runs of
  // whole pages (the system's zeroing of them shared out), before pass 1 writes them column by
  // column.
  std::vector<G, DefaultInitAllocator<G>> gy;
  touch_storage(threads, storage_for(gy, n));
  gy.resize(n);
  const int m = std::max(w, h);
  // One row further from the last covered texel: 0 on a covered one, else one more, saturating at kFar.
  const auto step = [kFar](G rows, std::uint8_t covered_here) { return covered_here ? G(0) : rows < kFar ? G(rows + 1) : kFar; };
  const auto column_block = [&](int x0, int nb) {
    G near[kBlock];  // per column: rows to the nearest covered texel so far, kFar beyond `padding`
    std::fill(near, near + nb, kFar);
    for (int y = 0; y < h; ++y) {  // down: to the nearest at or above, in gy for now
      const std::uint8_t* c = &covered[std::size_t(y) * w + x0];
      G* g = &gy[std::size_t(y) * w + x0];
      for (int j = 0; j < nb; ++j) g[j] = near[j] = step(near[j], c[j]);
    }
    std::fill(near, near + nb, kFar);
    for (int y = h - 1; y >= 0; --y) {  // up: to the nearest at or below, and the nearer of the two as an offset
      const std::uint8_t* c = &covered[std::size_t(y) * w + x0];
      G* g = &gy[std::size_t(y) * w + x0];
      for (int j = 0; j < nb; ++j) {
        near[j] = step(near[j], c[j]);
        const G above = g[j], below = near[j];
        g[j] = above <= below ? (above < kFar ? G(-above) : kNone) : below;
      }
    }
  };
  // Each thread a run of neighbouring columns, whole multiples of 16 (not blocks dealt round): two
  // threads' columns share the cache lines at their edges only, where dealt-round blocks shared
  // them on every row.
  run_on_threads(threads, [&](int id) {
    const auto edge = [&](int k) { return std::min(w, int(std::int64_t(w) * k / threads) / 16 * 16); };
    const int x1 = id + 1 == threads ? w : edge(id + 1);
    for (int x0 = edge(id); x0 < x1; x0 += kBlock) column_block(x0, std::min(kBlock, x1 - x0));
  });
  // Pass 2, rows: combine into the exact Euclidean nearest covered texel, then copy it. A row
  // writes only its own uncovered texels and reads only covered ones.
  const double limit = double(padding) * padding;
  constexpr int kRows = 16;
  std::vector<std::size_t> filled((h + kRows - 1) / kRows, 0);
  std::atomic<int> next{0};  // parts of kRows rows, each to the first thread free
  run_on_threads(threads, [&](int) {
    std::vector<double> f(w), d(m), z(m + 1);  // the thread's buffers, for every part it takes
    std::vector<int> arg(m), v(m);
    for (int part; (part = next.fetch_add(1)) < int(filled.size());)
      for (int y = part * kRows; y < std::min(h, (part + 1) * kRows); ++y) {
        for (int x = 0; x < w; ++x) {  // the column distances: squared, infinite where none
          const int p = row(gy[std::size_t(y) * w + x], y);
          f[std::size_t(x)] = p < 0 ? kInf : double(y - p) * (y - p);
        }
        distance_1d(f.data(), w, d.data(), arg.data(), v.data(), z.data());
        for (int x = 0; x < w; ++x) {
          if (covered[std::size_t(y) * w + x] || arg[x] < 0 || d[x] > limit) continue;
          const int sx = arg[x], sy = row(gy[std::size_t(y) * w + sx], y);
          for (Image* image : images) {
            const float* src = image->at(sx, sy);
            float* dst = image->at(x, y);
            for (int c = 0; c < image->channels; ++c) dst[c] = src[c];
          }
          ++filled[std::size_t(part)];
        }
      }
  });
  std::size_t total = 0;
  for (std::size_t f : filled) total += f;
  return total;
}

}  // namespace

std::size_t pad_islands(Image& image, const std::vector<std::uint8_t>& covered, int padding, int threads) {
  return pad_islands(std::vector<Image*>{&image}, covered, padding, threads);
}

std::size_t pad_islands(const std::vector<Image*>& images, const std::vector<std::uint8_t>& covered, int padding, int threads) {
  if (padding <= 0 || images.empty()) return 0;
  const int w = images.front()->width, h = images.front()->height;
  const std::size_t n = std::size_t(w) * h;
  // Nothing to fill from, or nothing to fill: skip the distance transform.
  std::atomic<std::size_t> covered_count{0};
  parallel_chunks(threads, n, std::size_t(1) << 20, [&](std::size_t begin, std::size_t end) {
    covered_count += std::size_t(std::count_if(covered.begin() + std::ptrdiff_t(begin), covered.begin() + std::ptrdiff_t(end),
                                               [](std::uint8_t c) { return c != 0; }));
  });
  if (covered_count == 0 || covered_count == n) return 0;
  threads = worker_threads(threads);
  // Pass 1 and 2 with the column pass's answers stored as row offsets in the narrowest type that
  // holds -padding .. padding (one byte for the usual paddings, a quarter of a row index's memory).
  return padding <= 126 ? pad_with<std::int8_t>(images, covered, padding, threads, w, h)
                        : pad_with<std::int32_t>(images, covered, padding, threads, w, h);
}

}  // namespace nmbake
