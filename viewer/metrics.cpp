#include "metrics.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdlib>
#include <limits>

namespace nmview {

void DifferenceStats::add(const DifferenceStats& other) {
  object_pixels += other.object_pixels;
  within2_pixels += other.within2_pixels;
  sum_squared += other.sum_squared;
  shared_pixels += other.shared_pixels;
  shared_sum_squared += other.shared_sum_squared;
}

double DifferenceStats::rmse() const {
  return object_pixels ? std::sqrt(sum_squared / (3.0 * double(object_pixels))) : 0.0;
}

double DifferenceStats::shared_rmse() const {
  return shared_pixels ? std::sqrt(shared_sum_squared / (3.0 * double(shared_pixels))) : 0.0;
}

double DifferenceStats::psnr() const {
  double e = rmse();
  return e > 0.0 ? 20.0 * std::log10(1.0 / e) : std::numeric_limits<double>::infinity();
}

double DifferenceStats::within2() const {
  return object_pixels ? double(within2_pixels) / double(object_pixels) : 1.0;
}

DifferenceStats compare_images(const Rgba8Image& a, const Rgba8Image& b) {
  assert(a.width == b.width && a.height == b.height);
  DifferenceStats s;
  const std::size_t n = std::size_t(a.width) * std::size_t(a.height);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* pa = &a.pixels[4 * i];
    const std::uint8_t* pb = &b.pixels[4 * i];
    if (pa[3] == 0 && pb[3] == 0) continue;
    ++s.object_pixels;
    int worst = 0;
    double squared = 0.0;
    for (int c = 0; c < 3; ++c) {
      int d = std::abs(int(pa[c]) - int(pb[c]));
      worst = std::max(worst, d);
      squared += double(d) * double(d) / (255.0 * 255.0);
    }
    s.sum_squared += squared;
    if (worst <= 2) ++s.within2_pixels;
    if (pa[3] != 0 && pb[3] != 0) {
      ++s.shared_pixels;
      s.shared_sum_squared += squared;
    }
  }
  return s;
}

}  // namespace nmview
