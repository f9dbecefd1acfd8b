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

#include <cstddef>
#include <vector>

#include <glm/glm.hpp>

#include "mesh.h"

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
// The same from a triangle's three corner normals and tangents.
PixelFrame interpolate_frame(const glm::vec3 normal[3], const glm::vec4 tangent[3], const double bary[3],
                             BitangentMode mode = BitangentMode::per_pixel);

// Tangent-space unit vector whose decoding in `frame` is the world direction `world`: the exact
// inverse of normalize(t.x*T + t.y*B + t.z*N), renormalized. Falls back to (0,0,1) when the frame
// is singular.
glm::dvec3 encode_tangent_normal(const PixelFrame& frame, const glm::dvec3& world);

// World direction of a tangent-space vector (the renderer's decoding).
glm::dvec3 decode_tangent_normal(const PixelFrame& frame, const glm::dvec3& tangent_space);

}  // namespace nmbake
