#include "pipeline/error_estimate.h"

#include "core/stopwatch.h"
#include "core/codec.h"
#include "core/parallel.h"
#include "pipeline/bake_stages.h"
#include "pipeline/trace.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>

namespace nmbake {

namespace {

constexpr double kDegPerRad = 57.29577951308232;

glm::dvec3 decode(const float* c) {
  double n[3];
  return codec::decode_texel(c, n) ? glm::dvec3(n[0], n[1], n[2]) : glm::dvec3(0, 0, 1);
}

// atan2 form: accurate for tiny angles, where acos(dot) is not.
double angle_deg(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * kDegPerRad;
}

// As image_io writes integer formats: round half away from zero, clamp.
float quantize(float c, int bits) {
  const double scale = double((1u << bits) - 1u);
  return float(std::clamp(std::round(double(c) * scale), 0.0, scale) / scale);
}

}  // namespace

ErrorEstimate estimate_bake_error(const Mesh& low, const BakeOptions& options, const BakeResult& result,
                                  const ErrorEstimateOptions& eo) {
  if (!result.trace_inputs) throw std::invalid_argument("estimate_bake_error: the bake kept no trace (BakeOptions::keep_trace)");
  return estimate_bake_error(low, *result.trace_inputs, options, result, eo);
}

ErrorEstimate estimate_bake_error(const Mesh& low, const TraceInputs& traced, const BakeOptions& options,
                                  const BakeResult& result, const ErrorEstimateOptions& eo) {
  const auto t0 = std::chrono::steady_clock::now();
  ErrorEstimate e;
  // 4x the most samples a texel of the bake has (with --samples auto, its deepest level's).
  const bool deep = options.adaptive && options.deep_factor > 0.0 && 4 * options.samples <= kMaxSamples;
  e.samples = std::min(kMaxSamples, std::max(eo.samples, 4 * (deep ? 4 * options.samples : options.samples)));

  // Texels: a fixed-seed uniform choice among the covered ones (partial Fisher-Yates), then sorted
  // so neighbouring texels share tiles.
  std::vector<std::uint32_t> texels;
  for (std::size_t i = 0; i < result.coverage.size(); ++i)
    if (result.coverage[i]) texels.push_back(std::uint32_t(i));
  if (texels.size() > eo.texels) {
    std::mt19937_64 rng(eo.seed);
    for (std::size_t i = 0; i < eo.texels; ++i) {
      std::uniform_int_distribution<std::size_t> pick(i, texels.size() - 1);
      std::swap(texels[i], texels[pick(rng)]);
    }
    texels.resize(eo.texels);
  }
  std::sort(texels.begin(), texels.end());

  BakeOptions fixed = options;  // the re-bake's samples, each texel all of them
  fixed.samples = e.samples;
  fixed.adaptive = false;
  fixed.progress = nullptr;
  // Tiles whose samples take no more room in the tracer than a 64-sample bake's (kTileSide).
  int side = kTileSide;
  while (side > 4 && side * side * e.samples > kTileSide * kTileSide * 64) side /= 2;
  const TileBins bins = bin_triangles(low, fixed.width, fixed.height, side, eo.tile);
  const std::vector<glm::dvec3> reference =
      trace_texels(traced.s, traced.scene, bins, traced.rays, fixed, worker_threads(fixed.threads), result.stats, texels);
  std::vector<double> err;
  err.reserve(texels.size());
  double sum = 0.0, qsum = 0.0;
  for (std::size_t i = 0; i < texels.size(); ++i) {
    if (reference[i] == glm::dvec3(0.0)) continue;  // no sample in the layout (cannot happen for a covered texel)
    const float* c = &result.map.pixels[3 * std::size_t(texels[i])];
    const glm::dvec3 baked = decode(c);
    const double a = angle_deg(baked, reference[i]);
    err.push_back(a);
    sum += a;
    if (eo.bits == 8 || eo.bits == 16) {
      const float q[3] = {quantize(c[0], eo.bits), quantize(c[1], eo.bits), quantize(c[2], eo.bits)};
      const double qa = angle_deg(decode(q), baked);
      qsum += qa;
      e.quantization_max_deg = std::max(e.quantization_max_deg, qa);
    }
  }
  e.texels = err.size();
  if (!err.empty()) {
    e.mean_deg = sum / double(err.size());
    e.quantization_mean_deg = qsum / double(err.size());
    e.max_deg = *std::max_element(err.begin(), err.end());
    const std::size_t k = std::min(err.size() - 1, std::size_t(0.95 * double(err.size() - 1) + 0.5));
    std::nth_element(err.begin(), err.begin() + std::ptrdiff_t(k), err.end());
    e.p95_deg = err[k];
  }
  e.seconds = seconds_since(t0);
  return e;
}

}  // namespace nmbake
