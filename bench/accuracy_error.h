// The accuracy bench's measurement: per texel a reference tangent-space normal (the exact normal
// of an analytic surface averaged over the texel, or a reference bake's), and the angular error of
// a baked map against it, both decoded with the low-poly's tangent frame at the texel centre.
#pragma once

#include <cstdint>
#include <vector>

#include "accuracy_scenes.h"
#include "core/image.h"
#include "core/mesh.h"
#include "core/tangent_frames.h"

namespace nmbake::bench {

// Per texel: the low-poly triangle and barycentrics at its centre (tri < 0: excluded), and the
// reference tangent-space unit vector.
struct TexelRef {
  glm::vec3 ref{0.0f};
  std::int32_t tri = -1;
  float b1 = 0, b2 = 0;
};

// Texel centres (and, with `analytic`, the 4x4 Gauss-Legendre points) against the low-poly's UV
// layout, the lowest triangle index winning as in the bake. With `analytic`, a texel is kept only
// when all 16 points are covered, and ref is the weighted mean of the analytic normal's tangent-
// space vectors, renormalized. W x H texels, row-major.
std::vector<TexelRef> texel_references(const Mesh& low, const TangentFrames& frames, int W, int H,
                                       const AnalyticNormal* analytic);

// Angular errors in degrees over the measured texels; over1: their share above 1 degree.
struct ErrorStats {
  double mean = 0, rms = 0, p95 = 0, max = 0, over1 = 0;
  std::size_t texels = 0;
};

// The bake's map (quantised to `bits` unless 32) against the references, both decoded with the
// low-poly frame at the texel centre. `ref_map` (real scenes) overrides TexelRef::ref.
ErrorStats measure(const Image& map, const std::vector<std::uint8_t>& coverage, const std::vector<TexelRef>& refs,
                   const Image* ref_map, const TangentFrames& frames, int bits);

// Mean angle in degrees between the reference and its own value rounded to `bits`: the floor that
// bit depth puts under any bake of the scene.
double quantization_floor(const std::vector<TexelRef>& refs, const TangentFrames& frames, int bits);

}  // namespace nmbake::bench
