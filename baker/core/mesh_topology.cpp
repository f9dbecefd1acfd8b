#include "core/mesh_topology.h"

#include "core/normals.h"
#include "core/parallel.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <utility>

namespace nmbake {

namespace {

// A position's coordinates as bits, -0 made +0: equal keys are one vertex.
struct PosKey {
  std::uint32_t bits[3];
  std::uint32_t id;  // in the weld table: 1 + the vertex id, 0 for an empty slot
};

PosKey key_of(const glm::vec3& p) {
  PosKey k{};
  for (int c = 0; c < 3; ++c) {
    const float v = p[c] + 0.0f;  // -0 -> +0
    std::memcpy(&k.bits[c], &v, sizeof v);
  }
  return k;
}

// A multiplicative mix of the key.
std::uint64_t hash_of(const PosKey& k) {
  std::uint64_t h = ((std::uint64_t(k.bits[0]) << 32) | k.bits[1]) * 0x9E3779B97F4A7C15ull;
  h ^= k.bits[2] * 0xC2B2AE3D27D4EB4Full;
  return (h ^ (h >> 29)) * 0xBF58476D1CE4E5B9ull;
}

// Its top bits: a table index of `shift` = 64 - log2(table size).
std::size_t slot_of(const PosKey& k, unsigned shift) { return std::size_t(hash_of(k) >> shift); }

// Everything the checks and the normals share: welded corners, duplicate faces, and the faces to
// turn so that every piece has one winding.
struct Analysis {
  std::vector<std::uint32_t> weld;    // per position
  std::vector<std::uint32_t> corner;  // per corner: welded vertex
  std::vector<std::uint8_t> skip;     // per triangle: duplicate or collapsed (two corners welded)
  std::vector<std::uint8_t> flip;     // per triangle: wound against its piece's majority
  MeshTopology topo;
};

// Faces linked across manifold edges, in the order of the edges' (smaller, larger vertex) keys: at
// most one link per edge of a face, so 3 slots per face.
struct Adjacency {
  std::vector<std::uint32_t> face;  // 3 per triangle, `count` of them used: face << 1 | same
  std::vector<std::uint8_t> count;  // per triangle

