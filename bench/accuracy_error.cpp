#include "accuracy_error.h"

#include <algorithm>
#include <cmath>

#include "bench_support.h"
#include "core/parallel.h"
#include "core/rasterize.h"

namespace nmbake::bench {

namespace {

constexpr double kDeg = 180.0 / kPi;

double angle_deg(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * kDeg;
}

glm::dvec3 decode_rgb(const float* c) {
  const glm::dvec3 v(2.0 * c[0] - 1.0, 2.0 * c[1] - 1.0, 2.0 * c[2] - 1.0);
  const double len = glm::length(v);
  return len > 0.0 ? v / len : glm::dvec3(0, 0, 1);
}

// As image_io writes integer formats: round half away from zero, clamp.
float quantize(float c, int bits) {
  const double scale = double((1u << bits) - 1u);
  return float(std::clamp(std::round(double(c) * scale), 0.0, scale) / scale);
}

}  // namespace

std::vector<TexelRef> texel_references(const Mesh& low, const TangentFrames& frames, int W, int H,
                                       const AnalyticNormal* analytic) {
  static const double g[4] = {0.5 - 0.5 * 0.8611363115940526, 0.5 - 0.5 * 0.3399810435848563, 0.5 + 0.5 * 0.3399810435848563,
                              0.5 + 0.5 * 0.8611363115940526};
  static const double gw[4] = {0.1739274225687269, 0.3260725774312731, 0.3260725774312731, 0.1739274225687269};
  const int points = analytic ? 17 : 1;  // point 16 (or 0) is the centre
  std::vector<TexelRef> out(std::size_t(W) * H);
  constexpr int kBand = 16;
  const int bands = (H + kBand - 1) / kBand;
  std::vector<TexelTriangle> tt(low.triangle_count());
  std::vector<std::vector<std::uint32_t>> band_tris(static_cast<std::size_t>(bands));
  for (std::size_t t = 0; t < low.triangle_count(); ++t) {
    tt[t] = setup_texel_triangle(low.corner_uv(t, 0), low.corner_uv(t, 1), low.corner_uv(t, 2), W, H);
    if (!tt[t].valid() || tt[t].xmax < tt[t].xmin || tt[t].ymax < tt[t].ymin) continue;
    for (int b = tt[t].ymin / kBand; b <= tt[t].ymax / kBand; ++b) band_tris[std::size_t(b)].push_back(std::uint32_t(t));
  }
  parallel_chunks(0, std::size_t(bands), 1, [&](std::size_t b0, std::size_t b1) {
    std::vector<std::uint32_t> mask;
    std::vector<glm::dvec3> acc;
    for (std::size_t band = b0; band < b1; ++band) {
      const int y0 = int(band) * kBand, y1 = std::min(H, y0 + kBand);
      mask.assign(std::size_t(y1 - y0) * W, 0u);
      acc.assign(std::size_t(y1 - y0) * W, glm::dvec3(0.0));
      for (std::uint32_t t : band_tris[band]) {
        const TexelTriangle& tri = tt[t];
        for (int y = std::max(y0, tri.ymin); y <= std::min(y1 - 1, tri.ymax); ++y)
          for (int x = tri.xmin; x <= tri.xmax; ++x) {
            const std::size_t li = std::size_t(y - y0) * W + x;
            for (int k = 0; k < points; ++k) {
              if (mask[li] & (1u << k)) continue;
              const bool centre = k == points - 1;
              const double ox = centre ? 0.5 : g[k % 4], oy = centre ? 0.5 : g[k / 4];
              double b[3];
              if (!covers(tri, sample_point(x, y, ox, oy), b)) continue;
              mask[li] |= 1u << k;
              if (centre) {
                TexelRef& r = out[std::size_t(y) * W + x];
                r.tri = std::int32_t(t);
                r.b1 = float(b[1]);
                r.b2 = float(b[2]);
                continue;
              }
              glm::dvec3 p(0.0);
              for (int c = 0; c < 3; ++c) p += b[c] * glm::dvec3(low.corner_position(t, c));
              const glm::dvec3 world = (*analytic)(p);
              acc[li] += gw[k % 4] * gw[k / 4] * encode_tangent_normal(interpolate_frame(frames, t, b), world);
            }
          }
      }
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < W; ++x) {
          const std::size_t li = std::size_t(y - y0) * W + x;
          TexelRef& r = out[std::size_t(y) * W + x];
          if (!analytic) continue;
          if (mask[li] != (1u << points) - 1u || glm::length(acc[li]) == 0.0) {
            r.tri = -1;
            continue;
          }
          r.ref = glm::vec3(glm::normalize(acc[li]));
        }
    }
  });
  return out;
}

ErrorStats measure(const Image& map, const std::vector<std::uint8_t>& coverage, const std::vector<TexelRef>& refs,
                   const Image* ref_map, const TangentFrames& frames, int bits) {
  std::vector<float> err(refs.size(), -1.0f);
  parallel_chunks(0, refs.size(), 4096, [&](std::size_t i0, std::size_t i1) {
    for (std::size_t i = i0; i < i1; ++i) {
      const TexelRef& r = refs[i];
      if (r.tri < 0 || !coverage[i]) continue;
      float c[3] = {map.pixels[3 * i], map.pixels[3 * i + 1], map.pixels[3 * i + 2]};
      if (bits != 32)
        for (float& v : c) v = quantize(v, bits);
      const double b[3] = {1.0 - double(r.b1) - double(r.b2), double(r.b1), double(r.b2)};
      const PixelFrame f = interpolate_frame(frames, std::size_t(r.tri), b);
      const glm::dvec3 ref = ref_map ? decode_rgb(&ref_map->pixels[3 * i]) : glm::dvec3(r.ref);
      err[i] = float(angle_deg(decode_tangent_normal(f, decode_rgb(c)), decode_tangent_normal(f, ref)));
    }
  });
  err.erase(std::remove(err.begin(), err.end(), -1.0f), err.end());
  ErrorStats s;
  s.texels = err.size();
  if (err.empty()) return s;
  double sum = 0, sum2 = 0;
  std::size_t over = 0;
  for (float e : err) sum += e, sum2 += double(e) * e, over += e > 1.0f, s.max = std::max(s.max, double(e));
  s.mean = sum / double(err.size());
  s.rms = std::sqrt(sum2 / double(err.size()));
  s.over1 = double(over) / double(err.size());
  const std::size_t k = std::min(err.size() - 1, std::size_t(0.95 * double(err.size() - 1) + 0.5));
  std::nth_element(err.begin(), err.begin() + std::ptrdiff_t(k), err.end());
  s.p95 = err[k];
  return s;
}

double quantization_floor(const std::vector<TexelRef>& refs, const TangentFrames& frames, int bits) {
  double sum = 0;
  std::size_t n = 0;
  for (const TexelRef& r : refs) {
    if (r.tri < 0) continue;
    float c[3];
    for (int k = 0; k < 3; ++k) c[k] = quantize(float(double(r.ref[k]) * 0.5 + 0.5), bits);
    const double b[3] = {1.0 - double(r.b1) - double(r.b2), double(r.b1), double(r.b2)};
    const PixelFrame f = interpolate_frame(frames, std::size_t(r.tri), b);
    sum += angle_deg(decode_tangent_normal(f, decode_rgb(c)), decode_tangent_normal(f, glm::dvec3(r.ref)));
    ++n;
  }
  return n ? sum / double(n) : 0.0;
}

}  // namespace nmbake::bench
