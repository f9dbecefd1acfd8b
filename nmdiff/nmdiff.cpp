#include "nmdiff.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>

#include "core/codec.h"
#include "core/errors.h"
#include "core/rasterize.h"
#include "texel_selection.h"

namespace nmbake::diff {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string size_text(const Image& m) { return std::to_string(m.width) + "x" + std::to_string(m.height); }

// atan2 of |a x b| and a . b keeps small angles accurate, where acos(dot) loses them.
double angle_deg(const double a[3], const double b[3]) {
  const double cx = a[1] * b[2] - a[2] * b[1], cy = a[2] * b[0] - a[0] * b[2], cz = a[0] * b[1] - a[1] * b[0];
  const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  return std::atan2(std::sqrt(cx * cx + cy * cy + cz * cz), dot) * (180.0 / kPi);
}

// Mean difference over the compared texels when B's channels are reinterpreted by `remap`.
template <typename Remap>
double mean_with_b_as(const Image& a, const Image& b, const DiffOptions& options, const std::vector<std::uint8_t>& compared,
                      Remap remap) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < compared.size(); ++i) {
    if (!compared[i]) continue;
    float rgb[3];
    remap(&b.pixels[i * b.channels], rgb);
    double na[3], nb[3];
    if (!decode_normal(&a.pixels[i * a.channels], options.green_a, na) || !decode_normal(rgb, options.green_b, nb)) continue;
    sum += angle_deg(na, nb);
    ++n;
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

std::string deg_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

void check_normal_map(const Image& map, const std::string& name) {
  if (map.width <= 0 || map.height <= 0 || map.pixels.empty()) throw InputError(name + ": empty image");
  if (map.channels < 3) throw InputError(name + ": has " + std::to_string(map.channels) + " channel(s); a normal map needs RGB");
  assert(map.pixels.size() == static_cast<std::size_t>(map.width) * map.height * map.channels);
}

bool decode_normal(const float* rgb, GreenAxis green, double n[3]) {
  if (!codec::decode_texel(rgb, n)) return false;  // the baker's codec (core/codec.h)
  if (green == GreenAxis::down) n[1] = -n[1];
  return true;
}

Image resample_image(const Image& src, int width, int height, Resample mode) {
  if (src.width == width && src.height == height) return src;
  if (mode == Resample::none)
    throw InputError("sizes differ: " + size_text(src) + " vs " + std::to_string(width) + "x" + std::to_string(height));
  const int c = src.channels;
  Image out(width, height, c);
  const double sx = double(src.width) / width, sy = double(src.height) / height;
  const bool box = mode == Resample::box && sx >= 1.0 && sy >= 1.0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      float* o = out.at(x, y);
      if (mode == Resample::nearest) {
        const int ix = std::min(src.width - 1, int((x + 0.5) * sx));
        const int iy = std::min(src.height - 1, int((y + 0.5) * sy));
        std::copy(src.at(ix, iy), src.at(ix, iy) + c, o);
      } else if (box) {
        // Source texels whose centres (i + 0.5) lie in [x * sx, (x + 1) * sx).
        const int x0 = int(std::ceil(x * sx - 0.5)), x1 = std::min(src.width, int(std::ceil((x + 1) * sx - 0.5)));
        const int y0 = int(std::ceil(y * sy - 0.5)), y1 = std::min(src.height, int(std::ceil((y + 1) * sy - 0.5)));
        std::vector<double> sum(c, 0.0);
        for (int j = y0; j < y1; ++j)
          for (int i = x0; i < x1; ++i)
            for (int k = 0; k < c; ++k) sum[k] += src.at(i, j)[k];
        const double n = double(std::max(1, (x1 - x0) * (y1 - y0)));
        for (int k = 0; k < c; ++k) o[k] = float(sum[k] / n);
      } else {
        const double fx = std::clamp((x + 0.5) * sx - 0.5, 0.0, double(src.width - 1));
        const double fy = std::clamp((y + 0.5) * sy - 0.5, 0.0, double(src.height - 1));
        const int jx = int(fx), jy = int(fy);
        const int kx = std::min(jx + 1, src.width - 1), ky = std::min(jy + 1, src.height - 1);
        const double tx = fx - jx, ty = fy - jy;
        for (int k = 0; k < c; ++k) {
          const double top = src.at(jx, jy)[k] * (1 - tx) + src.at(kx, jy)[k] * tx;
          const double bottom = src.at(jx, ky)[k] * (1 - tx) + src.at(kx, ky)[k] * tx;
          o[k] = float(top * (1 - ty) + bottom * ty);
        }
      }
    }
  return out;
}

std::vector<std::uint8_t> uv_layout_mask(const Mesh& low, int width, int height) {
  if (!low.has_uvs()) throw InputError(low.source + ": has no UVs, so it cannot mask the map");
  const std::vector<std::int32_t> tri = rasterize_texel_triangles(low, width, height);
  std::vector<std::uint8_t> mask(tri.size());
  for (std::size_t i = 0; i < tri.size(); ++i) mask[i] = tri[i] >= 0 ? 1 : 0;
  return mask;
}

const Image& comparable_b(const Image& a, const Image& b, Resample asked, Resample mode, const std::vector<std::uint8_t>& mask,
                          Image& storage) {
  const bool resized = a.width != b.width || a.height != b.height;
  if (resized && asked == Resample::none)
    throw InputError("sizes differ: " + size_text(a) + " vs " + size_text(b) + " (use --resample nearest|bilinear|box)");
  const std::size_t texels = static_cast<std::size_t>(a.width) * a.height;
  if (!mask.empty() && mask.size() != texels)
    throw InputError("mask has " + std::to_string(mask.size()) + " texels, the map " + size_text(a) + " has " +
                     std::to_string(texels));
  if (!resized) return b;
  storage = resample_image(b, a.width, a.height, mode);
  return storage;
}

