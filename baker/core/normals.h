// Smooth vertex normals and position-averaged normals.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "core/mesh.h"

namespace nmbake {

// Angle-weighted vertex normals (Thuermer and Wuethrich 1998), one per position. A position whose
// faces all have zero area gets (0,0,1). Never NaN.
std::vector<glm::vec3> compute_vertex_normals(const Mesh& mesh);

// Gives `mesh` per-position smooth normals (normal_index = position_index) when it has none.
// Returns true when normals were computed.
bool ensure_normals(Mesh& mesh);

}  // namespace nmbake
