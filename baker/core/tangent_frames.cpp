// Tangent frames with MikkTSpace semantics (Mikkelsen 2008). The structure follows the published
// algorithm: weld corners by value, per-triangle UV gradients, groups of triangles around each
// welded vertex that are edge-connected and share the UV orientation, angle-weighted averages of
// projected tangents per group. Written from the paper and the convention's documented behaviour.
#include "core/tangent_frames.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include "core/normals.h"

namespace nmbake {

namespace {

// Relative thresholds below which an area counts as zero. Thin but real triangles (aspect 1e6)
// stay far above them.
constexpr double kDegenerateRelative = 1e-12;

struct CornerKey {
  float v[8];  // position, normal, uv
  bool operator==(const CornerKey& o) const { return std::memcmp(v, o.v, sizeof v) == 0; }
};
struct CornerKeyHash {
  std::size_t operator()(const CornerKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    const unsigned char* p = reinterpret_cast<const unsigned char*>(k.v);
    for (std::size_t i = 0; i < sizeof k.v; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return std::size_t(h);
  }
};

struct TriInfo {
  glm::dvec3 tangent{0.0};  // unit dP/du, or zero
  bool orient_preserving = false;
  bool free_orientation = false;  // zero UV area: joins the orientation of the first group reaching it
  bool contributes = false;       // has a usable tangent and nonzero 3D area
  bool coincident = false;        // two corners at the same position: left out of grouping
};

glm::dvec3 any_orthogonal(const glm::dvec3& n) {
  const glm::dvec3 a =
      std::abs(n.x) < 0.6 ? glm::dvec3(1, 0, 0) : (std::abs(n.y) < 0.6 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1));
  const glm::dvec3 t = a - glm::dot(a, n) * n;
  const double len = glm::length(t);
  return len > 0.0 ? t / len : glm::dvec3(1, 0, 0);
}

glm::dvec3 project_normalize(const glm::dvec3& v, const glm::dvec3& n) {
  const glm::dvec3 p = v - glm::dot(n, v) * n;
  const double len = glm::length(p);
  return len > 0.0 ? p / len : p;
}

// +0 for -0 so that welding by bits treats them as equal, as a float comparison would.
float canon(float x) { return x + 0.0f; }

// The mesh's corners as the steps read them: normals (the file's, else smooth vertex normals),
// positions and UVs in double.
struct Corners {
  explicit Corners(const Mesh& m) : mesh(m) {
    if (!mesh.has_normals()) {
      computed = compute_vertex_normals(mesh);
      normals = &computed;
      normal_index = &mesh.position_index;
    }
  }
  glm::dvec3 normal(std::size_t c) const { return glm::dvec3((*normals)[(*normal_index)[c]]); }
  glm::dvec3 pos(std::size_t c) const { return glm::dvec3(mesh.positions[mesh.position_index[c]]); }
  glm::dvec2 uv(std::size_t c) const { return glm::dvec2(mesh.uvs[mesh.uv_index[c]]); }

