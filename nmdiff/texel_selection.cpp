#include "texel_selection.h"

#include <algorithm>
#include <cmath>

namespace nmbake::diff {
namespace {

bool alpha_covers(const Image& m, std::size_t i) {
  const int c = m.channels == 2 ? 1 : m.channels >= 4 ? 3 : -1;
  return c < 0 || m.pixels[i * std::size_t(m.channels) + std::size_t(c)] >= 0.5f;
}

}  // namespace

TexelSelection select_texel(const Image& a, const Image& b, std::size_t i, const std::vector<std::uint8_t>& mask, bool use_alpha,
                            bool include_padding) {
  const bool in_layout = mask.empty() || mask[i] != 0;
  const bool in_alpha = !use_alpha || (alpha_covers(a, i) && alpha_covers(b, i));
  if (in_layout && in_alpha) return TexelSelection::compared;
  if (include_padding) return TexelSelection::padding;
  return in_layout ? TexelSelection::outside_alpha : TexelSelection::outside_mask;
}

void DiffTally::add(std::size_t i, int width, double d) {
  if (d > max || worst_x < 0) {
    max = d;
    worst_x = static_cast<int>(i % static_cast<std::size_t>(width));
    worst_y = static_cast<int>(i / static_cast<std::size_t>(width));
  }
  sum += d;
  sum_sq += d * d;
  values.push_back(static_cast<float>(d));
}

DiffTally::Summary DiffTally::summary() {
  Summary m;
  if (values.empty()) return m;
  const double n = static_cast<double>(values.size());
  m.mean = sum / n;
  m.rms = std::sqrt(sum_sq / n);
  m.p95 = percentile(values, 0.95);
  m.p99 = percentile(values, 0.99);
  return m;
}

double percentile(std::vector<float>& values, double p) {
  if (values.empty()) return 0.0;
  const std::size_t rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(values.size())));
  const std::size_t index = std::min(values.size() - 1, rank == 0 ? 0 : rank - 1);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(index), values.end());
  return values[index];
}

}  // namespace nmbake::diff
