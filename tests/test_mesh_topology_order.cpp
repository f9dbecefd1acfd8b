// mesh_topology's exact answers: welded ids in order of first occurrence, the earliest of duplicate
// faces kept, and the faces turned in a non-orientable piece, which follow the order of the
// breadth-first walk (faces linked in the order of their edges' (smaller, larger vertex) keys).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/mesh_topology.h"
#include "core/normals.h"
#include "core/parallel.h"
#include "core/parallel.h"

using namespace nmbake;

namespace {

Mesh make_mesh(std::vector<glm::vec3> positions, std::vector<std::uint32_t> index) {
  Mesh m;
  m.positions = std::move(positions);
  m.position_index = std::move(index);
  return m;
}

// A Klein bottle as an nu x nv grid of quads (2 triangles each) on the figure-8 immersion: across
// the seam i = nu - 1 -> 0 the j direction is reversed. Vertex (i, j) is renumbered
// ((i * nv + j) * 7) % V and triangle t moved to (t * 5) % T (permutations for V and T = 2V prime to
// 7 and 5), so that numbers do not follow the grid.
Mesh make_shuffled_klein_bottle(int nu, int nv) {
  const std::size_t V = std::size_t(nu * nv), T = 2 * V;
  const float pi = 3.14159265f;
  std::vector<glm::vec3> positions(V);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const float u = 2 * pi * float(i) / float(nu), v = 2 * pi * float(j) / float(nv) + 0.3f;
      const float r = 3 + std::cos(u / 2) * std::sin(v) - std::sin(u / 2) * std::sin(2 * v);
      positions[(std::size_t(i * nv + j) * 7) % V] = {r * std::cos(u), r * std::sin(u),
                                                      std::sin(u / 2) * std::sin(v) + std::cos(u / 2) * std::sin(2 * v)};
    }
  auto id = [&](int i, int j) {
    if (i == nu) i = 0, j = nv - j;
    return std::uint32_t((std::size_t(i * nv + (j % nv + nv) % nv) * 7) % V);
  };
  std::vector<std::uint32_t> index(3 * T);
  std::size_t t = 0;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const std::uint32_t quad[2][3] = {{id(i, j), id(i + 1, j), id(i + 1, j + 1)}, {id(i, j), id(i + 1, j + 1), id(i, j + 1)}};
      for (const auto& tri : quad) {
        for (int k = 0; k < 3; ++k) index[3 * ((t * 5) % T) + std::size_t(k)] = tri[k];
        ++t;
      }
    }
  return make_mesh(std::move(positions), std::move(index));
}

// Every count of `t`: welded, isolated, duplicate faces, boundary, non-manifold, inconsistent winding.
void expect_counts(const MeshTopology& t, const std::array<std::size_t, 6>& want) {
  const std::array<std::size_t, 6> got = {t.welded_vertices, t.isolated_vertices,  t.duplicate_faces,
                                          t.boundary_edges,  t.non_manifold_edges, t.inconsistent_winding_faces};
  for (std::size_t k = 0; k < 6; ++k) EXPECT_EQ(got[k], want[k]) << "count " << k;
}

}  // namespace

TEST(MeshTopology, WeldIdsFollowFirstOccurrenceAndSignedZerosMeet) {
  std::size_t count = 0;
  const std::vector<std::uint32_t> ids =
      weld_positions({{1, 0, 0}, {0, 0, 0}, {1, -0.0f, 0}, {-0.0f, 0, -0.0f}, {2, 0, 0}, {1, 0, 0}}, &count);
  EXPECT_EQ(ids, (std::vector<std::uint32_t>{0, 1, 0, 1, 2, 0}));
  EXPECT_EQ(count, 3u);
}

// Enough positions for the parts on several threads (weld_positions deals positions in chunks of
// 65536): a random cloud where a third repeat an earlier position (some as -0), checked against
// the rule itself (a map from key to the first index) on 1 to 5 threads.
TEST(MeshTopology, WeldIdsOnSeveralThreadsAreTheFirstOccurrences) {
  std::vector<glm::vec3> positions;
  std::uint64_t x = 0x9e3779b97f4a7c15ull;
  auto next = [&] { return x ^= x << 13, x ^= x >> 7, x ^= x << 17; };
  for (std::size_t i = 0; i < 300000; ++i) {
    if (i > 0 && next() % 3 == 0) {
      glm::vec3 p = positions[std::size_t(next() % i)];
      if (p.x == 0.0f) p.x = -p.x;
      positions.push_back(p);
    } else {
      positions.push_back({float(next() % 1000) * 0.5f, float(next() % 7) - 3.0f, 0.0f});
    }
  }
  std::map<std::array<float, 3>, std::uint32_t> first;
  std::vector<std::uint32_t> want;
  for (const glm::vec3& p : positions) {
    const auto [it, added] = first.try_emplace({p.x + 0.0f, p.y + 0.0f, p.z + 0.0f}, std::uint32_t(first.size()));
    want.push_back(it->second);
  }
  for (int threads : {1, 2, 3, 5}) {
    std::size_t count = 0;
    EXPECT_TRUE(weld_positions(positions, &count, threads) == want) << threads << " threads";
    EXPECT_EQ(count, first.size()) << threads << " threads";
  }
}

