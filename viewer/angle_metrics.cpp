#include "angle_metrics.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <iterator>

namespace nmview {

float angle_between_degrees(const glm::vec3& a, const glm::vec3& b) {
  const double s = double(glm::length(glm::cross(a, b))), c = double(glm::dot(a, b));
  // A zero (or non-finite) vector has no direction: 90, as far from right as from wrong.
  if (!std::isfinite(s) || !std::isfinite(c) || (s == 0.0 && c == 0.0)) return 90.0f;
  return float(std::clamp(std::atan2(s, c) * (180.0 / M_PI), 0.0, 180.0));
}

void AngleStats::add_angle(float degrees) {
  const double d = std::clamp(double(degrees), 0.0, 180.0);
  ++pixels;
  sum_degrees += d;
  ++histogram[std::size_t(std::min(int(d * kBinsPerDegree), kBins - 1))];
}

void AngleStats::add(const AngleStats& other) {
  pixels += other.pixels;
  one_model_pixels += other.one_model_pixels;
  sum_degrees += other.sum_degrees;
  for (int i = 0; i < kBins; ++i) histogram[std::size_t(i)] += other.histogram[std::size_t(i)];
}

double AngleStats::mean() const { return pixels ? sum_degrees / double(pixels) : 0.0; }

double AngleStats::percentile(double fraction) const {
  if (!pixels) return 0.0;
  // The smallest bin whose cumulative count reaches ceil(fraction * pixels), at least one pixel.
  const double wanted = std::max(1.0, std::ceil(std::clamp(fraction, 0.0, 1.0) * double(pixels)));
  std::size_t seen = 0;
  for (int i = 0; i < kBins; ++i) {
    seen += histogram[std::size_t(i)];
    if (double(seen) >= wanted) return double(i + 1) / kBinsPerDegree;
  }
  return 180.0;
}

namespace {

bool normal_covered_at(const NormalImage& image, std::size_t i) { return image.pixels[i].w > 0.5f; }

}  // namespace

AngleStats measure_angles(const NormalImage& low, const NormalImage& high, int erode) {
  assert(low.width == high.width && low.height == high.height);
  assert(erode >= 0);
  const int w = low.width, h = low.height;
  const std::size_t n = std::size_t(w) * std::size_t(h);

  // Covered by both, eroded separably (rows, then columns); outside the image is not covered.
  std::vector<std::uint8_t> both(n), rows(n);
  for (std::size_t i = 0; i < n; ++i) both[i] = normal_covered_at(low, i) && normal_covered_at(high, i);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      bool all = true;
      for (int dx = -erode; dx <= erode && all; ++dx)
        all = x + dx >= 0 && x + dx < w && both[std::size_t(y) * std::size_t(w) + std::size_t(x + dx)];
      rows[std::size_t(y) * std::size_t(w) + std::size_t(x)] = all;
    }

  AngleStats s;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(w) + std::size_t(x);
      if (normal_covered_at(low, i) != normal_covered_at(high, i)) ++s.one_model_pixels;
      bool interior = true;
      for (int dy = -erode; dy <= erode && interior; ++dy)
        interior = y + dy >= 0 && y + dy < h && rows[std::size_t(y + dy) * std::size_t(w) + std::size_t(x)];
      if (interior) s.add_angle(angle_between_degrees(glm::vec3(low.pixels[i]), glm::vec3(high.pixels[i])));
    }
  return s;
}

std::vector<float> angle_image(const NormalImage& low, const NormalImage& high) {
  assert(low.width == high.width && low.height == high.height);
  std::vector<float> angles(low.pixels.size(), -1.0f);
  for (std::size_t i = 0; i < angles.size(); ++i)
    if (normal_covered_at(low, i) && normal_covered_at(high, i))
      angles[i] = angle_between_degrees(glm::vec3(low.pixels[i]), glm::vec3(high.pixels[i]));
  return angles;
}

glm::vec3 angle_colour(float degrees, float scale_degrees) {
  const float v = std::clamp(degrees / std::max(scale_degrees, 1e-6f), 0.0f, 1.0f);
  return {std::clamp(3.0f * v, 0.0f, 1.0f), std::clamp(3.0f * v - 1.0f, 0.0f, 1.0f), std::clamp(3.0f * v - 2.0f, 0.0f, 1.0f)};
}

float angle_from_colour(const glm::vec3& rgb, float scale_degrees) { return (rgb.r + rgb.g + rgb.b) / 3.0f * scale_degrees; }

float next_diff_scale(float current, bool up) {
  static constexpr float kSteps[] = {1, 2, 3, 5, 10, 15, 20, 30, 45, 60, 90, 120, 180};
  if (up) {
    for (float s : kSteps)
      if (s > current * 1.0001f) return s;
    return kSteps[std::size(kSteps) - 1];
  }
  for (auto it = std::rbegin(kSteps); it != std::rend(kSteps); ++it)
    if (*it < current * 0.9999f) return *it;
  return kSteps[0];
}

}  // namespace nmview