  // `same`: the two faces run the edge the same way (one of them is wound against the other).
  void link(std::uint32_t f, std::uint32_t g, std::uint32_t same) { face[3 * std::size_t(f) + count[f]++] = g << 1 | same; }
};

// Counting sort: counts in start[key + 2] become, by the prefix sum, the bucket starts at
// start[key + 1], which the scatter (start[key + 1]++) leaves as bucket key's range [start[key],
// start[key + 1]). Items scattered in increasing order stay in that order within their bucket.
void prefix_sum(std::vector<std::uint32_t>& start) {
  for (std::size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
}

void sort3(std::uint32_t v[3]) {
  if (v[0] > v[1]) std::swap(v[0], v[1]);
  if (v[1] > v[2]) std::swap(v[1], v[2]);
  if (v[0] > v[1]) std::swap(v[0], v[1]);
}

// Welded vertex ids used by faces, and file vertices no face uses. On `threads` threads: a flag is
// only ever set to 1, a relaxed atomic store (the value does not depend on which thread sets it).
void count_vertices(const Mesh& m, std::size_t ids, Analysis& a, int threads) {
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  const auto mark = [threads](const std::vector<std::uint32_t>& index, std::size_t n) {
    std::vector<std::uint8_t> used(n, 0);
    parallel_chunks(threads, index.size(), kChunk, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) __atomic_store_n(&used[index[i]], std::uint8_t(1), __ATOMIC_RELAXED);
    });
    std::atomic<std::size_t> count{0};
    parallel_chunks(threads, n, kChunk, [&](std::size_t begin, std::size_t end) {
      count += std::size_t(std::count(used.begin() + std::ptrdiff_t(begin), used.begin() + std::ptrdiff_t(end), 1));
    });
    return count.load();
  };
  a.topo.isolated_vertices = m.positions.size() - mark(m.position_index, m.positions.size());
  a.topo.welded_vertices = mark(a.corner, ids);
}

// Per vertex, the faces (not collapsed) it is the smallest or the middle vertex of, in face order:
// the faces with an edge from it to a larger vertex. Collapsed faces (two corners welded) are
// marked skipped: they have no edges and no direction.
struct VertexFaces {
  std::vector<std::uint32_t> start;  // vertex v's faces: face[start[v]] .. face[start[v + 1] - 1]
  std::vector<std::uint32_t> face;
};

// On one thread: a counting sort in face order. (With atomic counts and scatter on two threads it
// took twice as long here: 16M atomic increments cost more than the loop they would share.)
VertexFaces list_faces_by_vertex(std::size_t ids, Analysis& a) {
  const std::size_t tris = a.skip.size();
  VertexFaces vf;
  vf.start.assign(ids + 2, 0);
  for (std::size_t t = 0; t < tris; ++t) {
    std::uint32_t v[3] = {a.corner[3 * t], a.corner[3 * t + 1], a.corner[3 * t + 2]};
    sort3(v);
    if (v[0] == v[1] || v[1] == v[2]) a.skip[t] = 1;
    else ++vf.start[v[0] + 2], ++vf.start[v[1] + 2];
  }
  prefix_sum(vf.start);
  vf.face.resize(vf.start[ids + 1]);
  for (std::size_t t = 0; t < tris; ++t) {
    if (a.skip[t]) continue;
    std::uint32_t v[3] = {a.corner[3 * t], a.corner[3 * t + 1], a.corner[3 * t + 2]};
    sort3(v);
    vf.face[vf.start[v[0] + 1]++] = std::uint32_t(t);
    vf.face[vf.start[v[1] + 1]++] = std::uint32_t(t);
  }
  return vf;
}

// Per face whose smallest vertex is the one visited: (middle << 32 | largest vertex, face).
using FacePairs = std::vector<std::pair<std::uint64_t, std::uint32_t>>;

// Marks the duplicates among `pairs` (in face order): each face whose pair an earlier one has.
// How many.
std::size_t mark_duplicates(FacePairs& pairs, Analysis& a) {
  std::size_t marked = 0;
  auto mark = [&](std::size_t i) {
    a.skip[pairs[i].second] = 1;
    ++marked;
  };
  if (pairs.size() <= 32) {  // a handful of faces: compare each with the earlier ones
    for (std::size_t i = 1; i < pairs.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        if (pairs[j].first == pairs[i].first) {
          mark(i);
          break;
        }
  } else {
    std::sort(pairs.begin(), pairs.end());
    for (std::size_t i = 1; i < pairs.size(); ++i)
      if (pairs[i].first == pairs[i - 1].first) mark(i);
  }
  return marked;
}

// At vertex `b`, given `faces` (in face order) it is the smallest or the middle vertex of: among
// those whose smallest vertex is b, each face whose (middle, largest) pair an earlier one has is
// marked a duplicate (the faces a global sort of (sorted triple, face) finds after the first of
// each run). Only the faces whose smallest vertex is b are read or written, so vertices may be
// visited in any order, on any thread. How many were marked.
std::size_t mark_duplicates_at(std::uint32_t b, const std::uint32_t* faces, std::size_t n, Analysis& a, FacePairs& pairs) {
  pairs.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t t = faces[i];
    std::uint32_t v[3] = {a.corner[3 * std::size_t(t)], a.corner[3 * std::size_t(t) + 1], a.corner[3 * std::size_t(t) + 2]};
    sort3(v);
    if (v[0] != b) continue;
    pairs.emplace_back(std::uint64_t(v[1]) << 32 | v[2], t);
  }
  return pairs.size() >= 2 ? mark_duplicates(pairs, a) : 0;
}

// At vertex `b`, once every duplicate is marked: the edges from b to a larger vertex of its faces
// (`faces`, as above) left, sorted by (larger vertex, face): the order of a global sort of all edges
// by (key, face). Runs of one key are one edge. A half-edge is larger vertex << 32 | face << 1 |
// forward (the face runs from b to the larger vertex); face < 2^31, as the bucket starts count 2
// per face in 32 bits. Faces are distinct within one edge, so sorting by value sorts by (key, face).
void edges_at(std::uint32_t b, const std::uint32_t* faces, std::size_t n, const Analysis& a, std::vector<std::uint64_t>& edges) {
  edges.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t t = faces[i];
    if (a.skip[t]) continue;
    const std::uint32_t* c = &a.corner[3 * std::size_t(t)];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t p = c[k], q = c[k == 2 ? 0 : k + 1];
      if (std::min(p, q) == b) edges.push_back((std::uint64_t(std::max(p, q)) << 32) | (std::uint64_t(t) << 1) | (p < q));
    }
  }
  if (edges.size() <= 16) {  // insertion sort: a vertex has a handful of edges
    for (std::size_t i = 1; i < edges.size(); ++i) {
      const std::uint64_t e = edges[i];
      std::size_t j = i;
      for (; j > 0 && edges[j - 1] > e; --j) edges[j] = edges[j - 1];
      edges[j] = e;
    }
  } else {
    std::sort(edges.begin(), edges.end());
  }
}

