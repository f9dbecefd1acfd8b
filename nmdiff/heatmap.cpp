#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>

#include "nmdiff.h"

namespace nmbake::diff {
namespace {

// A perceptually ordered ramp (dark blue-violet, blue, teal, green, yellow): brightness rises
// monotonically, so larger differences always look brighter, also in greyscale.
constexpr std::array<std::array<float, 3>, 5> kRamp = {{
    {0.27f, 0.00f, 0.33f},
    {0.23f, 0.32f, 0.55f},
    {0.13f, 0.57f, 0.55f},
    {0.37f, 0.79f, 0.38f},
    {0.99f, 0.91f, 0.14f},
}};
constexpr float kNotCompared = 0.18f;  // dark grey: the only colour without a hue

void ramp(double t, float* rgb) {
  t = std::clamp(t, 0.0, 1.0) * (kRamp.size() - 1);
  const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(t), kRamp.size() - 2);
  const float f = static_cast<float>(t - static_cast<double>(i));
  for (int k = 0; k < 3; ++k) rgb[k] = kRamp[i][k] * (1 - f) + kRamp[i + 1][k] * f;
}

// 3x5 glyphs, one row per entry, bit 2 = left column.
struct Glyph {
  char c;
  std::array<unsigned char, 5> rows;
};
constexpr Glyph kFont[] = {
    {'0', {7, 5, 5, 5, 7}}, {'1', {2, 6, 2, 2, 7}}, {'2', {7, 1, 7, 4, 7}}, {'3', {7, 1, 7, 1, 7}},
    {'4', {5, 5, 7, 1, 1}}, {'5', {7, 4, 7, 1, 7}}, {'6', {7, 4, 7, 5, 7}}, {'7', {7, 1, 1, 1, 1}},
    {'8', {7, 5, 7, 5, 7}}, {'9', {7, 5, 7, 1, 7}}, {'.', {0, 0, 0, 0, 2}}, {'o', {7, 5, 7, 0, 0}},
};

// Draws `text` ('o' is the degree sign) with its top-left corner at (x, y), `scale` pixels per dot.
void draw_text(Image& img, int x, int y, int scale, const std::string& text) {
  for (char ch : text) {
    for (const Glyph& g : kFont) {
      if (g.c != ch) continue;
      for (int row = 0; row < 5; ++row)
        for (int col = 0; col < 3; ++col) {
          if (!(g.rows[row] & (4 >> col))) continue;
          for (int dy = 0; dy < scale; ++dy)
            for (int dx = 0; dx < scale; ++dx) {
              const int px = x + col * scale + dx, py = y + row * scale + dy;
              if (px < 0 || py < 0 || px >= img.width || py >= img.height) continue;
              float* p = img.at(px, py);
              p[0] = p[1] = p[2] = 0.9f;
            }
        }
    }
    x += 4 * scale;
  }
}

int text_width(const std::string& text, int scale) { return static_cast<int>(text.size()) * 4 * scale - scale; }

}  // namespace

Image render_heatmap(const AngleField& field, double scale_max_deg, const std::string& unit) {
  const int w = field.width, h = field.height;
  if (!(scale_max_deg > 0.0)) scale_max_deg = 1.0;

  // Layout: the map, a black gap, the legend bar, and a row of values when there is room.
  const int gap = std::max(1, h / 64);
  const int bar = std::max(4, h / 16);
  const int scale = std::max(1, std::min(w, h) / 256);
  char max_text[32];
  std::snprintf(max_text, sizeof max_text, "%.3g%s", scale_max_deg, unit.c_str());
  const std::string zero_text = "0" + unit;
  const bool with_text = w >= text_width(zero_text, scale) + text_width(max_text, scale) + 4 * scale;
  const int text_rows = with_text ? 7 * scale : 0;
  Image out(w, h + gap + bar + text_rows, 3, 0.0f);

  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float d = field.degrees[static_cast<std::size_t>(y) * w + x];
      float* p = out.at(x, y);
      if (d < 0.0f) p[0] = p[1] = p[2] = kNotCompared;
      else ramp(d / scale_max_deg, p);
    }
  for (int x = 0; x < w; ++x) {
    float rgb[3];
    ramp(w > 1 ? double(x) / (w - 1) : 1.0, rgb);
    for (int y = h + gap; y < h + gap + bar; ++y) std::copy(rgb, rgb + 3, out.at(x, y));
  }
  if (with_text) {
    const int ty = h + gap + bar + scale;
    draw_text(out, 0, ty, scale, zero_text);
    draw_text(out, w - text_width(max_text, scale), ty, scale, max_text);
  }
  return out;
}

}  // namespace nmbake::diff
