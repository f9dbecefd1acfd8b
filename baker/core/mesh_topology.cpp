#include "core/mesh_topology.h"

#include "core/image.h"
#include "core/normals.h"
#include "core/parallel.h"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <mutex>
#include <utility>

namespace nmbake {

namespace {

// A position's coordinates as bits, -0 made +0: equal keys are one vertex.
struct PosKey {
  std::uint32_t bits[3];
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

// Arrays each written whole by a loop on every thread before they are read: not zeroed first (on
// one thread, which the first touch of their pages would also be).
template <typename T>
using Unset = std::vector<T, DefaultInitAllocator<T>>;

// weld_positions into `out`.
void weld_into(const std::vector<glm::vec3>& positions, Unset<std::uint32_t>& out, std::size_t* count, int threads);

// Everything the checks and the normals share: welded corners, duplicate faces, and the faces to
// turn so that every piece has one winding.
struct Analysis {
  Unset<std::uint32_t> weld;    // per position
  Unset<std::uint32_t> corner;  // per corner: welded vertex
  Unset<std::uint8_t> skip;     // per triangle: duplicate or collapsed (two corners welded)
  Unset<std::uint8_t> flip;     // per triangle: wound against its piece's majority
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

void sort3(std::uint32_t v[3]) {
  if (v[0] > v[1]) std::swap(v[0], v[1]);
  if (v[1] > v[2]) std::swap(v[1], v[2]);
  if (v[0] > v[1]) std::swap(v[0], v[1]);
}

// Welded vertex ids used by faces, and file vertices no face uses, on `threads` threads.
void count_vertices(const Mesh& m, std::size_t ids, Analysis& a, int threads) {
  constexpr std::size_t kChunk = std::size_t(1) << 16;
  const auto mark = [threads](const auto& index, std::size_t n) {
    Unset<std::uint8_t> used(n);
    mark_on_threads(threads, index, used);
    std::atomic<std::size_t> count{0};
    parallel_chunks(threads, n, kChunk, [&](std::size_t begin, std::size_t end) {
      count += std::size_t(std::count(used.begin() + std::ptrdiff_t(begin), used.begin() + std::ptrdiff_t(end), 1));
    });
    return count.load();
  };
  a.topo.isolated_vertices = m.positions.size() - mark(m.position_index, m.positions.size());
  a.topo.welded_vertices = mark(a.corner, ids);
}

// Per vertex, the edges from it to a larger vertex of the faces not collapsed (two corners welded:
// no edges, no direction; marked skipped): half-edges, larger vertex << 32 | face << 1 | forward
// (the face runs from the vertex to the larger one; face < 2^31), in face order, and of one face
// in corner order. A face has two at its smallest vertex and one at its middle one.
struct VertexEdges {
  Unset<std::size_t> start;  // vertex v's: edge[start[v]] .. edge[start[v + 1] - 1]
  Unset<std::uint64_t> edge;
};

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

// At vertex b, its half-edges `e` (n of them, as VertexEdges keeps them): the faces whose smallest
// vertex b is, the two half-edges in a row of one face, each with its (middle, largest) pair; each
// whose pair an earlier face has is marked a duplicate (the faces a global sort of (sorted triple,
// face) finds after the first of each run). Only those faces are written, so vertices may be
// visited in any order, on any thread. How many were marked.
std::size_t mark_duplicates_at(const std::uint64_t* e, std::size_t n, Analysis& a, FacePairs& pairs) {
  pairs.clear();
  for (std::size_t i = 0; i + 1 < n; ++i)
    if (std::uint32_t(e[i]) >> 1 == std::uint32_t(e[i + 1]) >> 1) {
      const std::uint64_t x = e[i] >> 32, y = e[i + 1] >> 32;
      pairs.emplace_back(std::min(x, y) << 32 | std::max(x, y), std::uint32_t(e[i]) >> 1);
      ++i;
    }
  return pairs.size() >= 2 ? mark_duplicates(pairs, a) : 0;
}

// At a vertex, its half-edges `e` (n of them) of the faces left (all of them when `skip` is null),
// sorted by (larger vertex, face): the order of a global sort of all edges by (key, face). Runs of
// one key are one edge. Faces are distinct within one edge, so sorting by value sorts by (key, face).
void edges_at(const std::uint64_t* e, std::size_t n, const std::uint8_t* skip, std::vector<std::uint64_t>& edges) {
  edges.clear();
  for (std::size_t i = 0; i < n; ++i)
    if (!skip || !skip[std::uint32_t(e[i]) >> 1]) edges.push_back(e[i]);
  if (edges.size() <= 16) {  // insertion sort: a vertex has a handful of edges
    for (std::size_t i = 1; i < edges.size(); ++i) {
      const std::uint64_t x = edges[i];
      std::size_t j = i;
      for (; j > 0 && edges[j - 1] > x; --j) edges[j] = edges[j - 1];
      edges[j] = x;
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
std::uint32_t same_way_of(std::uint64_t e, std::uint64_t f) { return (e & 1) == (f & 1); }

// Edges by how many faces use them, and how many manifold ones their two faces run the same way.
struct EdgeCounts {
  std::size_t boundary = 0, non_manifold = 0, same_way = 0;
  void add(const std::vector<std::uint64_t>& edges) {
    for_each_edge(edges, [&](std::size_t i, std::size_t n) {
      if (n == 1) ++boundary;
      else if (n > 2) ++non_manifold;
      else same_way += same_way_of(edges[i], edges[i + 1]);
    });
  }
  void add(const EdgeCounts& o) { boundary += o.boundary, non_manifold += o.non_manifold, same_way += o.same_way; }
};

// The half-edges of the faces not collapsed, bucketed by their smaller vertex, on every thread.
// The vertices are cut into parts of 2^shift consecutive ids (at most 2^16, so that a half-edge's
// vertex within its part fits 16 bits). Faces go in chunks: per chunk, how many half-edges it
// sends to each part; then each chunk lists its half-edges in their parts' lists (part by part,
// chunk by chunk within a part: each list in face order); then each part sorts its own list by
// vertex (a counting sort, which keeps face order) and finds its vertices' duplicate faces. Parts
// are ranges of ids, so their lists follow one another in `edge` as one counting sort of all the
// half-edges would lay them out: the same arrays, whatever the threads. Returns the duplicates
// marked. Each part also counts its vertices' edges as if no face were a duplicate, into
// `if_no_duplicates`: the counts when none is (the common case), without a pass of their own.
std::size_t list_edges_by_vertex(std::size_t ids, Analysis& a, int threads, VertexEdges& ve, EdgeCounts& if_no_duplicates) {
  const std::size_t tris = a.skip.size();
  constexpr std::size_t kChunk = std::size_t(1) << 16;  // faces
  unsigned shift = 0;
  while ((ids >> shift) > 256 && shift < 16) ++shift;
  const std::size_t parts = (ids >> shift) + 1, chunks = (tris + kChunk - 1) / kChunk;
  const auto chunk_end = [&](std::size_t c) { return std::min(tris, (c + 1) * kChunk); };
  std::vector<std::size_t> at(chunks * parts, 0);
  parallel_chunks(threads, chunks, 1, [&](std::size_t c, std::size_t) {
    std::size_t* count = &at[c * parts];
    for (std::size_t t = c * kChunk; t < chunk_end(c); ++t) {
      std::uint32_t v[3] = {a.corner[3 * t], a.corner[3 * t + 1], a.corner[3 * t + 2]};
      sort3(v);
      a.skip[t] = v[0] == v[1] || v[1] == v[2];
      if (!a.skip[t]) count[v[0] >> shift] += 2, ++count[v[1] >> shift];
    }
  });
  std::vector<std::size_t> part_start(parts + 1, 0);
  std::size_t next = 0;
  for (std::size_t p = 0; p < parts; ++p) {
    part_start[p] = next;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::size_t k = at[c * parts + p];
      at[c * parts + p] = next;
      next += k;
    }
  }
  part_start[parts] = next;
  ve.edge.resize(next);
  Unset<std::uint16_t> within(next);  // per listed half-edge: its smaller vertex within its part
  parallel_chunks(threads, chunks, 1, [&](std::size_t c, std::size_t) {
    std::size_t* to = &at[c * parts];
    for (std::size_t t = c * kChunk; t < chunk_end(c); ++t) {
      if (a.skip[t]) continue;
      const std::uint32_t* v = &a.corner[3 * t];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t p = v[k], q = v[k == 2 ? 0 : k + 1], lo = std::min(p, q);
        const std::size_t i = to[lo >> shift]++;
        ve.edge[i] = std::uint64_t(std::max(p, q)) << 32 | std::uint64_t(t) << 1 | (p < q);
        within[i] = std::uint16_t(lo & ((1u << shift) - 1));
      }
    }
  });
  ve.start.resize(ids + 1);
  ve.start[ids] = next;
  std::atomic<std::size_t> duplicates{0};
  std::atomic<std::size_t> next_part{0};
  std::mutex counted;
  // Parts shared out as parallel_chunks does, each thread's buffers kept from part to part (a
  // buffer freed and made again takes fresh pages from the system each time).
  run_on_threads(worker_threads(threads), [&](int) {
    std::vector<std::size_t> place;
    Unset<std::uint64_t> sorted;
    FacePairs pairs;
    std::vector<std::uint64_t> edges;
    EdgeCounts counts;
    std::size_t found = 0;
    for (std::size_t p; (p = next_part++) < parts;) {
      const std::size_t v0 = std::min(ids, p << shift), v1 = std::min(ids, (p + 1) << shift);
      const std::size_t first = part_start[p], n = part_start[p + 1] - first;
      // Counts (vertex v's at v - v0 + 1), then where each vertex's half-edges go (at v - v0).
      place.assign(v1 - v0 + 1, 0);
      for (std::size_t k = first; k < first + n; ++k) ++place[within[k] + 1];
      for (std::size_t v = v0, sum = 0; v < v1; ++v) {
        const std::size_t count = place[v - v0 + 1];
        ve.start[v] = first + sum;
        place[v - v0] = sum;
        sum += count;
      }
      sorted.resize(n);
      for (std::size_t k = first; k < first + n; ++k) sorted[place[within[k]]++] = ve.edge[k];
      std::copy(sorted.begin(), sorted.begin() + std::ptrdiff_t(n), ve.edge.begin() + std::ptrdiff_t(first));
      // (The next part's first start may not be written yet: each vertex's end is where its
      // scatter left place[v - v0].)
      for (std::size_t v = v0, from = 0; v < v1; from = place[v - v0], ++v) {
        const std::uint64_t* e = ve.edge.data() + first + from;
        found += mark_duplicates_at(e, place[v - v0] - from, a, pairs);
        edges_at(e, place[v - v0] - from, nullptr, edges);
        counts.add(edges);
      }
    }
    duplicates += found;
    const std::lock_guard<std::mutex> lock(counted);
    if_no_duplicates.add(counts);
  });
  return duplicates;
}

// Counted on every core, vertex by vertex, once the duplicates are marked: the edges of the faces
// left.
EdgeCounts count_edges(const VertexEdges& ve, std::size_t ids, const Analysis& a, int threads) {
  constexpr std::size_t kVertices = 4096;  // per chunk
  EdgeCounts all;
  std::mutex counted;
  parallel_chunks(threads, ids, kVertices, [&](std::size_t begin, std::size_t end) {
    std::vector<std::uint64_t> edges;
    EdgeCounts counts;
    for (std::size_t b = begin; b < end; ++b) {
      edges_at(ve.edge.data() + ve.start[b], ve.start[b + 1] - ve.start[b], a.skip.data(), edges);
      counts.add(edges);
    }
    const std::lock_guard<std::mutex> lock(counted);
    all.add(counts);
  });
  return all;
}

// Faces linked across manifold edges, vertex by vertex in increasing order (the duplicates marked).
Adjacency link_faces(const VertexEdges& ve, std::size_t ids, const Analysis& a) {
  const std::size_t tris = a.skip.size();
  Adjacency adj;
  adj.face.resize(3 * tris);
  adj.count.assign(tris, 0);
  std::vector<std::uint64_t> edges;
  for (std::size_t b = 0; b < ids; ++b) {
    edges_at(ve.edge.data() + ve.start[b], ve.start[b + 1] - ve.start[b], a.skip.data(), edges);
    for_each_edge(edges, [&](std::size_t i, std::size_t n) {
      if (n != 2) return;
      const std::uint32_t f = std::uint32_t(edges[i]) >> 1, g = std::uint32_t(edges[i + 1]) >> 1;
      adj.link(f, g, same_way_of(edges[i], edges[i + 1]));
      adj.link(g, f, same_way_of(edges[i], edges[i + 1]));
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
  weld_into(m.positions, a.weld, &ids, threads);
  a.corner.resize(3 * tris);  // written whole by the loop below
  parallel_chunks(threads, 3 * tris, std::size_t(1) << 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) a.corner[c] = a.weld[m.position_index[c]];
  });
  count_vertices(m, ids, a, threads);
  a.skip.resize(tris);  // written whole by list_edges_by_vertex
  VertexEdges ve;
  EdgeCounts counts;
  a.topo.duplicate_faces = list_edges_by_vertex(ids, a, threads, ve, counts);
  if (a.topo.duplicate_faces > 0) counts = count_edges(ve, ids, a, threads);  // again, without the duplicates
  a.topo.boundary_edges = counts.boundary;
  a.topo.non_manifold_edges = counts.non_manifold;
  // With every manifold edge run opposite ways by its two faces, each piece is wound one way: no
  // face to turn, and no need for the links (the common case, and the slower half of the work).
  if (counts.same_way > 0) orient_pieces(link_faces(ve, ids, a), a);
  else {
    a.flip.resize(tris);
    fill_on_threads(threads, a.flip, std::uint8_t(0));
  }
  return a;
}

// Ids in order of first occurrence, on every core. One open-addressing table (linear probing, at
// most half full) shared by the threads: a slot holds 32 bits of a key's hash and 1 + the first
// position with that key, claimed and lowered by compare-and-swap, so whatever the order the
// threads come in, each key's slot ends with its first position. Each position notes the first it
// saw; a first that a smaller one displaced later is marked stale, and the positions that saw it
// look again (rare: a key met by two threads at once). Then the firsts are numbered in position
// order and every other position takes its first's number. The ids do not depend on the threads.
void weld_into(const std::vector<glm::vec3>& positions, Unset<std::uint32_t>& out, std::size_t* count, int threads) {
  const std::size_t n = positions.size();
  constexpr std::size_t kChunk = std::size_t(1) << 16;  // positions
  const std::size_t chunks = (n + kChunk - 1) / kChunk;
  const auto chunk_end = [&](std::size_t c) { return std::min(n, (c + 1) * kChunk); };
  unsigned bits = 4;
  while ((std::size_t(1) << bits) < 2 * n) ++bits;
  const std::size_t mask = (std::size_t(1) << bits) - 1;
  Unset<std::uint64_t> table(mask + 1);  // (32 bits of the hash) << 32 | 1 + position; 0: empty
  fill_on_threads(threads, table, std::uint64_t(0));
  Unset<std::uint8_t> stale(n);
  fill_on_threads(threads, stale, std::uint8_t(0));
  const auto same_key = [&](const PosKey& k, std::uint64_t entry) {
    const PosKey e = key_of(positions[std::uint32_t(entry) - 1]);
    return e.bits[0] == k.bits[0] && e.bits[1] == k.bits[1] && e.bits[2] == k.bits[2];
  };
  // The slot of key k (hash h): its own, or the empty one where it goes.
  const auto slot_for = [&](const PosKey& k, std::uint64_t h) {
    for (std::size_t s = std::size_t(h >> (64 - bits));; s = (s + 1) & mask) {
      const std::uint64_t e = __atomic_load_n(&table[s], __ATOMIC_RELAXED);
      if (e == 0 || ((e >> 32) == (h & 0xffffffffu) && same_key(k, e))) return s;
    }
  };
  out.resize(n);  // per position: the first with its key (as it saw it, then final)
  parallel_chunks(threads, chunks, 1, [&](std::size_t c, std::size_t) {
    for (std::size_t i = c * kChunk; i < chunk_end(c); ++i) {
      // The table is larger than the caches: its slot for a position some steps ahead is fetched now.
      constexpr std::size_t kAhead = 16;
      if (i + kAhead < chunk_end(c))
        __builtin_prefetch(&table[std::size_t(hash_of(key_of(positions[i + kAhead])) >> (64 - bits))]);
      const PosKey k = key_of(positions[i]);
      const std::uint64_t h = hash_of(k), mine = (h & 0xffffffffu) << 32 | (i + 1);
      std::size_t s = std::size_t(h >> (64 - bits));
      std::uint64_t e;
      while (true) {
        e = __atomic_load_n(&table[s], __ATOMIC_RELAXED);
        if (e == 0) {  // claim it, unless another thread just did (then e is what it put there)
          if (__atomic_compare_exchange_n(&table[s], &e, mine, false, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
            e = mine;
            break;
          }
        }
        if ((e >> 32) == (h & 0xffffffffu) && same_key(k, e)) break;
        s = (s + 1) & mask;  // another key's
      }
      // The key's slot. Held by a later position (another thread's): take its place.
      for (std::uint64_t seen = e; std::uint32_t(e) - 1 > i; seen = e)
        if (__atomic_compare_exchange_n(&table[s], &e, mine, false, __ATOMIC_RELAXED, __ATOMIC_RELAXED)) {
          __atomic_store_n(&stale[std::uint32_t(seen) - 1], std::uint8_t(1), __ATOMIC_RELAXED);
          e = mine;
        }
      out[i] = std::uint32_t(e) - 1;
    }
  });
  // The firsts that were displaced are looked up again; then, per chunk, the firsts counted.
  std::vector<std::uint32_t> firsts_before(chunks + 1, 0);
  parallel_chunks(threads, chunks, 1, [&](std::size_t c, std::size_t) {
    std::uint32_t firsts = 0;
    for (std::size_t i = c * kChunk; i < chunk_end(c); ++i) {
      if (stale[out[i]]) {
        const PosKey k = key_of(positions[i]);
        out[i] = std::uint32_t(table[slot_for(k, hash_of(k))]) - 1;
      }
      firsts += out[i] == i;
    }
    firsts_before[c + 1] = firsts;
  });
  for (std::size_t c = 0; c < chunks; ++c) firsts_before[c + 1] += firsts_before[c];
  // The firsts numbered in position order (in `stale`'s place, their marks done with: 1 = first),
  // then every other position takes its first's number.
  parallel_chunks(threads, chunks, 1, [&](std::size_t c, std::size_t) {
    std::uint32_t id = firsts_before[c];
    for (std::size_t i = c * kChunk; i < chunk_end(c); ++i) {
      stale[i] = out[i] == i;
      if (stale[i]) out[i] = id++;
    }
  });
  parallel_chunks(threads, n, kChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      if (!stale[i]) out[i] = out[out[i]];
  });
  if (count) *count = firsts_before[chunks];
}

}  // namespace

std::vector<std::uint32_t> weld_positions(const std::vector<glm::vec3>& positions, std::size_t* count, int threads) {
  Unset<std::uint32_t> ids;
  weld_into(positions, ids, count, threads);
  return std::vector<std::uint32_t>(ids.begin(), ids.end());
}

MeshTopology inspect_topology(const Mesh& mesh, int threads) { return analyze(mesh, threads).topo; }

void compute_high_corner_normals(const Mesh& m, glm::vec3* out, MeshTopology* topology, int threads) {
  const Analysis a = analyze(m, threads);
  if (topology) *topology = a.topo;
  // Indexed by welded id (< positions).
  const std::vector<glm::dvec3> sum =
      angle_weighted_sums(m, a.corner.data(), m.positions.size(), a.skip.data(), a.flip.data(), threads);
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
