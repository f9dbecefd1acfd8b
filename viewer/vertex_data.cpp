#include "vertex_data.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <numeric>
#include <unordered_map>

namespace nmview {

Bounds mesh_bounds(const nmbake::Mesh& mesh) {
  Bounds b;
  for (std::uint32_t i : mesh.position_index) b.extend(mesh.positions[i]);
  return b;
}

LowVertices build_low_vertices(const nmbake::Mesh& mesh, const nmbake::TangentFrames& frames, glm::vec3 centre) {
  assert(mesh.has_uvs());
  const std::size_t corners = mesh.position_index.size();
  assert(frames.normal.size() == corners && frames.tangent.size() == corners);

  std::vector<LowVertex> corner(corners);
  for (std::size_t c = 0; c < corners; ++c) {
    corner[c].position = mesh.positions[mesh.position_index[c]] - centre;
    corner[c].normal = frames.normal[c];
    corner[c].tangent = frames.tangent[c];
    corner[c].uv = mesh.uvs[mesh.uv_index[c]];
    const double at_corner[3] = {c % 3 == 0 ? 1.0 : 0.0, c % 3 == 1 ? 1.0 : 0.0, c % 3 == 2 ? 1.0 : 0.0};
    corner[c].bitangent = glm::vec3(nmbake::interpolate_frame(frames, c / 3, at_corner, nmbake::BitangentMode::per_vertex).b);
  }

  // Merge corners with identical bytes: sort an index permutation, then number the runs.
  // Byte equality (not float equality) keeps -0/+0 apart, which only costs a duplicate vertex.
  std::vector<std::uint32_t> order(corners);
  std::iota(order.begin(), order.end(), 0u);
  auto less = [&](std::uint32_t a, std::uint32_t b) {
    int r = std::memcmp(&corner[a], &corner[b], sizeof(LowVertex));
    return r != 0 ? r < 0 : a < b;
  };
  std::sort(order.begin(), order.end(), less);

  LowVertices out;
  out.indices.resize(corners);
  for (std::size_t k = 0; k < corners; ++k) {
    std::uint32_t c = order[k];
    if (k == 0 || std::memcmp(&corner[c], &out.vertices.back(), sizeof(LowVertex)) != 0) out.vertices.push_back(corner[c]);
    out.indices[c] = static_cast<std::uint32_t>(out.vertices.size() - 1);
  }
  return out;
}

HighVertices build_high_vertices(const nmbake::Mesh& mesh, glm::vec3 centre) {
  assert(mesh.has_normals());
  HighVertices out;
  const std::size_t corners = mesh.position_index.size();

  if (mesh.normal_index == mesh.position_index && mesh.normals.size() == mesh.positions.size()) {
    out.vertices.resize(mesh.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) out.vertices[i] = {mesh.positions[i] - centre, mesh.normals[i]};
    out.indices = mesh.position_index;
    return out;
  }

  std::unordered_map<std::uint64_t, std::uint32_t> ids;
  ids.reserve(corners);
  out.indices.resize(corners);
  for (std::size_t c = 0; c < corners; ++c) {
    std::uint32_t p = mesh.position_index[c], n = mesh.normal_index[c];
    std::uint64_t key = (std::uint64_t(p) << 32) | n;
    auto [it, inserted] = ids.emplace(key, static_cast<std::uint32_t>(out.vertices.size()));
    if (inserted) out.vertices.push_back({mesh.positions[p] - centre, mesh.normals[n]});
    out.indices[c] = it->second;
  }
  return out;
}

}  // namespace nmview
