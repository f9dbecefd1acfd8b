// The angle between the low-poly's shading normal and the high-poly's normal seen at the same pixel
// (CPU only): the difference pane's colour scale and --compare's angle figures.
//
// Both normals are rendered by Renderer::render_normals into single-sample float targets from one
// camera: the low-poly's is exactly what its lit pane shades with (the interpolated frame perturbed
// by the decoded map, or the bare interpolated normal), the high-poly's is its own, both unit and in
// the re-centred scene space (object space translated; directions are unchanged). A pixel is
// compared only where both models cover it; one covered by one model only is silhouette mismatch
// (metrics.h), counted apart and never as an angle.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

namespace nmview {

// Float normals of one model, row 0 at the top. `covered` 0 = background.
struct NormalImage {
  int width = 0;
  int height = 0;
  std::vector<glm::vec4> pixels;  // xyz = unit normal, scene space; w = 1 where the model covers the pixel, else 0
};

// The angle in degrees (0..180) between two unit vectors, well conditioned near 0 and 180
// (atan2 of |a x b| and a.b). Non-unit inputs are fine; a zero vector gives 90, never NaN.
float angle_between_degrees(const glm::vec3& a, const glm::vec3& b);

// Angles pooled over pixels (several views add up): a histogram of 0.05-degree bins, so the mean
// is exact (summed apart) and percentiles are good to 0.05 degrees.
struct AngleStats {
  static constexpr int kBinsPerDegree = 20;
  static constexpr int kBins = 180 * kBinsPerDegree;

  std::size_t pixels = 0;            // pixels with an angle (covered by both, in the interior)
  std::size_t one_model_pixels = 0;  // covered by exactly one model (not an angle)
  double sum_degrees = 0.0;
  std::array<std::size_t, kBins> histogram{};

  void add_angle(float degrees);
  void add(const AngleStats& other);
  double mean() const;  // degrees; 0 when there are no pixels
  // The angle below which `fraction` (0..1) of the pixels lie, degrees (the upper edge of its bin);
  // 0 when there are no pixels.
  double percentile(double fraction) const;
};

// Angle statistics of one view. Requires equal sizes. `erode` >= 0: a pixel counts when it and its
// neighbours within `erode` pixels (Chebyshev) are covered by both models, as metrics.h's interior
// (grazing normals at a silhouette turn fast, so a one-pixel shift there is a large angle that says
// nothing of the map).
AngleStats measure_angles(const NormalImage& low, const NormalImage& high, int erode);

// Per-pixel angles in degrees, row 0 at the top; -1 where fewer than two models cover the pixel
// (what the difference pane draws, no erosion).
std::vector<float> angle_image(const NormalImage& low, const NormalImage& high);

// The difference pane's colour scale, as its shader draws it: `degrees` / `scale_degrees` = v,
// clamped to 0..1, as black -> red -> yellow -> white (r = 3v, g = 3v - 1, b = 3v - 2, each clamped
// to 0..1). So r + g + b = 3v exactly, and angle_from_colour inverts it below the scale's maximum.
glm::vec3 angle_colour(float degrees, float scale_degrees);
float angle_from_colour(const glm::vec3& rgb, float scale_degrees);

// Pixels covered by one model only are drawn in this colour (linear RGB), outside the scale.
inline const glm::vec3 kOneModelColour(0.15f, 0.35f, 0.85f);

// The colour scale's maximum in degrees: default, and the steps the [ and ] keys walk through.
constexpr float kDefaultDiffScale = 30.0f;
constexpr float kMaxDiffScale = 180.0f;
// The next step of {1, 2, 3, 5, 10, 15, 20, 30, 45, 60, 90, 120, 180} above (`up`) or below
// `current`, staying at the ends; a value between steps goes to the neighbouring step.
float next_diff_scale(float current, bool up);

}  // namespace nmview
