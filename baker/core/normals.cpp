#include "core/normals.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "core/mesh_topology.h"
#include "core/parallel.h"

namespace nmbake {

namespace {

// A face's shares of its vertices' sums: corner c adds share[c] to vertex[c]'s sum, or nothing when
// vertex[c] is kNoShare (a face that counts nothing, a corner with no angle).
constexpr std::uint32_t kNoShare = 0xffffffffu;

struct FaceShares {
  std::uint32_t vertex[3];
  glm::dvec3 share[3];
};

FaceShares face_shares(const Mesh& mesh, std::size_t t, const std::uint32_t* corner_vertex, const std::uint8_t* skip,
                       const std::uint8_t* flip) {
  FaceShares f;
  f.vertex[0] = f.vertex[1] = f.vertex[2] = kNoShare;
  if (skip && skip[t]) return f;
  const glm::dvec3 p[3] = {glm::dvec3(mesh.corner_position(t, 0)), glm::dvec3(mesh.corner_position(t, 1)),
                           glm::dvec3(mesh.corner_position(t, 2))};
  glm::dvec3 face = glm::cross(p[1] - p[0], p[2] - p[0]);
  const double len = glm::length(face);
  if (!(len > 0.0) || !std::isfinite(len)) return f;  // zero-area faces carry no direction
  face /= len;
  if (flip && flip[t]) face = -face;
  for (int c = 0; c < 3; ++c) {
    const glm::dvec3 a = p[(c + 1) % 3] - p[c], b = p[(c + 2) % 3] - p[c];
    if (!(glm::length(a) > 0.0) || !(glm::length(b) > 0.0)) continue;
    // atan2 of |cross| and dot is accurate for angles near 0 and pi, unlike acos.
    const double angle = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
    const std::size_t corner = 3 * t + std::size_t(c);
    f.vertex[c] = corner_vertex ? corner_vertex[corner] : mesh.position_index[corner];
    f.share[c] = angle * face;
  }
  return f;
}

}  // namespace

// Each vertex's sum adds its shares in face order, whatever the threads. Faces go in blocks of
// chunks: the threads work out a block's shares (the angles, most of the work) chunk by chunk,
// each share into its chunk's list for the thread that owns its vertex (runs of 64 ids dealt
// round); then each thread adds its lists, chunk after chunk, to its own vertices' sums. So every
// sum is the one the face-by-face loop makes, to the bit.
std::vector<glm::dvec3> angle_weighted_sums(const Mesh& mesh, const std::uint32_t* corner_vertex, std::size_t vertices,
                                            const std::uint8_t* skip, const std::uint8_t* flip, int threads) {
  std::vector<glm::dvec3> sum(vertices, glm::dvec3(0.0));
  const std::size_t tris = mesh.triangle_count();
  constexpr std::size_t kChunk = 4096;  // faces
  constexpr std::size_t kChunks = 16;   // per block
  const int n = std::min(worker_threads(threads), int((tris + kChunk - 1) / kChunk));
  if (n <= 1) {
    for (std::size_t t = 0; t < tris; ++t) {
      const FaceShares f = face_shares(mesh, t, corner_vertex, skip, flip);
      for (int c = 0; c < 3; ++c)
        if (f.vertex[c] != kNoShare) sum[f.vertex[c]] += f.share[c];
    }
    return sum;
  }
  struct Share {
    std::uint32_t vertex;
    glm::dvec3 share;
  };
  const std::size_t owners = std::size_t(n);
  struct alignas(64) List {  // one cache line each: the threads push to neighbouring lists
    std::vector<Share> shares;
  };
  std::vector<List> lists(kChunks * owners);  // [chunk in block][owner]
  for (std::size_t b0 = 0; b0 < tris; b0 += kChunk * kChunks) {
    const std::size_t chunks = std::min(kChunks, (tris - b0 + kChunk - 1) / kChunk);
    parallel_chunks(n, chunks, 1, [&](std::size_t k0, std::size_t k1) {
      for (std::size_t k = k0; k < k1; ++k) {
        List* own = &lists[k * owners];
        for (std::size_t j = 0; j < owners; ++j) own[j].shares.clear();
        const std::size_t t1 = std::min(tris, b0 + (k + 1) * kChunk);
        for (std::size_t t = b0 + k * kChunk; t < t1; ++t) {
          const FaceShares f = face_shares(mesh, t, corner_vertex, skip, flip);
          for (int c = 0; c < 3; ++c)
            if (f.vertex[c] != kNoShare) own[(f.vertex[c] >> 6) % owners].shares.push_back({f.vertex[c], f.share[c]});
        }
      }
    });
    run_on_threads(n, [&](int id) {
      for (std::size_t k = 0; k < chunks; ++k)
        for (const Share& sh : lists[k * owners + std::size_t(id)].shares) sum[sh.vertex] += sh.share;
    });
  }
  return sum;
}

glm::vec3 unit_or_up(const glm::dvec3& sum) {
  const double len = glm::length(sum);
  return (len > 0.0 && std::isfinite(len)) ? glm::vec3(sum / len) : glm::vec3(0, 0, 1);
}

std::vector<glm::vec3> compute_vertex_normals(const Mesh& mesh) {
  const std::vector<glm::dvec3> sum = angle_weighted_sums(mesh, nullptr, mesh.positions.size());
  std::vector<glm::vec3> out(sum.size());
  for (std::size_t i = 0; i < sum.size(); ++i) out[i] = unit_or_up(sum[i]);
  return out;
}

bool ensure_normals(Mesh& mesh) {
  if (mesh.has_normals()) return false;
  mesh.normals = compute_high_corner_normals(mesh);
  mesh.normal_index.resize(mesh.normals.size());
  for (std::size_t c = 0; c < mesh.normal_index.size(); ++c) mesh.normal_index[c] = std::uint32_t(c);
  return true;
}

// Beyond normals.h's contract: materials are merged by name (Mesh::materials), vertex colours kept
// only when every mesh has them, like UVs.
Mesh merge_meshes(std::vector<Mesh> meshes) {
  if (meshes.size() == 1) return std::move(meshes.front());
  Mesh out;
  if (meshes.empty()) return out;
  out.source = meshes.front().source;
  out.origin = meshes.front().origin;
  bool uvs = true, colors = true, materials = false;
  for (Mesh& m : meshes) {
    ensure_normals(m);
    uvs = uvs && m.has_uvs();
    colors = colors && m.has_colors();
    materials = materials || m.material_count() > 0;
  }
  // Materials by name; a file that names none gives its triangles the material "".
  std::unordered_map<std::string, std::uint32_t> material_by_name;
  auto material_number = [&](const std::string& name) {
    const auto [it, added] = material_by_name.try_emplace(name, std::uint32_t(out.materials.size()));
    if (added) out.materials.push_back(name);
    return it->second;
  };
  for (const Mesh& m : meshes) {
    const auto p0 = std::uint32_t(out.positions.size()), n0 = std::uint32_t(out.normals.size()),
               u0 = std::uint32_t(out.uvs.size());
    out.positions.insert(out.positions.end(), m.positions.begin(), m.positions.end());
    out.normals.insert(out.normals.end(), m.normals.begin(), m.normals.end());
    for (std::uint32_t i : m.position_index) out.position_index.push_back(p0 + i);
    for (std::uint32_t i : m.normal_index) out.normal_index.push_back(n0 + i);
    if (uvs) {
      out.uvs.insert(out.uvs.end(), m.uvs.begin(), m.uvs.end());
      for (std::uint32_t i : m.uv_index) out.uv_index.push_back(u0 + i);
    }
    out.source_face.insert(out.source_face.end(), m.source_face.begin(), m.source_face.end());
    const auto o0 = std::uint32_t(out.objects.size());
    if (m.objects.empty()) out.objects.push_back({m.source, m.source});
    out.objects.insert(out.objects.end(), m.objects.begin(), m.objects.end());
    for (std::size_t t = 0; t < m.triangle_count(); ++t) out.triangle_object.push_back(o0 + m.object_of(t));
    if (colors) {
      const auto c0 = std::uint32_t(out.colors.size());
      out.colors.insert(out.colors.end(), m.colors.begin(), m.colors.end());
      for (std::uint32_t i : m.color_index) out.color_index.push_back(c0 + i);
    }
    if (materials) {
      std::vector<std::uint32_t> renumber;
      for (const std::string& name : m.materials) renumber.push_back(material_number(name));
      if (renumber.empty()) renumber.push_back(material_number(""));
      for (std::size_t t = 0; t < m.triangle_count(); ++t) out.triangle_material.push_back(renumber[m.material_of(t)]);
    }
  }
  if (out.objects.size() == 1) out.triangle_object.clear();
  if (out.materials.size() == 1) out.triangle_material.clear();
  return out;
}

}  // namespace nmbake
