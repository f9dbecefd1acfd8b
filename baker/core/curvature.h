// Mean curvature of a mesh's surface at its vertices, from its own positions (not its normals):
// the discrete mean-curvature normal of Meyer, Desbrun, Schroeder and Barr 2003, "Discrete
// differential-geometry operators for triangulated 2-manifolds" (the cotangent Laplacian over the
// one-ring, divided by the vertex's mixed Voronoi area), for the curvature map of a texture set.
//
// Vertices are welded by value first (core/mesh_topology.h weld_positions: bit-identical xyz is
// one vertex), so that positions split at UV seams and hard edges get one value and a seam does not
// show. The answer is in 1/(the mesh's units) and is signed by the winding: positive where the
// surface bulges towards its front (a sphere of radius R wound outwards +1/R, wound inwards -1/R;
// an outward cylinder +1/(2R)), 0 on a plane.
#pragma once

#include <cstddef>
#include <vector>

#include "core/mesh.h"

namespace nmbake {

struct CurvatureOptions {
  // Passes of area-weighted averaging over the welded mesh, for noisy scans and sculpts; 0 = none.
  // Each pass gives every vertex the area-weighted mean of its faces' values (a face's value: the
  // mean of its corners'), so n passes reach n rings of neighbours (a reach in rings, not in scene
  // units: a denser mesh needs more passes for the same width). A constant field is kept. Negative: 0.
  int smoothing = 0;
  int threads = 0;  // <= 0: all cores; the answer does not depend on it
};

// What the computation met, for the report. Counts are of welded vertices and of triangles.
struct CurvatureStats {
  std::size_t welded_vertices = 0;    // distinct positions
  std::size_t border_vertices = 0;    // on an open or non-manifold edge: valued from their neighbours
  std::size_t unvalued_vertices = 0;  // no face, or no neighbour with a value: 0
  std::size_t degenerate_faces = 0;   // zero area, two corners welded, or a non-finite corner: ignored
  std::size_t duplicate_faces = 0;    // the same three welded vertices as an earlier face: ignored
};

// One signed mean curvature per entry of mesh.positions (1/units; duplicates of one welded
// position share its value; positions no face uses: 0). Never NaN or inf.
//
// Per welded vertex i with one-ring triangles T (Meyer et al. section 3.3 and 3.5):
//   K_i = (1 / (2 A_i)) sum_j (cot a_ij + cot b_ij) (x_i - x_j),   H_i = K_i . n_i / 2,
// where A_i is the mixed area (the Voronoi area in non-obtuse triangles, a half or a quarter of an
// obtuse one) and n_i the unit area-weighted normal of the winding: H is the normal part of the
// mean-curvature normal (its tangential part on an irregular mesh is discretisation error). One
// triangle's cotangent terms at x_i are summed in their closed form, n_T x (x_k - x_j) (twice the
// gradient of its area; (i, j, k) counter-clockwise), as long as the opposite edge however thin the
// triangle, where the cotangents of a needle or cap triangle grow without bound; Voronoi areas are
// clamped to [0, the triangle's area].
//
// Degenerate but legal input:
//  - zero-area triangles (and ones with two corners welded or a non-finite corner) contribute nothing;
//  - a border vertex (on an edge with one face, or with three or more: open meshes, non-manifold
//    fans) has no meaningful one-ring, so it takes the mean of its interior neighbours' values (the
//    vertices it shares a face with); one with none (a corner of a grid) takes the mean of its
//    neighbours valued that way; with none of either, 0. So a flat grid is 0 everywhere, border
//    included, and an open cylinder's rim takes the cylinder's value. An interior vertex with no
//    area or whose normal cancels to zero is valued the same way;
//  - a repeated face (same three welded vertices, either winding) counts once;
//  - faces wound against their neighbours: the Laplacian does not depend on winding; the sign
//    follows the vertex's area-weighted normal, which such faces partly cancel.
// Linear time and memory; the welding's lists and the faces' sums (one pass in face order) on one
// core, the per-face and per-vertex passes on `threads` (the smoothing gathers each vertex's values
// over its faces in face order), so the same to the bit on any number of threads.
std::vector<float> vertex_mean_curvature(const Mesh& mesh, const CurvatureOptions& opt = {}, CurvatureStats* stats = nullptr);

}  // namespace nmbake
