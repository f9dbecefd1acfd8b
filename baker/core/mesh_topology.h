// Topology checks of a mesh and the normals computed for a high-poly that has none.
//
// Vertices are compared by value: positions with bit-identical coordinates are one vertex (exporters
// split vertices at UV seams and hard edges; a file's vertex order carries no meaning here). Faces
// are compared as sets of welded vertices.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "core/mesh.h"

namespace nmbake {

struct MeshTopology {
  std::size_t welded_vertices = 0;     // distinct positions used by faces
  std::size_t isolated_vertices = 0;   // file vertices no face uses
  std::size_t duplicate_faces = 0;     // faces repeating an earlier face's vertex set (any order)
  std::size_t boundary_edges = 0;      // edges used by one face
  std::size_t non_manifold_edges = 0;  // edges used by three faces or more
  // Faces wound against their neighbours: per edge-connected piece (across manifold edges), the
  // faces on the minority side of the winding. 0 for a consistently wound mesh.
  std::size_t inconsistent_winding_faces = 0;
};

// threads <= 0: all cores; the answers do not depend on it.
MeshTopology inspect_topology(const Mesh& mesh, int threads = 0);

// Per position, an id shared by all positions with bit-identical coordinates (-0 equals +0).
// `count` receives the number of distinct ids. Ids in order of first occurrence, on any number of
// threads (<= 0: all cores).
std::vector<std::uint32_t> weld_positions(const std::vector<glm::vec3>& positions, std::size_t* count = nullptr, int threads = 0);

// Angle-weighted smooth normals for a high-poly without normals, one per corner (3 per triangle):
// vertices welded by value, duplicate faces counted once, and faces wound against their
// neighbours turned to the majority winding of their piece first (`reoriented` receives how many).
// Zero-area faces carry no direction; a vertex with none gets (0,0,1). Never NaN.
std::vector<glm::vec3> compute_high_corner_normals(const Mesh& mesh, std::size_t* reoriented = nullptr, int threads = 0);
// The same into `out` (3 per triangle), the caller's storage; `topology`, when not null, receives
// what inspect_topology finds (the same analysis: a bake that computes the normals need not check
// again).
void compute_high_corner_normals(const Mesh& mesh, glm::vec3* out, MeshTopology* topology = nullptr, int threads = 0);

}  // namespace nmbake