// fn(first, count) for each run of one edge in `edges` (sorted by edges_at).
template <typename Fn>
void for_each_edge(const std::vector<std::uint64_t>& edges, Fn&& fn) {
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && (edges[j] >> 32) == (edges[i] >> 32)) ++j;
    fn(i, j - i);
    i = j;
  }
}

// Whether the two half-edges run the edge the same way (one face is wound against the other).
std::uint32_t same_way(std::uint64_t e, std::uint64_t f) { return (e & 1) == (f & 1); }

// Counted on every core, vertex by vertex: first the duplicates (at each face's smallest vertex),
// then the edges of the faces left (boundary, non-manifold, and manifold edges whose two faces run
// it the same way). Returns the last: only when there are some does a piece need turning.
std::size_t count_edges(const VertexFaces& vf, std::size_t ids, Analysis& a, int threads) {
  constexpr std::size_t kVertices = 4096;  // per chunk
  std::atomic<std::size_t> duplicates{0}, boundary{0}, non_manifold{0}, same{0};
  parallel_chunks(threads, ids, kVertices, [&](std::size_t begin, std::size_t end) {
    FacePairs pairs;
    std::size_t found = 0;
    for (std::size_t b = begin; b < end; ++b)
      found += mark_duplicates_at(std::uint32_t(b), vf.face.data() + vf.start[b], vf.start[b + 1] - vf.start[b], a, pairs);
    duplicates += found;
  });
  parallel_chunks(threads, ids, kVertices, [&](std::size_t begin, std::size_t end) {
    std::vector<std::uint64_t> edges;
    std::size_t counts[3] = {0, 0, 0};  // boundary, non-manifold, same way
    for (std::size_t b = begin; b < end; ++b) {
      edges_at(std::uint32_t(b), vf.face.data() + vf.start[b], vf.start[b + 1] - vf.start[b], a, edges);
      for_each_edge(edges, [&](std::size_t i, std::size_t n) {
        if (n == 1) ++counts[0];
        else if (n > 2) ++counts[1];
        else counts[2] += same_way(edges[i], edges[i + 1]);
      });
    }
    boundary += counts[0];
    non_manifold += counts[1];
    same += counts[2];
  });
  a.topo.duplicate_faces = duplicates;
  a.topo.boundary_edges = boundary;
  a.topo.non_manifold_edges = non_manifold;
  return same;
}

// Faces linked across manifold edges, vertex by vertex in increasing order (the duplicates marked).
Adjacency link_faces(const VertexFaces& vf, std::size_t ids, const Analysis& a) {
  const std::size_t tris = a.skip.size();
  Adjacency adj;
  adj.face.resize(3 * tris);
  adj.count.assign(tris, 0);
  std::vector<std::uint64_t> edges;
  for (std::size_t b = 0; b < ids; ++b) {
    edges_at(std::uint32_t(b), vf.face.data() + vf.start[b], vf.start[b + 1] - vf.start[b], a, edges);
    for_each_edge(edges, [&](std::size_t i, std::size_t n) {
      if (n != 2) return;
      const std::uint32_t f = std::uint32_t(edges[i]) >> 1, g = std::uint32_t(edges[i + 1]) >> 1;
      adj.link(f, g, same_way(edges[i], edges[i + 1]));
      adj.link(g, f, same_way(edges[i], edges[i + 1]));
    });
  }
  return adj;
}

// Per piece: breadth-first, each face's winding relative to the seed; the minority is flipped.
void orient_pieces(const Adjacency& adj, Analysis& a) {
  const std::size_t tris = a.skip.size();
  a.flip.assign(tris, 0);
  std::vector<std::int8_t> rel(tris, -1);
  std::vector<std::uint32_t> queue;
  queue.reserve(tris);
  for (std::size_t seed = 0; seed < tris; ++seed) {
    if (a.skip[seed] || rel[seed] >= 0) continue;
    // The queue, once drained, holds the piece.
    queue.assign(1, std::uint32_t(seed));
    rel[seed] = 0;
    std::size_t ones = 0;
    for (std::size_t qi = 0; qi < queue.size(); ++qi) {
      // Faces leave the queue in an order far from their numbers: fetch a later one's links now.
      constexpr std::size_t kAhead = 16;
      if (qi + kAhead < queue.size()) __builtin_prefetch(&adj.face[3 * std::size_t(queue[qi + kAhead])]);
      const std::uint32_t f = queue[qi];
      ones += std::size_t(rel[f]);
      for (std::size_t k = 3 * std::size_t(f); k < 3 * std::size_t(f) + adj.count[f]; ++k) {
        const std::uint32_t g = adj.face[k] >> 1;
        if (rel[g] >= 0) continue;  // a conflict (non-orientable piece) keeps the first assignment
        rel[g] = std::int8_t(rel[f] ^ std::int8_t(adj.face[k] & 1));
        queue.push_back(g);
      }
    }
    // Ties keep the seed's (lowest face number's) winding.
    const std::int8_t minority = ones * 2 > queue.size() ? 0 : 1;
    for (std::uint32_t f : queue)
      if (rel[f] == minority) {
        a.flip[f] = 1;
        ++a.topo.inconsistent_winding_faces;
      }
  }
}