// "All cores" is what an AllCores scope says while it lasts.
TEST(Parallel, AllCoresScopeBoundsTheDefaultThreads) {
  const int machine = worker_threads(0);
  {
    const AllCores one(1);
    EXPECT_EQ(worker_threads(0), 1);
    EXPECT_EQ(worker_threads(3), 3);
    {
      const AllCores seven(7);
      EXPECT_EQ(worker_threads(-1), 7);
    }
    EXPECT_EQ(worker_threads(0), 1);
  }
  EXPECT_EQ(worker_threads(0), machine);
  const AllCores none(0);
  EXPECT_EQ(worker_threads(0), machine);
}

// mark_on_threads: 1 exactly at the indexed places (earlier contents cleared), whatever the threads.
TEST(Parallel, MarkOnThreadsMarksExactlyTheIndexed) {
  std::vector<std::uint32_t> index;
  for (std::uint32_t i = 0; i < 300000; ++i) index.push_back((i * 7919u) % 200003u);
  std::vector<std::uint8_t> want(400000, 0);
  for (std::uint32_t i : index) want[i] = 1;
  for (int threads : {1, 3}) {
    std::vector<std::uint8_t> marks(400000, 9);
    mark_on_threads(threads, index, marks);
    EXPECT_EQ(marks, want) << threads << " threads";
  }
}

// touch_storage reserves each vector's storage (its elements kept, its size unchanged), for several
// vectors of different types at once, one of them already large enough and one asked for nothing.
TEST(Parallel, TouchStorageReservesAndKeepsTheElements) {
  std::vector<std::uint32_t> a = {7, 8, 9};
  std::vector<glm::dvec3> b;
  std::vector<std::uint8_t> c(100, 5), d;
  c.reserve(1000);
  for (int threads : {1, 3}) {
    touch_storage(threads, storage_for(a, std::size_t(1) << 20), storage_for(b, 300000), storage_for(c, 500), storage_for(d, 0));
    EXPECT_GE(a.capacity(), std::size_t(1) << 20);
    EXPECT_GE(b.capacity(), 300000u);
    EXPECT_EQ(c.capacity(), 1000u);
    EXPECT_EQ(a, (std::vector<std::uint32_t>{7, 8, 9}));
    EXPECT_TRUE(b.empty());
    EXPECT_EQ(c, std::vector<std::uint8_t>(100, 5));
    EXPECT_TRUE(d.empty());
  }
  a.resize(std::size_t(1) << 20);
  EXPECT_EQ(a[2], 9u);
  EXPECT_EQ(std::count(a.begin() + 3, a.end(), 0u), std::ptrdiff_t((1 << 20) - 3));
}

TEST(MeshTopology, DuplicatesKeepTheEarliestFace) {
  // Position 4 is position 0 again, position 5 is used by no face. Faces 2 and 3 repeat face 1's
  // vertices (welded), in other orders; face 4 has two corners welded. Face 1 (kept) is wound
  // against face 0 across edge 1-2: one of the two is turned. Had face 3 been kept instead, the
  // two would agree.
  const Mesh m = make_mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 0}, {5, 5, 5}},
                           {1, 3, 2, /**/ 4, 2, 1, /**/ 0, 1, 2, /**/ 1, 2, 4, /**/ 0, 4, 3});
  expect_counts(inspect_topology(m), {4, 1, 2, 4, 0, 1});
  // A tie: the seed (face 0) keeps its winding, +z, and so does every corner.
  std::size_t reoriented = 0;
  const std::vector<glm::vec3> n = compute_high_corner_normals(m, &reoriented);
  EXPECT_EQ(reoriented, 1u);
  for (std::size_t c = 0; c < n.size(); ++c) {
    EXPECT_NEAR(n[c].x, 0.0f, 1e-6f) << "corner " << c;
    EXPECT_NEAR(n[c].y, 0.0f, 1e-6f) << "corner " << c;
    EXPECT_NEAR(n[c].z, 1.0f, 1e-6f) << "corner " << c;
  }
}

TEST(MeshTopology, ThreeFacesOnAnEdgeMakeItNonManifoldAndLinkNone) {
  // Faces 0 and 1 run edge 0-1 the same way; they would be linked (and one turned) across a
  // manifold edge, but face 2 makes it non-manifold.
  const Mesh m =
      make_mesh({{0, 0, 0}, {1, 0, 0}, {0.5f, 1, 0}, {0.5f, -1, 0}, {0.5f, 0, 1}}, {0, 1, 2, /**/ 0, 1, 3, /**/ 1, 0, 4});
  expect_counts(inspect_topology(m), {5, 0, 0, 6, 1, 0});
}

