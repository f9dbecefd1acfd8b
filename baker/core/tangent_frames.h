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

#include "core/codec.h"
#include "core/mesh.h"

namespace nmbake {

enum class BitangentMode {
  per_pixel,   // B = sign * cross(N, T) from the interpolated N and T (MikkTSpace, default)
  per_vertex,  // B = sign * cross(N, T) per corner, then interpolated
};

struct TangentFrames {
  std::vector<glm::vec3> normal;            // per corner (3 per triangle), unit length, object space
  std::vector<glm::vec4> tangent;           // per corner: xyz unit and orthogonal to normal, w = +1 or -1
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
inline codec::Vec3<double> to_codec(const glm::dvec3& v) { return {v.x, v.y, v.z}; }
inline glm::dvec3 from_codec(const codec::Vec3<double>& v) { return {v.x, v.y, v.z}; }

template <typename Vec3, typename Vec4>
inline PixelFrame interpolate_frame(const Vec3 normal[3], const Vec4 tangent[3], const double bary[3],
                                    BitangentMode mode = BitangentMode::per_pixel) {
  if (mode == BitangentMode::per_pixel) {  // the codec's frame (codec.h)
    codec::Vec3<double> n[3], t[3];
    double w[3];
    for (int c = 0; c < 3; ++c) {
      n[c] = to_codec(glm::dvec3(normal[c]));
      t[c] = to_codec(glm::dvec3(glm::dvec4(tangent[c])));
      w[c] = double(tangent[c].w);
    }
    codec::Frame<double> f;
    codec::per_pixel_frame(f, bary, n, t, w, 0.0);
    return {from_codec(f.t), from_codec(f.b), from_codec(f.n)};
  }
  PixelFrame f{glm::dvec3(0.0), glm::dvec3(0.0), glm::dvec3(0.0)};
  for (int c = 0; c < 3; ++c) {
    const glm::dvec3 n(normal[c]);
    const glm::dvec4 t(tangent[c]);
    f.n += bary[c] * n;
    f.t += bary[c] * glm::dvec3(t);
    f.b += bary[c] * (t.w * glm::cross(n, glm::dvec3(t)));
  }
  return f;
}

// Tangent-space unit vector whose decoding in `frame` is the direction of `world` (any positive
// length): the exact inverse of normalize(t.x*T + t.y*B + t.z*N), renormalized (codec.h). Falls
// back to (0,0,1) when the frame is singular or the result not finite. Inline: the bake calls it
// per sample.
inline glm::dvec3 encode_tangent_normal(const PixelFrame& f, const glm::dvec3& world) {
  codec::Encoding<double> e;
  codec::encode_in_frame(e, codec::Frame<double>{to_codec(f.t), to_codec(f.b), to_codec(f.n)}, to_codec(world));
  bool ok;
  codec::trusted(ok, e);
  if (!ok) return {0.0, 0.0, 1.0};
  codec::Vec3<double> r;
  codec::scaled(r, e.x, e.det > 0.0 ? e.inv : -e.inv);
  return from_codec(r);
}

// World direction of a tangent-space vector (the renderer's decoding).
glm::dvec3 decode_tangent_normal(const PixelFrame& frame, const glm::dvec3& tangent_space);

}  // namespace nmbake