Analysis analyze(const Mesh& m, int threads) {
  Analysis a;
  const std::size_t tris = m.triangle_count();
  std::size_t ids = 0;
  a.weld = weld_positions(m.positions, &ids, threads);
  a.corner.resize(3 * tris);
  parallel_chunks(threads, 3 * tris, std::size_t(1) << 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) a.corner[c] = a.weld[m.position_index[c]];
  });
  count_vertices(m, ids, a, threads);
  a.skip.assign(tris, 0);
  const VertexFaces vf = list_faces_by_vertex(ids, a);
  // With every manifold edge run opposite ways by its two faces, each piece is wound one way: no
  // face to turn, and no need for the links (the common case, and the slower half of the work).
  if (count_edges(vf, ids, a, threads) > 0) orient_pieces(link_faces(vf, ids, a), a);
  else a.flip.assign(tris, 0);
  return a;
}

}  // namespace

namespace {

// Open addressing with linear probing over a table at most half full, for `items` keys.
class KeyTable {
 public:
  explicit KeyTable(std::size_t items = 0) { start(items); }
  void start(std::size_t items) {
    shift_ = 64 - 4;
    while ((std::size_t(1) << (64 - shift_)) < 2 * items) --shift_;
    mask_ = (std::size_t(1) << (64 - shift_)) - 1;
    slots_.assign(mask_ + 1, PosKey{});
  }
  void prefetch(const PosKey& k) const { __builtin_prefetch(&slots_[slot_of(k, shift_)]); }
  // The entry with k's bits, or the empty one (id 0) where k goes.
  PosKey& find(const PosKey& k) {
    for (std::size_t s = slot_of(k, shift_);; s = (s + 1) & mask_) {
      PosKey& e = slots_[s];
      if (e.id == 0 || (e.bits[0] == k.bits[0] && e.bits[1] == k.bits[1] && e.bits[2] == k.bits[2])) return e;
    }
  }

 private:
  unsigned shift_ = 0;
  std::size_t mask_ = 0;
  std::vector<PosKey> slots_;
};

// On one thread: one table, the positions in order.
std::vector<std::uint32_t> weld_serial(const std::vector<glm::vec3>& positions, std::size_t* count) {
  KeyTable table(positions.size());
  std::vector<std::uint32_t> out(positions.size());
  std::uint32_t ids = 0;
  for (std::size_t i = 0; i < positions.size(); ++i) {
    // The table is larger than the caches: its slot for a position some steps ahead is fetched now.
    constexpr std::size_t kAhead = 8;
    if (i + kAhead < positions.size()) table.prefetch(key_of(positions[i + kAhead]));
    const PosKey k = key_of(positions[i]);
    PosKey& e = table.find(k);
    if (e.id == 0) {
      e = k;
      e.id = ++ids;
    }
    out[i] = e.id - 1;
  }
  if (count) *count = ids;
  return out;
}

}  // namespace