TEST(MeshTopology, FacesTurnedInANonOrientablePieceFollowTheEdgeOrder) {
  // A Klein bottle has no consistent winding: which faces are turned depends on the order the
  // walk reaches them in. These are the faces the sort-based implementation (all edges sorted by
  // (key, face)) turned; a change of the links' order changes them (vertices visited in decreasing
  // order, or a vertex's edges by decreasing larger vertex, turn 10 or 15 faces here).
  struct Case {
    int nu, nv;
    std::vector<std::size_t> turned;
  };
  const Case cases[] = {{3, 6, {2, 6, 11, 12, 16, 17, 18, 21, 22, 23, 26, 28, 31, 33}}};
  for (const Case& k : cases) {
    SCOPED_TRACE(std::to_string(k.nu) + " x " + std::to_string(k.nv));
    const Mesh m = make_shuffled_klein_bottle(k.nu, k.nv);
    const MeshTopology t = inspect_topology(m);
    ASSERT_EQ(t.welded_vertices, m.positions.size());
    EXPECT_EQ(t.boundary_edges, 0u);
    EXPECT_EQ(t.non_manifold_edges, 0u);
    EXPECT_EQ(t.duplicate_faces, 0u);
    EXPECT_EQ(t.inconsistent_winding_faces, k.turned.size());
    // The normals are those of exactly these faces turned (positions are distinct, so welded ids
    // are position numbers).
    std::vector<std::uint8_t> flip(m.triangle_count(), 0), skip(m.triangle_count(), 0);
    for (std::size_t f : k.turned) flip[f] = 1;
    const std::vector<glm::dvec3> sum =
        angle_weighted_sums(m, m.position_index.data(), m.positions.size(), skip.data(), flip.data());
    std::size_t reoriented = 0;
    const std::vector<glm::vec3> n = compute_high_corner_normals(m, &reoriented);
    EXPECT_EQ(reoriented, k.turned.size());
    ASSERT_EQ(n.size(), m.position_index.size());
    for (std::size_t c = 0; c < n.size(); ++c) EXPECT_EQ(n[c], unit_or_up(sum[m.position_index[c]])) << "corner " << c;
  }
}

// A grid large enough for many chunks of vertices: the counts are those of the grid, whatever the
// threads, and with faces turned, repeated and a fin added, the counts and normals are the same on
// 1, 2 and 3 threads.
TEST(MeshTopology, CountsAndNormalsDoNotDependOnTheThreads) {
  // Past 65536 positions, so that weld_positions deals them into its parts on several threads.
  const int n = 260;  // n x n quads, (n + 1)^2 = 68121 vertices
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> index;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) positions.push_back({float(i), float(j), 0.01f * float((i * 7 + j * 3) % 5)});
  auto v = [&](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      for (std::uint32_t k : {v(i, j), v(i + 1, j), v(i + 1, j + 1)}) index.push_back(k);
      for (std::uint32_t k : {v(i, j), v(i + 1, j + 1), v(i, j + 1)}) index.push_back(k);
    }
  const Mesh grid = make_mesh(positions, index);
  for (int threads : {1, 2, 3})
    expect_counts(inspect_topology(grid, threads), {positions.size(), 0, 0, std::size_t(4 * n), 0, 0});

  // Every 37th face turned, every 101st repeated (rotated), a fin on the diagonal of the first quad.
  std::vector<std::uint32_t> messy = index;
  for (std::size_t t = 0; t < index.size() / 3; t += 37) std::swap(messy[3 * t + 1], messy[3 * t + 2]);
  for (std::size_t t = 5; t < index.size() / 3; t += 101)
    for (int k : {1, 2, 0}) messy.push_back(index[3 * t + std::size_t(k)]);
  positions.push_back({0.5f, 0.0f, 3.0f});
  for (std::uint32_t k : {index[0], index[2], std::uint32_t(positions.size() - 1)}) messy.push_back(k);
  const Mesh m = make_mesh(positions, messy);
  const MeshTopology one = inspect_topology(m, 1);
  EXPECT_EQ(one.duplicate_faces, (index.size() / 3 - 5 + 100) / 101);
  EXPECT_EQ(one.non_manifold_edges, 1u);
  EXPECT_EQ(one.inconsistent_winding_faces, (index.size() / 3 + 36) / 37);
  std::size_t reoriented_one = 0;
  const std::vector<glm::vec3> normals_one = compute_high_corner_normals(m, &reoriented_one, 1);
  for (int threads : {2, 3}) {
    const MeshTopology t = inspect_topology(m, threads);
    expect_counts(t, {one.welded_vertices, one.isolated_vertices, one.duplicate_faces, one.boundary_edges, one.non_manifold_edges,
                      one.inconsistent_winding_faces});
    std::size_t reoriented = 0;
    EXPECT_TRUE(compute_high_corner_normals(m, &reoriented, threads) == normals_one);
    EXPECT_EQ(reoriented, reoriented_one);
  }
}
