#include "pipeline/rays.h"

#include "core/tangent_frames.h"
#include "trace/shade_batch.h"

namespace nmbake {

glm::dvec3 shade_sample(const Prepared& s, const HighScene& scene, std::size_t tri, const double b[3], const raycast::Hit& h,
                        const BakeOptions& opt) {
  const PixelFrame frame = interpolate_frame(s.low_tris[tri].n, s.low_tris[tri].t, b, opt.bitangent);
  if (!h.hit()) {
    const double nl = glm::length(frame.n);
    return opt.space == NormalSpace::tangent ? glm::dvec3(0, 0, 1) : (nl > 0 ? frame.n / nl : glm::dvec3(0, 0, 1));
  }
  const std::size_t ht = h.triangle;
  // The hit normal, interpolated as the codec does (codec.h; shade_batch.h's kernel the same).
  const double w[3] = {1.0 - double(h.u) - double(h.v), double(h.u), double(h.v)};
  codec::Vec3<double> corner[3], interpolated;
  for (int c = 0; c < 3; ++c) corner[c] = to_codec(glm::dvec3(scene.normals[3 * ht + c]));
  codec::interpolate(interpolated, w, corner, 0.0);
  glm::dvec3 nh = from_codec(interpolated);
  const double len2 = glm::dot(nh, nh);
  // The encoding normalizes, so in tangent space the hit normal goes in at its own length, unless
  // that is too short to trust (encode_hits_per_pixel's test).
  if (opt.space == NormalSpace::tangent && len2 > kShortHitNormal2) return encode_tangent_normal(frame, nh);
  double len = std::sqrt(len2);
  if (!(len > 1e-12)) {
    const glm::dvec3 q0(scene.positions[scene.index[3 * ht]]), q1(scene.positions[scene.index[3 * ht + 1]]),
        q2(scene.positions[scene.index[3 * ht + 2]]);
    nh = glm::cross(q1 - q0, q2 - q0);
    len = glm::length(nh);
  }
  nh = len > 0.0 ? nh / len : glm::normalize(frame.n);
  return opt.space == NormalSpace::tangent ? encode_tangent_normal(frame, nh) : nh;
}

}  // namespace nmbake
