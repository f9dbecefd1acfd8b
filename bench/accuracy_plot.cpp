#include "accuracy_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include "core/errors.h"

namespace nmbake::bench {

namespace {

using OIIO::ImageBuf;
namespace IBA = OIIO::ImageBufAlgo;

struct Colour {
  float c[3];
};
const Colour kPalette[] = {{{0.12f, 0.47f, 0.71f}}, {{0.84f, 0.15f, 0.16f}}, {{0.17f, 0.63f, 0.17f}}, {{0.58f, 0.40f, 0.74f}},
                           {{1.00f, 0.50f, 0.05f}}, {{0.55f, 0.34f, 0.29f}}, {{0.89f, 0.47f, 0.76f}}, {{0.50f, 0.50f, 0.50f}}};
const float kBlack[3] = {0, 0, 0};
const float kGrid[3] = {0.88f, 0.88f, 0.88f};

class Canvas {
 public:
  Canvas(int w, int h, const std::string& font) : buf_(OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::FLOAT)), font_(font) {
    const float white[3] = {1, 1, 1};
    IBA::fill(buf_, white);
  }
  void line(double x0, double y0, double x1, double y1, const float* c, int width = 1, bool dashed = false) {
    const double len = std::hypot(x1 - x0, y1 - y0);
    const int pieces = dashed ? std::max(1, int(len / 8.0)) : 1;
    for (int p = 0; p < pieces; p += dashed ? 2 : 1) {
      const double a = double(p) / pieces, b = double(std::min(p + 1, pieces)) / pieces;
      for (int o = -(width / 2); o <= width / 2; ++o) {
        const bool steep = std::abs(y1 - y0) > std::abs(x1 - x0);
        const double dx = steep ? o : 0, dy = steep ? 0 : o;
        IBA::render_line(buf_, int(std::lround(x0 + a * (x1 - x0) + dx)), int(std::lround(y0 + a * (y1 - y0) + dy)),
                         int(std::lround(x0 + b * (x1 - x0) + dx)), int(std::lround(y0 + b * (y1 - y0) + dy)),
                         OIIO::cspan<float>(c, 3));
      }
    }
  }
  void box(int x0, int y0, int x1, int y1, const float* c, bool fill) {
    IBA::render_box(buf_, x0, y0, x1, y1, OIIO::cspan<float>(c, 3), fill);
  }
  void text(int x, int y, const std::string& s, int size, const float* c, bool centred = false) {
    if (font_.empty() || s.empty()) return;
    if (centred) {
      const OIIO::ROI r = IBA::text_size(s, size, font_);
      if (r.defined()) x -= r.width() / 2;
    }
    if (!IBA::render_text(buf_, x, y, s, size, font_, OIIO::cspan<float>(c, 3))) font_.clear();  // no usable font: no text
  }
  void write(const std::string& path) {
    ImageBuf out = buf_;
    if (!out.write(path, OIIO::TypeDesc::UINT8)) throw OutputError(path + ": cannot write the plot: " + out.geterror());
  }

 private:
  ImageBuf buf_;
  std::string font_;
};

std::string tick_text(double v) {
  char b[32];
  if (v >= 1.0 && v < 1e5) std::snprintf(b, sizeof b, "%g", v);
  else std::snprintf(b, sizeof b, "%g", v);
  return b;
}

}  // namespace

void write_log_log_plot(const std::string& path, const std::string& title, const std::string& x_label, const std::string& y_label,
                        const std::vector<PlotSeries>& series, const std::vector<PlotHLine>& hlines, const std::string& footer,
                        const std::string& font, int width, int height) {
  Canvas cv(width, height, font);
  // Data range in decades, widened to whole decades.
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  for (const PlotSeries& s : series)
    for (const auto& l : s.lines)
      for (const PlotPoint& p : l) {
        if (!(p.x > 0) || !(p.y > 0)) continue;
        xmin = std::min(xmin, p.x), xmax = std::max(xmax, p.x), ymin = std::min(ymin, p.y), ymax = std::max(ymax, p.y);
      }
  for (const PlotHLine& h : hlines)
    if (h.y > 0) ymin = std::min(ymin, h.y), ymax = std::max(ymax, h.y);
  if (xmin > xmax) xmin = 0.1, xmax = 10, ymin = 0.01, ymax = 1;
  const double lx0 = std::floor(std::log10(xmin)), lx1 = std::max(lx0 + 1, std::ceil(std::log10(xmax)));
  const double ly0 = std::floor(std::log10(ymin)), ly1 = std::max(ly0 + 1, std::ceil(std::log10(ymax)));
  const int left = 110, right = width - 300, top = 70, bottom = height - 110;
  auto X = [&](double x) { return left + (std::log10(x) - lx0) / (lx1 - lx0) * (right - left); };
  auto Y = [&](double y) { return bottom - (std::log10(y) - ly0) / (ly1 - ly0) * (bottom - top); };

  // Grid, ticks at 1, 2, 5 per decade, axes.
  for (double d = lx0; d <= lx1; ++d)
    for (double m : {1.0, 2.0, 5.0}) {
      const double v = m * std::pow(10.0, d);
      if (std::log10(v) > lx1 + 1e-9) continue;
      cv.line(X(v), top, X(v), bottom, kGrid);
      if (m == 1.0 || (lx1 - lx0) <= 3) cv.text(int(X(v)), bottom + 24, tick_text(v), 16, kBlack, true);
    }
  for (double d = ly0; d <= ly1; ++d)
    for (double m : {1.0, 2.0, 5.0}) {
      const double v = m * std::pow(10.0, d);
      if (std::log10(v) > ly1 + 1e-9) continue;
      cv.line(left, Y(v), right, Y(v), kGrid);
      if (m == 1.0 || (ly1 - ly0) <= 3) cv.text(left - 70, int(Y(v)) + 6, tick_text(v), 16, kBlack);
    }
  cv.box(left, top, right, bottom, kBlack, false);
  cv.text((left + right) / 2, bottom + 56, x_label, 20, kBlack, true);
  cv.text(left - 95, top - 20, y_label, 20, kBlack);
  cv.text((left + right) / 2, 34, title, 24, kBlack, true);
  cv.text(left, height - 22, footer, 15, kBlack);

  // Horizontal reference lines.
  for (const PlotHLine& h : hlines) {
    cv.line(left, Y(h.y), right, Y(h.y), kBlack, 1, true);
    cv.text(left + 8, int(Y(h.y)) - 6, h.label, 15, kBlack);
  }
  // Series: polylines, point markers, labels; legend on the right.
  for (std::size_t si = 0; si < series.size(); ++si) {
    const float* c = kPalette[si % (sizeof kPalette / sizeof kPalette[0])].c;
    for (const auto& l : series[si].lines) {
      for (std::size_t i = 0; i + 1 < l.size(); ++i)
        cv.line(X(l[i].x), Y(l[i].y), X(l[i + 1].x), Y(l[i + 1].y), c, 3, series[si].dashed);
      for (const PlotPoint& p : l) {
        const int px = int(std::lround(X(p.x))), py = int(std::lround(Y(p.y)));
        cv.box(px - 4, py - 4, px + 4, py + 4, c, true);
        cv.text(px + 7, py - 5, p.label, 13, c);
      }
    }
    const int ly = top + 20 + int(si) * 30;
    cv.line(right + 20, ly, right + 60, ly, c, 3, series[si].dashed);
    cv.text(right + 70, ly + 6, series[si].name, 17, c);
  }
  cv.write(path);
}

}  // namespace nmbake::bench
