#include "core/mesh_topology.h"

#include "core/normals.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>

namespace nmbake {

namespace {

struct PosKey {
  std::uint32_t bits[3];
  bool operator==(const PosKey& o) const { return bits[0] == o.bits[0] && bits[1] == o.bits[1] && bits[2] == o.bits[2]; }
};
struct PosKeyHash {
  std::size_t operator()(const PosKey& k) const {
    std::uint64_t h = 1469598103934665603ull;
    for (std::uint32_t b : k.bits) h = (h ^ b) * 1099511628211ull;
    return std::size_t(h ^ (h >> 29));
  }
};

// Everything the checks and the normals share: welded corners, duplicate faces, and the faces to
// turn so that every piece has one winding.
struct Analysis {
  std::vector<std::uint32_t> weld;    // per position
  std::vector<std::uint32_t> corner;  // per corner: welded vertex
  std::vector<std::uint8_t> skip;     // per triangle: duplicate or collapsed (two corners welded)
  std::vector<std::uint8_t> flip;     // per triangle: wound against its piece's majority
  MeshTopology topo;
};

Analysis analyze(const Mesh& m) {
  Analysis a;
  const std::size_t tris = m.triangle_count();
  a.weld = weld_positions(m.positions, &a.topo.welded_vertices);
  a.corner.resize(3 * tris);
  for (std::size_t c = 0; c < 3 * tris; ++c) a.corner[c] = a.weld[m.position_index[c]];
  {
    std::vector<std::uint8_t> used(m.positions.size(), 0);
    for (std::uint32_t p : m.position_index) used[p] = 1;
    for (std::uint8_t u : used) a.topo.isolated_vertices += !u;
    std::vector<std::uint8_t> used_welded(a.topo.welded_vertices, 0);
    for (std::uint32_t w : a.corner) used_welded[w] = 1;
    a.topo.welded_vertices = std::size_t(std::count(used_welded.begin(), used_welded.end(), 1));
  }
  // Duplicate faces: the same sorted vertex triple as an earlier face.
  a.skip.assign(tris, 0);
  {
    struct Tri {
      std::uint32_t v[3];
      std::uint32_t face;
    };
    std::vector<Tri> sorted(tris);
    for (std::size_t t = 0; t < tris; ++t) {
      std::uint32_t v[3] = {a.corner[3 * t], a.corner[3 * t + 1], a.corner[3 * t + 2]};
      std::sort(v, v + 3);
      sorted[t] = {{v[0], v[1], v[2]}, std::uint32_t(t)};
      if (v[0] == v[1] || v[1] == v[2]) a.skip[t] = 1;  // collapsed: no edges, no direction
    }
    std::sort(sorted.begin(), sorted.end(), [](const Tri& x, const Tri& y) {
      if (x.v[0] != y.v[0]) return x.v[0] < y.v[0];
      if (x.v[1] != y.v[1]) return x.v[1] < y.v[1];
      if (x.v[2] != y.v[2]) return x.v[2] < y.v[2];
      return x.face < y.face;
    });
    auto same = [](const Tri& x, const Tri& y) { return x.v[0] == y.v[0] && x.v[1] == y.v[1] && x.v[2] == y.v[2]; };
    for (std::size_t i = 1; i < tris; ++i)
      if (same(sorted[i], sorted[i - 1]) && !a.skip[sorted[i].face]) {
        a.skip[sorted[i].face] = 1;
        ++a.topo.duplicate_faces;
      }
  }
  // Edges: sorted (undirected key, face, direction) records; runs of one key are one edge.
  struct Edge {
    std::uint64_t key;
    std::uint32_t face;
    std::uint32_t forward;  // 1 when the face runs from the smaller to the larger vertex
  };
  std::vector<Edge> edges;
  edges.reserve(3 * tris);
  for (std::size_t t = 0; t < tris; ++t) {
    if (a.skip[t]) continue;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t p = a.corner[3 * t + k], q = a.corner[3 * t + (k + 1) % 3];
      const std::uint64_t lo = std::min(p, q), hi = std::max(p, q);
      edges.push_back({(lo << 32) | hi, std::uint32_t(t), p < q ? 1u : 0u});
    }
  }
  std::sort(edges.begin(), edges.end(),
            [](const Edge& x, const Edge& y) { return x.key < y.key || (x.key == y.key && x.face < y.face); });
  // Manifold edges link two faces; `same` marks a pair running the edge the same way (one of the
  // two is wound against the other).
  std::vector<std::uint32_t> adj_start(tris + 1, 0);
  struct Link {
    std::uint32_t a, b, same;
  };
  std::vector<Link> links;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    const std::size_t n = j - i;
    if (n == 1) ++a.topo.boundary_edges;
    else if (n > 2) ++a.topo.non_manifold_edges;
    else if (edges[i].face != edges[i + 1].face)
      links.push_back({edges[i].face, edges[i + 1].face, edges[i].forward == edges[i + 1].forward});
    i = j;
  }
  for (const Link& l : links) ++adj_start[l.a + 1], ++adj_start[l.b + 1];
  for (std::size_t t = 0; t < tris; ++t) adj_start[t + 1] += adj_start[t];
  std::vector<std::uint32_t> adj(adj_start[tris]);
  std::vector<std::uint8_t> adj_same(adj_start[tris]);
  {
    std::vector<std::uint32_t> fill(adj_start.begin(), adj_start.end() - 1);
    for (const Link& l : links) {
      adj_same[fill[l.a]] = std::uint8_t(l.same);
      adj[fill[l.a]++] = l.b;
      adj_same[fill[l.b]] = std::uint8_t(l.same);
      adj[fill[l.b]++] = l.a;
    }
  }
  // Per piece: breadth-first, each face's winding relative to the seed; the minority is flipped.
  a.flip.assign(tris, 0);
  std::vector<std::int8_t> rel(tris, -1);
  std::vector<std::uint32_t> piece, queue;
  for (std::size_t seed = 0; seed < tris; ++seed) {
    if (a.skip[seed] || rel[seed] >= 0) continue;
    piece.clear();
    queue.assign(1, std::uint32_t(seed));
    rel[seed] = 0;
    std::size_t ones = 0;
    for (std::size_t qi = 0; qi < queue.size(); ++qi) {
      const std::uint32_t f = queue[qi];
      piece.push_back(f);
      ones += rel[f];
      for (std::uint32_t k = adj_start[f]; k < adj_start[f + 1]; ++k) {
        const std::uint32_t g = adj[k];
        if (rel[g] >= 0) continue;  // a conflict (non-orientable piece) keeps the first assignment
        rel[g] = std::int8_t(rel[f] ^ adj_same[k]);
        queue.push_back(g);
      }
    }
    // Ties keep the seed's (lowest face number's) winding.
    const std::int8_t minority = ones * 2 > piece.size() ? 0 : 1;
    for (std::uint32_t f : piece)
      if (rel[f] == minority) {
        a.flip[f] = 1;
        ++a.topo.inconsistent_winding_faces;
      }
  }
  return a;
}

}  // namespace

