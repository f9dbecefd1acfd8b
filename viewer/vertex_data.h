// GPU-ready vertex arrays built once from the loaded meshes (CPU only, no GL).
//
// Positions are re-centred on the scene centre (the centre of the union bounding box of both
// meshes) so a mesh far from the origin keeps its float precision; shading only uses directions,
// which re-centring does not change. Corners with identical attributes are merged, so the GPU
// draws indexed triangles and a multi-million-triangle mesh is uploaded once and drawn with no
// per-frame CPU work.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/mesh.h"
#include "core/tangent_frames.h"

namespace nmview {

// Axis-aligned box in object space; empty when min > max.
struct Bounds {
  glm::vec3 min{1e30f};
  glm::vec3 max{-1e30f};
  void extend(glm::vec3 p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void extend(const Bounds& b) {
    extend(b.min);
    extend(b.max);
  }
  glm::vec3 centre() const { return 0.5f * (min + max); }
  float radius() const { return 0.5f * glm::length(max - min); }  // half the diagonal
};

// Bounds of the positions the triangles use.
Bounds mesh_bounds(const nmbake::Mesh& mesh);

// Low-poly corner: exactly the baker's per-corner frame (normal, tangent xyz + sign in w, and the
// per-vertex bitangent).
struct LowVertex {
  glm::vec3 position;   // object space minus the scene centre
  glm::vec3 normal;     // frames.normal of the corner, unit length
  glm::vec4 tangent;    // frames.tangent of the corner: xyz unit, w = +1 or -1
  glm::vec2 uv;         // OBJ convention, v = 1 at the top of the image
  glm::vec3 bitangent;  // the corner's B of BitangentMode::per_vertex (nmbake::interpolate_frame at
                        // the corner), interpolated when a map was baked that way
};
static_assert(sizeof(LowVertex) == 60, "LowVertex is uploaded as tightly packed floats");

// High-poly vertex: position and its own normal.
struct HighVertex {
  glm::vec3 position;  // object space minus the scene centre
  glm::vec3 normal;    // unit length
};
static_assert(sizeof(HighVertex) == 24, "HighVertex is uploaded as tightly packed floats");

template <class V>
struct IndexedVertices {
  std::vector<V> vertices;
  std::vector<std::uint32_t> indices;  // 3 per triangle, counter-clockwise from the front
  std::size_t triangle_count() const { return indices.size() / 3; }
};
using LowVertices = IndexedVertices<LowVertex>;
using HighVertices = IndexedVertices<HighVertex>;

// One vertex per distinct (position, normal, tangent, uv) corner of `mesh`, which must have UVs;
// `frames` must come from nmbake::compute_tangent_frames(mesh).
LowVertices build_low_vertices(const nmbake::Mesh& mesh, const nmbake::TangentFrames& frames, glm::vec3 centre);

// One vertex per distinct (position, normal) pair; `mesh` must have normals (see
// nmbake::ensure_normals). Meshes whose normals are indexed like their positions take a fast path
// with no merging.
HighVertices build_high_vertices(const nmbake::Mesh& mesh, glm::vec3 centre);

}  // namespace nmview
