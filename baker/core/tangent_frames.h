// Per-corner tangent frames with MikkTSpace semantics.
//
// Reference: M. Mikkelsen, "Simulation of Wrinkled Surfaces Revisited", 2008, and the MikkTSpace
// convention used by Blender, glTF 2.0, Substance, Unity and Unreal. Per triangle the UV gradient
// gives a tangent and an orientation (sign of the UV area; mirrored UVs have the other one). Per
// corner, tangents of the triangles that share the corner's position, normal, UV and orientation
// are projected onto the plane of the corner normal, weighted by the corner angle, summed and
// normalized. Triangles with zero UV area or zero 3D area contribute nothing; a corner left
// without a tangent gets a unit vector orthogonal to its normal. No output is ever NaN.
//
// Renderer side (and therefore the baker's encoding, see encode_tangent_normal): N and T are
// interpolated across the triangle without normalizing, B = sign * cross(N, T) per pixel, and the
// world normal of a map value t is normalize(t.x * T + t.y * B + t.z * N).
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "core/mesh.h"

namespace nmbake {

enum class BitangentMode {
  per_pixel,   // B = sign * cross(N, T) from the interpolated N and T (MikkTSpace, default)
  per_vertex,  // B = sign * cross(N, T) per corner, then interpolated
};

struct TangentFrames {
  std::vector<glm::vec3> normal;   // per corner (3 per triangle), unit length, object space
  std::vector<glm::vec4> tangent;  // per corner: xyz unit and orthogonal to normal, w = +1 or -1
  std::size_t degenerate_uv_triangles = 0;  // zero UV area: no tangent contribution
  std::size_t degenerate_3d_triangles = 0;  // zero 3D area: no tangent contribution
  std::size_t corners_without_tangent = 0;  // given an arbitrary tangent orthogonal to N
};

// `mesh` must have UVs. Normals: the file's when present, else angle-weighted smooth vertex
// normals (compute_vertex_normals).
TangentFrames compute_tangent_frames(const Mesh& mesh);

// The frame at barycentrics `bary` of triangle `tri`, as the renderer builds it.
struct PixelFrame {
  glm::dvec3 t, b, n;  // not orthonormal in general
};
PixelFrame interpolate_frame(const TangentFrames& frames, std::size_t tri, const double bary[3],
                             BitangentMode mode = BitangentMode::per_pixel);
// The same from a triangle's three corner normals and tangents, given in float (glm::vec3/vec4) or
// already widened to double (glm::dvec3/dvec4: the same result, without the per-call widening).
// Inline: the bake calls it per sample.
template <typename Vec3, typename Vec4>
inline PixelFrame interpolate_frame(const Vec3 normal[3], const Vec4 tangent[3], const double bary[3],
                                    BitangentMode mode = BitangentMode::per_pixel) {
  PixelFrame f{glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0)};
  double sign = 0.0;
  for (int c = 0; c < 3; ++c) {
    const glm::dvec3 n(normal[c]);
    const glm::dvec4 t(tangent[c]);
    f.n += bary[c] * n;
    f.t += bary[c] * glm::dvec3(t);
    sign += bary[c] * t.w;
    if (mode == BitangentMode::per_vertex) f.b += bary[c] * (t.w * glm::cross(n, glm::dvec3(t)));
  }
  if (mode == BitangentMode::per_pixel) f.b = sign * glm::cross(f.n, f.t);
  return f;
}

// Tangent-space unit vector whose decoding in `frame` is the direction of `world` (any positive
// length): the exact inverse of normalize(t.x*T + t.y*B + t.z*N), renormalized. Falls back to
// (0,0,1) when the frame is singular. Inline: the bake calls it per sample.
inline glm::dvec3 encode_tangent_normal(const PixelFrame& f, const glm::dvec3& world) {
  // Solve [T B N] x = world by Cramer's rule; x is defined up to a positive scale because the
  // renderer normalizes, so the determinant's magnitude does not matter, only its sign and zero:
  // the adjugate times world, normalized, negated when det < 0 (one division, not six).
  const glm::dvec3 bxn = glm::cross(f.b, f.n), nxt = glm::cross(f.n, f.t), txb = glm::cross(f.t, f.b);
  const double det = glm::dot(f.t, bxn);
  // Singular when |det| <= 1e-12 |T||B||N|, compared squared to spare three square roots.
  const double scale2 = glm::dot(f.t, f.t) * glm::dot(f.b, f.b) * glm::dot(f.n, f.n);
  if (!(det * det > 1e-24 * scale2) || !std::isfinite(det)) return {0.0, 0.0, 1.0};
  const glm::dvec3 x(glm::dot(world, bxn), glm::dot(world, nxt), glm::dot(world, txb));
  const double len = std::sqrt(glm::dot(x, x));
  if (!(len > 0.0) || !std::isfinite(len)) return {0.0, 0.0, 1.0};
  const double inv = 1.0 / len;
  return det > 0.0 ? x * inv : x * -inv;
}

// World direction of a tangent-space vector (the renderer's decoding).
glm::dvec3 decode_tangent_normal(const PixelFrame& frame, const glm::dvec3& tangent_space);

}  // namespace nmbake
