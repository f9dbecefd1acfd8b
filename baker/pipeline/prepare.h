// Stage 2 of the bake, prepare: from the meshes, everything the rays and the shading read.
// Tangent frames, coordinates re-centred on the scene's bounding-box centre (float, as Embree takes
// them), ray normals, the high-poly's corner normals and facing codes, the low-poly triangles in
// double, and a cage's corners when there is one.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/image.h"
#include "core/mesh.h"
#include "core/tangent_frames.h"
#include "pipeline/bake.h"
#include "trace/shade_batch.h"

namespace nmbake {

// Per-corner normals, left unset as they grow: filled on every core, so the system's zeroing of
// their pages (their first touch) is shared out too.
using CornerNormals = std::vector<glm::vec3, DefaultInitAllocator<glm::vec3>>;

// The scene in re-centred coordinates, flat arrays for the hot loop.
struct Prepared {
  glm::dvec3 centre{0.0};
  double diagonal = 0.0;
  std::vector<glm::vec3> low_pos, cage_pos, high_pos;
  std::vector<glm::vec3> ray_normal;  // per low-poly position: mean of its corners' normals
  CornerNormals high_corner_normals;  // 3 per high-poly triangle: one cache line per hit
  // Per high-poly triangle: the side its normals point to, +1 that of cross(p1 - p0, p2 - p0)
  // (raycast::HitRule::facing).
  std::vector<std::int8_t> high_facing;
  TangentFrames frames;
  std::vector<LowTriangle> low_tris;
  std::vector<CageTriangle> cage_tris;  // per low-poly triangle, with a cage (attach_cage, set_cage_reach)
  // Per low-poly triangle its object (Mesh::triangle_object), or null: one object; the objects of
  // each mesh.
  const std::uint32_t* low_object = nullptr;
  std::size_t low_objects = 1, high_objects = 1;
};

// Fills st.prepare with what it learns on the way: degenerate counts, centre, coordinate precision, computed
// high-poly normals, UVs outside the unit square. A cage given is attached (and must enclose the
// low-poly: InputError otherwise).
Prepared prepare(const Mesh& low, const Mesh& high, const Mesh* cage, BakeStats& st);

// The cage's corners, re-centred, 3 per low-poly triangle (its topology is the low-poly's: 3
// position indices per triangle).
void attach_cage(Prepared& s, const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& index);

// The cage triangles' rear and search distances: per vertex (LocalDistances) when measured, else
// the one rear distance and no search beyond the cage.
void set_cage_reach(Prepared& s, const Mesh& low, double rear, const std::vector<float>& vertex_rear,
                    const std::vector<float>& vertex_search);

}  // namespace nmbake
