// Appearance difference between two renderings of the same view (CPU only).
//
// In the spirit of Cignoni et al., "Metro: measuring error on simplified surfaces", 1998, but in
// image space: the two panes are rendered from the same camera with the same light and compared
// over the object's pixels, i.e. the pixels covered by either model (alpha > 0 in either
// coverage mask). Values are 8-bit RGB as rendered (linear shading, premultiplied over black), so a
// pixel covered by one model only is compared against black.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace nmview {

// RGBA8 pixels, row 0 at the top; alpha is the coverage mask (0 = background).
struct Rgba8Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // width * height * 4
};

// Sums over object pixels; add several views together and then read the metrics.
struct DifferenceStats {
  std::size_t object_pixels = 0;   // covered by either image
  std::size_t within2_pixels = 0;  // every channel within 2/255
  double sum_squared = 0.0;        // sum over object pixels and RGB channels of ((a-b)/255)^2
  std::size_t shared_pixels = 0;   // covered by both images (the silhouette mismatch left out)
  double shared_sum_squared = 0.0; // sum_squared over the shared pixels only

  void add(const DifferenceStats& other);
  double rmse() const;             // 0..1 over RGB channels of object pixels; 0 when no pixels
  double psnr() const;             // 20 log10(1 / rmse) in dB; +infinity when rmse == 0
  double within2() const;          // fraction of object pixels; 1 when there are none
  double shared_rmse() const;      // rmse over the shared pixels only
};

// Requires equal sizes.
DifferenceStats compare_images(const Rgba8Image& a, const Rgba8Image& b);

}  // namespace nmview