DiffStats compare_normal_maps(const Image& a, const Image& b_in, const DiffOptions& options, AngleField* field) {
  check_normal_map(a, "map A");
  check_normal_map(b_in, "map B");
  Image resampled;
  const Image& b = comparable_b(a, b_in, options.resample, options.resample, options.mask, resampled);
  const std::size_t texels = static_cast<std::size_t>(a.width) * a.height;

  DiffStats s;
  s.width = a.width;
  s.height = a.height;
  if (field) {
    field->width = a.width;
    field->height = a.height;
    field->degrees.assign(texels, -1.0f);
  }

  // Select, decode and measure each texel.
  // Floats for the percentiles and a byte per texel keep an 8k x 8k comparison under 0.4 GB.
  DiffTally tally;  // in degrees
  std::vector<std::uint8_t> compared(texels, 0);
  tally.values.reserve(texels);
  std::size_t over1 = 0, over5 = 0;
  for (std::size_t i = 0; i < texels; ++i) {
    const float* pa = &a.pixels[i * a.channels];
    const float* pb = &b.pixels[i * b.channels];
    const TexelSelection sel = select_texel(a, b, i, options.mask, options.use_alpha, options.include_padding);
    if (count_skipped(sel, s)) continue;
    double na[3], nb[3];
    const bool nonfinite = !std::isfinite(pa[0]) || !std::isfinite(pa[1]) || !std::isfinite(pa[2]) || !std::isfinite(pb[0]) ||
                           !std::isfinite(pb[1]) || !std::isfinite(pb[2]);
    if (!nonfinite && !decode_normal(pa, options.green_a, na)) {
      ++s.invalid_a;
      continue;
    }
    if (!nonfinite && !decode_normal(pb, options.green_b, nb)) {
      ++s.invalid_b;
      continue;
    }
    if (sel == TexelSelection::padding) ++s.padding_compared;
    s.nonfinite_texels += nonfinite;
    const double d = nonfinite ? 180.0 : angle_deg(na, nb);  // a NaN texel is as different as can be
    if (field) field->degrees[i] = static_cast<float>(d);
    tally.add(i, a.width, d);
    over1 += d > 1.0;
    over5 += d > 5.0;
    compared[i] = 1;
  }

  // Statistics.
  s.texels_compared = tally.values.size();
  s.max_deg = tally.max;
  s.worst_x = tally.worst_x, s.worst_y = tally.worst_y;
  if (!tally.values.empty()) {
    const double n = static_cast<double>(tally.values.size());
    s.over_1deg = static_cast<double>(over1) / n;
    s.over_5deg = static_cast<double>(over5) / n;
    const DiffTally::Summary m = tally.summary();
    s.mean_deg = m.mean, s.rms_deg = m.rms, s.p95_deg = m.p95, s.p99_deg = m.p99;
  }
  const Tolerances& t = options.tolerances;
  // A map holding NaN is broken whatever the tolerances.
  s.within = s.texels_compared > 0 && s.nonfinite_texels == 0 && s.mean_deg <= t.max_mean_deg && s.p99_deg <= t.max_p99_deg &&
             s.max_deg <= t.max_deg;
  if (s.texels_compared == 0) s.warnings.push_back("no texels compared: nothing is within tolerance");
  if (s.nonfinite_texels > 0)
    s.warnings.push_back(
        std::to_string(s.nonfinite_texels) +
        " texel(s) hold a value that is not a number (NaN or infinity) in A or B: each counted as a difference of "
        "180 deg");
  if (s.invalid_a + s.invalid_b > 0)
    s.warnings.push_back(std::to_string(s.invalid_a + s.invalid_b) +
                         " texel(s) decode to a zero vector and were not compared (A: " + std::to_string(s.invalid_a) +
                         ", B: " + std::to_string(s.invalid_b) + ")");

  // Common mistakes: the maps agree far better once B's green is flipped or R and G are swapped.
  if (options.detect_convention_mistakes && !s.within && s.texels_compared > 0) {
    const double flipped =
        mean_with_b_as(a, b, options, compared, [](const float* p, float* q) { q[0] = p[0], q[1] = 1.0f - p[1], q[2] = p[2]; });
    const double swapped =
        mean_with_b_as(a, b, options, compared, [](const float* p, float* q) { q[0] = p[1], q[1] = p[0], q[2] = p[2]; });
    // A quarter of the difference left is "far better"; the flipped/swapped map need not match
    // exactly (the two maps may also differ by rounding or a different bake).
    const double far_better = 0.25 * s.mean_deg;
    if (flipped < far_better && flipped <= swapped)
      s.warnings.push_back("the maps look like they differ by a green flip (mean " + deg_text(s.mean_deg) + " deg as given, " +
                           deg_text(flipped) +
                           " deg with B's green flipped): check --green-a/--green-b (up = OpenGL Y+, "
                           "down = DirectX Y-)");
    else if (swapped < far_better)
      s.warnings.push_back("the maps look like they differ by a red/green swap (mean " + deg_text(s.mean_deg) +
                           " deg as given, " + deg_text(swapped) + " deg with B's R and G swapped)");
  }
  return s;
}

std::string summary_line(const DiffStats& s) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "mean=%.4f p99=%.4f max=%.4f texels=%zu within=%d", s.mean_deg, s.p99_deg, s.max_deg,
                s.texels_compared, s.within ? 1 : 0);
  return buf;
}

double auto_heatmap_scale(const DiffStats& stats, const Tolerances& tolerances) {
  return std::max({tolerances.max_deg, stats.p99_deg, 0.1});
}

}  // namespace nmbake::diff