// Ids in order of first occurrence. On every core: the positions' keys are dealt into kParts parts
// by their hash (each part in position order), each part finds every position's first occurrence
// in an open-addressing table of its own (linear probing, at most half full, small enough for the
// caches), and the first occurrences are numbered in position order. The ids do not depend on the
// threads.
std::vector<std::uint32_t> weld_positions(const std::vector<glm::vec3>& positions, std::size_t* count, int threads) {
  const std::size_t n = positions.size();
  constexpr std::size_t kChunk = std::size_t(1) << 16;  // positions
  constexpr std::size_t kParts = 256;
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  // One thread's table of all positions is faster than the parts' three passes (the same ids).
  if (std::min(worker_threads(threads), int(chunks)) <= 1) return weld_serial(positions, count);
  const auto chunk_end = [&](std::size_t c) { return std::min(n, (c + 1) * kChunk); };
  // The low bits of the hash: a part's table indexes by the top ones.
  const auto part_of = [](const PosKey& k) { return std::size_t(hash_of(k) & (kParts - 1)); };
  // Per chunk, how many of its positions go to each part; then where they go (part by part, chunk
  // by chunk within a part, so each part's list is in position order).
  std::vector<std::uint32_t> at(chunks * kParts, 0);
  parallel_chunks(threads, chunks, 1, [&](std::size_t c0, std::size_t c1) {
    for (std::size_t c = c0; c < c1; ++c)
      for (std::size_t i = c * kChunk; i < chunk_end(c); ++i) ++at[c * kParts + part_of(key_of(positions[i]))];
  });
  std::vector<std::size_t> part_start(kParts + 1, 0);
  std::uint32_t next = 0;
  for (std::size_t p = 0; p < kParts; ++p) {
    part_start[p] = next;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::uint32_t k = at[c * kParts + p];
      at[c * kParts + p] = next;
      next += k;
    }
  }
  part_start[kParts] = next;
  std::vector<PosKey> listed(n);  // the keys part by part, each with its position (in `id`)
  parallel_chunks(threads, chunks, 1, [&](std::size_t c0, std::size_t c1) {
    for (std::size_t c = c0; c < c1; ++c)
      for (std::size_t i = c * kChunk; i < chunk_end(c); ++i) {
        PosKey k = key_of(positions[i]);
        k.id = std::uint32_t(i);
        listed[at[c * kParts + part_of(k)]++] = k;
      }
  });
  // Per position, the first with its key (in `out` for now), and which are firsts.
  std::vector<std::uint32_t> out(n);
  std::vector<std::uint8_t> is_first(n);
  parallel_chunks(threads, kParts, 1, [&](std::size_t p0, std::size_t p1) {
    KeyTable table;  // id: 1 + the position
    for (std::size_t p = p0; p < p1; ++p) {
      table.start(part_start[p + 1] - part_start[p]);
      for (std::size_t k = part_start[p]; k < part_start[p + 1]; ++k) {
        const PosKey& key = listed[k];
        PosKey& e = table.find(key);
        if (e.id == 0) {
          e = key;
          e.id = key.id + 1;
        }
        out[key.id] = e.id - 1;
        is_first[key.id] = e.id - 1 == key.id;
      }
    }
  });
  // The firsts numbered in position order, then every other position takes its first's number.
  std::vector<std::uint32_t> firsts_before(chunks + 1, 0);
  parallel_chunks(threads, chunks, 1, [&](std::size_t c0, std::size_t c1) {
    for (std::size_t c = c0; c < c1; ++c)
      for (std::size_t i = c * kChunk; i < chunk_end(c); ++i) firsts_before[c + 1] += is_first[i];
  });
  for (std::size_t c = 0; c < chunks; ++c) firsts_before[c + 1] += firsts_before[c];
  parallel_chunks(threads, chunks, 1, [&](std::size_t c0, std::size_t c1) {
    for (std::size_t c = c0; c < c1; ++c) {
      std::uint32_t id = firsts_before[c];
      for (std::size_t i = c * kChunk; i < chunk_end(c); ++i)
        if (is_first[i]) out[i] = id++;
    }
  });
  parallel_chunks(threads, n, kChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      if (!is_first[i]) out[i] = out[out[i]];
  });
  if (count) *count = firsts_before[chunks];
  return out;
}

MeshTopology inspect_topology(const Mesh& mesh, int threads) { return analyze(mesh, threads).topo; }

void compute_high_corner_normals(const Mesh& m, glm::vec3* out, MeshTopology* topology, int threads) {
  const Analysis a = analyze(m, threads);
  if (topology) *topology = a.topo;
  // Indexed by welded id (< positions).
  const std::vector<glm::dvec3> sum = angle_weighted_sums(m, &a.corner, m.positions.size(), &a.skip, &a.flip, threads);
  parallel_chunks(threads, 3 * m.triangle_count(), std::size_t(1) << 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) out[c] = unit_or_up(sum[a.corner[c]]);
  });
}

std::vector<glm::vec3> compute_high_corner_normals(const Mesh& m, std::size_t* reoriented, int threads) {
  std::vector<glm::vec3> out(3 * m.triangle_count());
  MeshTopology topology;
  compute_high_corner_normals(m, out.data(), &topology, threads);
  if (reoriented) *reoriented = topology.inconsistent_winding_faces;
  return out;
}

}  // namespace nmbake
