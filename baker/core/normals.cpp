#include "core/normals.h"

#include <cmath>

namespace nmbake {

std::vector<glm::vec3> compute_vertex_normals(const Mesh& mesh) {
  std::vector<glm::dvec3> sum(mesh.positions.size(), glm::dvec3(0.0));
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const glm::dvec3 p[3] = {glm::dvec3(mesh.corner_position(t, 0)), glm::dvec3(mesh.corner_position(t, 1)),
                             glm::dvec3(mesh.corner_position(t, 2))};
    const glm::dvec3 face = glm::cross(p[1] - p[0], p[2] - p[0]);
    const double len = glm::length(face);
    if (!(len > 0.0) || !std::isfinite(len)) continue;  // zero-area faces carry no direction
    const glm::dvec3 unit = face / len;
    for (int c = 0; c < 3; ++c) {
      const glm::dvec3 a = p[(c + 1) % 3] - p[c], b = p[(c + 2) % 3] - p[c];
      const double la = glm::length(a), lb = glm::length(b);
      if (!(la > 0.0) || !(lb > 0.0)) continue;
      // atan2 of |cross| and dot is accurate for angles near 0 and pi, unlike acos.
      const double angle = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
      sum[mesh.position_index[3 * t + c]] += angle * unit;
    }
  }
  std::vector<glm::vec3> out(sum.size());
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const double len = glm::length(sum[i]);
    out[i] = (len > 0.0 && std::isfinite(len)) ? glm::vec3(sum[i] / len) : glm::vec3(0, 0, 1);
  }
  return out;
}

bool ensure_normals(Mesh& mesh) {
  if (mesh.has_normals()) return false;
  mesh.normals = compute_vertex_normals(mesh);
  mesh.normal_index = mesh.position_index;
  return true;
}

}  // namespace nmbake
