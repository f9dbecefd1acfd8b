// Smooth vertex normals and position-averaged normals.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/mesh.h"

namespace nmbake {

// The one angle-weighted normal rule (Thuermer and Wuethrich 1998) of the baker and the viewer:
// per vertex, the sum over its faces of the corner angle times the unit face normal. Vertices are
// the corners' `corner_vertex` ids (3 per triangle; null: the position index), `vertices` of them;
// faces marked in `skip` (1 per triangle, or null) count nothing, faces marked in `flip` count
// reversed. Zero-area faces carry no direction.
// Each sum adds its faces in face order: the same bits on any number of threads (<= 0: all cores).
std::vector<glm::dvec3> angle_weighted_sums(const Mesh& mesh, const std::uint32_t* corner_vertex, std::size_t vertices,
                                            const std::uint8_t* skip = nullptr, const std::uint8_t* flip = nullptr,
                                            int threads = 0);
// A sum made unit, or (0,0,1) when it has no direction. Never NaN.
glm::vec3 unit_or_up(const glm::dvec3& sum);

// Angle-weighted vertex normals, one per position (positions not welded: the low-poly's own
// vertices, as its tangent frames take them).
std::vector<glm::vec3> compute_vertex_normals(const Mesh& mesh);

// Gives `mesh` the normals the bake computes for a high-poly without them, one per corner
// (compute_high_corner_normals, mesh_topology.h: welded, one winding per piece), when it has none.
// Returns true when normals were computed.
bool ensure_normals(Mesh& mesh);

// Several high-poly meshes (`nmbake LOW HIGH HIGH...`, all on one origin) as one: their triangles
// in order, indices moved on. One mesh is returned as it is. With several, each without normals
// first gets the ones the bake would compute for it alone (ensure_normals), so that the others
// keep theirs; UVs are kept only when every one has them. Triangles keep their file's face numbers.
Mesh merge_meshes(std::vector<Mesh> meshes);

}  // namespace nmbake