  const Mesh& mesh;
  std::vector<glm::vec3> computed;
  const std::vector<glm::vec3>* normals = &mesh.normals;
  const std::vector<std::uint32_t>* normal_index = &mesh.normal_index;
};

struct Group {
  std::uint32_t rep;
  bool orient_preserving;
  std::vector<std::uint32_t> tris;
};

// The corner of triangle t at welded vertex rep, or -1.
int corner_with(const std::vector<std::uint32_t>& vid, std::size_t t, std::uint32_t rep) {
  for (int i = 0; i < 3; ++i)
    if (vid[3 * t + std::size_t(i)] == rep) return i;
  return -1;
}

// 1. Corners welded by the value of position, normal and UV: an id per corner.
std::vector<std::uint32_t> weld_corners(const Corners& in) {
  const Mesh& mesh = in.mesh;
  const std::size_t corners = mesh.position_index.size();
  std::vector<std::uint32_t> vid(corners);
  {
    std::unordered_map<CornerKey, std::uint32_t, CornerKeyHash> ids;
    ids.reserve(corners);
    for (std::size_t c = 0; c < corners; ++c) {
      const glm::vec3 p = mesh.positions[mesh.position_index[c]];
      const glm::vec3 n = (*in.normals)[(*in.normal_index)[c]];
      const glm::vec2 t = mesh.uvs[mesh.uv_index[c]];
      CornerKey key{{canon(p.x), canon(p.y), canon(p.z), canon(n.x), canon(n.y), canon(n.z), canon(t.x), canon(t.y)}};
      vid[c] = ids.emplace(key, std::uint32_t(ids.size())).first->second;
    }
  }

  return vid;
}

// 2. Per triangle: UV gradient dP/du, orientation, degeneracy.
std::vector<TriInfo> triangle_info(const Corners& in, TangentFrames& out) {
  const std::size_t tris = in.mesh.triangle_count();
  auto corner_pos = [&](std::size_t c) { return in.pos(c); };
  auto corner_uv = [&](std::size_t c) { return in.uv(c); };
  std::vector<TriInfo> info(tris);
  for (std::size_t t = 0; t < tris; ++t) {
    TriInfo& ti = info[t];
    const glm::dvec3 p0 = corner_pos(3 * t), p1 = corner_pos(3 * t + 1), p2 = corner_pos(3 * t + 2);
    ti.coincident = p0 == p1 || p0 == p2 || p1 == p2;
    const glm::dvec3 d1 = p1 - p0, d2 = p2 - p0;
    const glm::dvec2 t21 = corner_uv(3 * t + 1) - corner_uv(3 * t), t31 = corner_uv(3 * t + 2) - corner_uv(3 * t);
    const double uv_area2 = t21.x * t31.y - t21.y * t31.x;
    const double uv_scale = glm::dot(t21, t21) + glm::dot(t31, t31);
    const double area3 = glm::length(glm::cross(d1, d2));
    const double scale3 = std::max(glm::dot(d1, d1), glm::dot(d2, d2));
    const bool zero_3d = !(area3 > kDegenerateRelative * scale3);
    const bool zero_uv = !(std::abs(uv_area2) > kDegenerateRelative * uv_scale);
    ti.orient_preserving = uv_area2 > 0.0;
    if (zero_uv) ++out.degenerate_uv_triangles;
    if (zero_3d) ++out.degenerate_3d_triangles;
    ti.free_orientation = zero_uv;
    if (!zero_uv) {
      // dP/du * uv_area2; dividing by the signed area makes mirrored triangles point along +u too.
      const glm::dvec3 os = (t31.y * d1 - t21.y * d2) / uv_area2;
      const double len = glm::length(os);
      if (len > 0.0 && std::isfinite(len)) {
        ti.tangent = os / len;
        ti.contributes = !zero_3d;
      } else {
        ti.free_orientation = true;
      }
    }
  }

  return info;
}

// 3. Neighbours across edges whose welded ends match with opposite direction.
std::vector<std::int32_t> edge_neighbours(const std::vector<std::uint32_t>& vid, const std::vector<TriInfo>& info) {
  const std::size_t corners = vid.size(), tris = info.size();
  std::vector<std::int32_t> neighbour(corners, -1);  // across edge (i, i+1) of each triangle
  {
    std::unordered_map<std::uint64_t, std::uint32_t> edges;
    edges.reserve(corners);
    auto key = [](std::uint32_t a, std::uint32_t b) { return (std::uint64_t(a) << 32) | b; };
    for (std::size_t t = 0; t < tris; ++t) {
      if (info[t].coincident) continue;
      for (int i = 0; i < 3; ++i) edges.emplace(key(vid[3 * t + i], vid[3 * t + (i + 1) % 3]), std::uint32_t(t));
    }
    for (std::size_t t = 0; t < tris; ++t) {
      if (info[t].coincident) continue;
      for (int i = 0; i < 3; ++i) {
        auto it = edges.find(key(vid[3 * t + (i + 1) % 3], vid[3 * t + i]));
        if (it != edges.end() && it->second != t) neighbour[3 * t + i] = std::int32_t(it->second);
      }
    }
  }

  return neighbour;
}

// 4. Groups: around each welded vertex, the triangles reached across edges with one orientation.
// group_of receives each corner's group (-1: none).
std::vector<Group> build_groups(const std::vector<std::uint32_t>& vid, std::vector<TriInfo>& info,
                                const std::vector<std::int32_t>& neighbour, std::vector<std::int32_t>& group_of) {
  const std::size_t tris = info.size();
  std::vector<Group> groups;
  std::vector<std::uint32_t> stack;
  for (std::size_t f = 0; f < tris; ++f) {
    if (info[f].coincident || info[f].free_orientation) continue;
    for (int i = 0; i < 3; ++i) {
      if (group_of[3 * f + i] >= 0) continue;
      const std::int32_t g = std::int32_t(groups.size());
      groups.push_back({vid[3 * f + i], info[f].orient_preserving, {std::uint32_t(f)}});
      group_of[3 * f + i] = g;
      // Depth-first, left neighbour before right, as a recursive walk would go.
      stack.clear();
      stack.push_back(std::uint32_t(neighbour[3 * f + (i + 2) % 3]));
      stack.push_back(std::uint32_t(neighbour[3 * f + i]));
      while (!stack.empty()) {
        const std::int32_t t = std::int32_t(stack.back());
        stack.pop_back();
        if (t < 0) continue;
        const int k = corner_with(vid, std::size_t(t), groups[g].rep);
        if (k < 0 || group_of[3 * t + k] >= 0) continue;
        TriInfo& ti = info[t];
        if (ti.free_orientation && group_of[3 * t] < 0 && group_of[3 * t + 1] < 0 && group_of[3 * t + 2] < 0)
          ti.orient_preserving = groups[g].orient_preserving;
        if (ti.orient_preserving != groups[g].orient_preserving) continue;
        groups[g].tris.push_back(std::uint32_t(t));
        group_of[3 * t + k] = g;
        stack.push_back(std::uint32_t(neighbour[3 * t + (k + 2) % 3]));
        stack.push_back(std::uint32_t(neighbour[3 * t + k]));
      }
    }
  }

  return groups;
}

// 5. Per group: angle-weighted mean of the members' tangents projected onto the normal's plane.
std::vector<glm::dvec3> group_tangents(const Corners& in, const std::vector<std::uint32_t>& vid, const std::vector<TriInfo>& info,
                                       const std::vector<Group>& groups) {
  auto corner_normal = [&](std::size_t c) { return in.normal(c); };
  auto corner_pos = [&](std::size_t c) { return in.pos(c); };
  std::vector<glm::dvec3> group_tangent(groups.size(), glm::dvec3(0.0));
  for (std::size_t g = 0; g < groups.size(); ++g) {
    glm::dvec3 sum(0.0);
    for (std::uint32_t f : groups[g].tris) {
      if (!info[f].contributes) continue;
      const int i = corner_with(vid, f, groups[g].rep);
      const glm::dvec3 n = corner_normal(3 * f + i);
      const glm::dvec3 os = project_normalize(info[f].tangent, n);
      const glm::dvec3 p1 = corner_pos(3 * f + i);
      const glm::dvec3 v1 = project_normalize(corner_pos(3 * f + (i + 2) % 3) - p1, n);
      const glm::dvec3 v2 = project_normalize(corner_pos(3 * f + (i + 1) % 3) - p1, n);
      const double angle = std::acos(std::clamp(glm::dot(v1, v2), -1.0, 1.0));
      sum += angle * os;
    }
    group_tangent[g] = sum;
  }

  return group_tangent;
}

// 6. Per corner output; corners without a group copy the first grouped corner of their welded
//    vertex (as MikkTSpace does for degenerate triangles), else any tangent orthogonal to N.
void corner_frames(const Corners& in, const std::vector<std::uint32_t>& vid, const std::vector<Group>& groups,
                   const std::vector<std::int32_t>& group_of, const std::vector<glm::dvec3>& group_tangent, TangentFrames& out) {
  const std::size_t corners = vid.size();
  auto corner_normal = [&](std::size_t c) { return in.normal(c); };
  std::vector<std::int32_t> first_grouped(corners, -1);  // by welded vertex id (ids < corners)
  for (std::size_t c = 0; c < corners; ++c)
    if (group_of[c] >= 0 && first_grouped[vid[c]] < 0) first_grouped[vid[c]] = group_of[c];
  out.normal.resize(corners);
  out.tangent.resize(corners);
  for (std::size_t c = 0; c < corners; ++c) {
    glm::dvec3 n = corner_normal(c);
    const double nlen = glm::length(n);
    n = nlen > 0.0 && std::isfinite(nlen) ? n / nlen : glm::dvec3(0, 0, 1);
    std::int32_t g = group_of[c] >= 0 ? group_of[c] : first_grouped[vid[c]];
    glm::dvec3 t(0.0);
    double sign = 1.0;
    if (g >= 0) {
      t = project_normalize(group_tangent[g], n);
      sign = groups[g].orient_preserving ? 1.0 : -1.0;
    }
    if (!(glm::length(t) > 0.5)) {
      t = any_orthogonal(n);
      ++out.corners_without_tangent;
    }
    out.normal[c] = glm::vec3(n);
    out.tangent[c] = glm::vec4(glm::vec3(t), float(sign));
  }
}

}  // namespace

TangentFrames compute_tangent_frames(const Mesh& mesh) {
  assert(mesh.has_uvs());
  TangentFrames out;
  const Corners in(mesh);
  const std::vector<std::uint32_t> vid = weld_corners(in);
  std::vector<TriInfo> info = triangle_info(in, out);
  const std::vector<std::int32_t> neighbour = edge_neighbours(vid, info);
  std::vector<std::int32_t> group_of(vid.size(), -1);
  const std::vector<Group> groups = build_groups(vid, info, neighbour, group_of);
  corner_frames(in, vid, groups, group_of, group_tangents(in, vid, info, groups), out);
  return out;
}

PixelFrame interpolate_frame(const TangentFrames& frames, std::size_t tri, const double bary[3], BitangentMode mode) {
  return interpolate_frame(&frames.normal[3 * tri], &frames.tangent[3 * tri], bary, mode);
}

glm::dvec3 decode_tangent_normal(const PixelFrame& f, const glm::dvec3& t) {
  const glm::dvec3 w = t.x * f.t + t.y * f.b + t.z * f.n;
  const double len = glm::length(w);
  return len > 0.0 ? w / len : glm::dvec3(0.0, 0.0, 1.0);
}

}  // namespace nmbake
