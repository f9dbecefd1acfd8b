// Appearance difference between two renderings of the same view (CPU only).
//
// In the spirit of Cignoni et al., "Metro: measuring error on simplified surfaces", 1998, but in
// image space: the two panes are rendered from the same camera with the same light and compared
// pixel by pixel. Two things are measured apart because a normal map can fix one and not the other:
// - shading, over the *interior*: pixels fully covered by both models (coverage alpha 255 in both,
//   so no anti-aliased edge) whose neighbours within `erode` pixels are too. This is "the panes
//   are hard to tell apart away from the silhouette", and the main figure of --compare;
// - the silhouette mismatch: the share of the object's pixels (covered by either model) that only
//   one model covers. It comes from geometry the low-poly does not have and no map can add.
// Values are 8-bit RGB as rendered (display-encoded shading, premultiplied over black), so in the
// union figures a pixel covered by one model only is compared against black.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace nmview {

// RGBA8 pixels, row 0 at the top; alpha is the coverage mask (0 = background, 255 = fully covered).
struct Rgba8Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // width * height * 4
};

// Squared-error sums over a set of pixels; add several views together and then read the metrics.
struct ErrorSums {
  std::size_t pixels = 0;          // pixels in the set
  std::size_t within2_pixels = 0;  // every RGB channel within 2/255
  double sum_squared = 0.0;        // sum over the pixels and RGB channels of ((a-b)/255)^2

  void add(const ErrorSums& other);
  void add_pixel(const std::uint8_t* a, const std::uint8_t* b);  // RGB of both
  double rmse() const;                                           // 0..1 over RGB channels; 0 when there are no pixels
  double psnr() const;                                           // 20 log10(1 / rmse) in dB; +infinity when rmse == 0
  double within2() const;                                        // fraction of the pixels; 1 when there are none
};

struct DifferenceStats {
  ErrorSums interior;               // both models fully cover the pixel and its neighbourhood
  ErrorSums object;                 // covered by either model (the union), silhouettes included
  std::size_t mismatch_pixels = 0;  // covered by exactly one model (alpha > 0 in one only)

  void add(const DifferenceStats& other);
  // mismatch_pixels / object pixels: 0 when both silhouettes agree; 0 when there are none.
  double silhouette_mismatch() const;
};

// Default erosion of the interior: one pixel beyond the fully covered ones, so a pixel next to an
// anti-aliased silhouette edge (whose shading comes from a grazing, fast-changing normal) is out.
constexpr int kDefaultErode = 1;

// Requires equal sizes. `erode` >= 0 pixels (Chebyshev distance).
DifferenceStats compare_images(const Rgba8Image& a, const Rgba8Image& b, int erode = kDefaultErode);

}  // namespace nmview
