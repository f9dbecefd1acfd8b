// A float image in memory: row 0 is the top of the picture, channels interleaved.
// Normal maps hold encoded values c = n * 0.5 + 0.5 in [0, 1].
#pragma once

#include <cstddef>
#include <vector>

namespace nmbake {

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<float> pixels;  // width * height * channels, row-major from the top row

  Image() = default;
  Image(int w, int h, int c, float fill = 0.0f)
      : width(w), height(h), channels(c), pixels(static_cast<std::size_t>(w) * h * c, fill) {}

  float* at(int x, int y) { return &pixels[(static_cast<std::size_t>(y) * width + x) * channels]; }
  const float* at(int x, int y) const {
    return &pixels[(static_cast<std::size_t>(y) * width + x) * channels];
  }
};

}  // namespace nmbake