std::vector<std::uint32_t> weld_positions(const std::vector<glm::vec3>& positions, std::size_t* count) {
  std::unordered_map<PosKey, std::uint32_t, PosKeyHash> ids;
  ids.reserve(positions.size());
  std::vector<std::uint32_t> out(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) {
    PosKey k;
    for (int c = 0; c < 3; ++c) {
      const float v = positions[i][c] + 0.0f;  // -0 -> +0
      std::memcpy(&k.bits[c], &v, sizeof v);
    }
    out[i] = ids.emplace(k, std::uint32_t(ids.size())).first->second;
  }
  if (count) *count = ids.size();
  return out;
}

MeshTopology inspect_topology(const Mesh& mesh) { return analyze(mesh).topo; }

std::vector<glm::vec3> compute_high_corner_normals(const Mesh& m, std::size_t* reoriented) {
  const Analysis a = analyze(m);
  if (reoriented) *reoriented = a.topo.inconsistent_winding_faces;
  // Indexed by welded id (< positions).
  const std::vector<glm::dvec3> sum = angle_weighted_sums(m, &a.corner, m.positions.size(), &a.skip, &a.flip);
  std::vector<glm::vec3> out(3 * m.triangle_count());
  for (std::size_t c = 0; c < out.size(); ++c) out[c] = unit_or_up(sum[a.corner[c]]);
  return out;
}

}  // namespace nmbake
