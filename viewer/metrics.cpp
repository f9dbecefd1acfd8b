#include "metrics.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace nmview {

void ErrorSums::add(const ErrorSums& other) {
  pixels += other.pixels;
  within2_pixels += other.within2_pixels;
  sum_squared += other.sum_squared;
}

void ErrorSums::add_pixel(const std::uint8_t* a, const std::uint8_t* b) {
  int worst = 0;
  for (int c = 0; c < 3; ++c) {
    const int d = std::abs(int(a[c]) - int(b[c]));
    worst = std::max(worst, d);
    sum_squared += double(d) * double(d) / (255.0 * 255.0);
  }
  ++pixels;
  if (worst <= 2) ++within2_pixels;
}

double ErrorSums::rmse() const { return pixels ? std::sqrt(sum_squared / (3.0 * double(pixels))) : 0.0; }

double ErrorSums::psnr() const {
  const double e = rmse();
  return e > 0.0 ? 20.0 * std::log10(1.0 / e) : std::numeric_limits<double>::infinity();
}

double ErrorSums::within2() const { return pixels ? double(within2_pixels) / double(pixels) : 1.0; }

void DifferenceStats::add(const DifferenceStats& other) {
  interior.add(other.interior);
  object.add(other.object);
  mismatch_pixels += other.mismatch_pixels;
}

double DifferenceStats::silhouette_mismatch() const {
  return object.pixels ? double(mismatch_pixels) / double(object.pixels) : 0.0;
}

DifferenceStats compare_images(const Rgba8Image& a, const Rgba8Image& b, int erode) {
  assert(a.width == b.width && a.height == b.height);
  assert(erode >= 0);
  const int w = a.width, h = a.height;
  const std::size_t n = std::size_t(w) * std::size_t(h);

  // Fully covered by both, then eroded separably (rows, then columns) by `erode` pixels; pixels
  // outside the image count as not covered.
  std::vector<std::uint8_t> full(n), rows(n);
  for (std::size_t i = 0; i < n; ++i) full[i] = a.pixels[4 * i + 3] == 255 && b.pixels[4 * i + 3] == 255;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool all = true;
      for (int dx = -erode; dx <= erode && all; ++dx)
        all = x + dx >= 0 && x + dx < w && full[std::size_t(y) * std::size_t(w) + std::size_t(x + dx)];
      rows[std::size_t(y) * std::size_t(w) + std::size_t(x)] = all;
    }

  DifferenceStats s;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
      const std::uint8_t* pa = &a.pixels[4 * i];
      const std::uint8_t* pb = &b.pixels[4 * i];
      const bool in_a = pa[3] != 0, in_b = pb[3] != 0;
      if (!in_a && !in_b) continue;
      s.object.add_pixel(pa, pb);
      if (in_a != in_b) ++s.mismatch_pixels;
      bool interior = true;
      for (int dy = -erode; dy <= erode && interior; ++dy)
        interior = y + dy >= 0 && y + dy < h && rows[std::size_t(y + dy) * std::size_t(w) + std::size_t(x)];
      if (interior) s.interior.add_pixel(pa, pb);
    }
  return s;
}

}  // namespace nmview
