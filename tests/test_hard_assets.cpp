// Checks of the hard-asset generators themselves (tests/procedural/hard_assets.h): closed and
// consistently wound meshes, normals that follow the faces, a low-poly within max_s of the
// high-poly, UV islands apart inside [0,1]^2, the requested gap and bump, and known answers from
// locate (style.md: known answers first).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <numeric>
#include <unordered_map>
#include <vector>

#include <gtest/gtest.h>

#include "hard_assets.h"
#include "test_support.h"

using namespace nmbake;
using procedural::HardAsset;
using test::angle_deg;

namespace {

constexpr double kTubeRadius = 0.05;  // hard_assets.h

// The set, built once for the whole program (it is the slow part).
const std::vector<HardAsset>& assets() {
  static const std::vector<HardAsset> set = procedural::hard_asset_set();
  return set;
}

bool flipped(const HardAsset& a) { return a.name.find("_flipped") != std::string::npos; }

int part_count(const HardAsset& a) { return *std::max_element(a.low_part.begin(), a.low_part.end()) + 1; }

glm::dvec3 pos(const Mesh& m, std::size_t t, int c) { return glm::dvec3(m.corner_position(t, c)); }

// Twice the area vector of triangle t (its geometric normal, unnormalised).
glm::dvec3 area_normal(const Mesh& m, std::size_t t) {
  return glm::cross(pos(m, t, 1) - pos(m, t, 0), pos(m, t, 2) - pos(m, t, 0));
}

// One id per distinct position value (-0 and +0 are the same value).
std::vector<std::uint32_t> weld(const Mesh& m) {
  struct Hash {
    std::size_t operator()(const std::array<std::uint32_t, 3>& k) const {
      return (std::size_t(k[0]) * 73856093u) ^ (std::size_t(k[1]) * 19349663u) ^ (std::size_t(k[2]) * 83492791u);
    }
  };
  std::unordered_map<std::array<std::uint32_t, 3>, std::uint32_t, Hash> ids;
  std::vector<std::uint32_t> id(m.positions.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    std::array<std::uint32_t, 3> key{};
    for (int k = 0; k < 3; ++k) {
      const float v = m.positions[i][k] + 0.0f;  // -0 + 0 = +0
      std::memcpy(&key[std::size_t(k)], &v, sizeof v);
    }
    id[i] = ids.emplace(key, std::uint32_t(ids.size())).first->second;
  }
  return id;
}

// Every undirected edge (positions welded by value) is used by exactly two triangles, once in each
// direction; no triangle has two welded corners or zero area. Returns the first problem or "".
std::string closed_problem(const Mesh& m) {
  const std::vector<std::uint32_t> id = weld(m);
  std::vector<std::uint64_t> edges;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    std::array<std::uint64_t, 3> v{};
    for (int c = 0; c < 3; ++c) v[std::size_t(c)] = id[m.position_index[3 * t + std::size_t(c)]];
    if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) return "triangle " + std::to_string(t) + " has welded corners";
    if (!(glm::length(area_normal(m, t)) > 1e-12)) return "triangle " + std::to_string(t) + " has zero area";
    for (int c = 0; c < 3; ++c) edges.push_back(v[std::size_t(c)] << 32 | v[std::size_t((c + 1) % 3)]);
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const std::uint64_t e = edges[i], reverse = (e & 0xffffffffu) << 32 | e >> 32;
    if (i + 1 < edges.size() && edges[i + 1] == e) return "directed edge used twice (a fold or a flipped neighbour)";
    if (!std::binary_search(edges.begin(), edges.end(), reverse)) return "open edge";
  }
  return "";
}

// The positions of the high-poly's vertices of one part (each once).
std::vector<glm::dvec3> part_vertices(const HardAsset& a, int part) {
  std::vector<char> used(a.high.positions.size(), 0);
  for (std::size_t t = 0; t < a.high.triangle_count(); ++t)
    if (a.high_part[t] == part)
      for (int c = 0; c < 3; ++c) used[a.high.position_index[3 * t + std::size_t(c)]] = 1;
  std::vector<glm::dvec3> out;
  for (std::size_t i = 0; i < used.size(); ++i)
    if (used[i]) out.push_back(glm::dvec3(a.high.positions[i]));
  return out;
}

// The smallest distance between a point of `a` and a point of `b`, searched up to `reach` (returns
// reach when nothing is closer): a hash grid of cell `reach` over b.
double min_distance(const std::vector<glm::dvec3>& a, const std::vector<glm::dvec3>& b, double reach) {
  auto cell = [reach](const glm::dvec3& p) {
    return std::array<long, 3>{long(std::floor(p.x / reach)), long(std::floor(p.y / reach)), long(std::floor(p.z / reach))};
  };
  auto key = [](long x, long y, long z) {
    return (std::uint64_t(x & 0x1fffff) << 42) | (std::uint64_t(y & 0x1fffff) << 21) | std::uint64_t(z & 0x1fffff);
  };
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> grid;
  for (std::size_t i = 0; i < b.size(); ++i) {
    const auto c = cell(b[i]);
    grid[key(c[0], c[1], c[2])].push_back(i);
  }
  double best = reach;
  for (const glm::dvec3& p : a) {
    const auto c = cell(p);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
          if (it == grid.end()) continue;
          for (std::size_t j : it->second) best = std::min(best, glm::distance(p, b[j]));
        }
  }
  return best;
}

}  // namespace

TEST(HardAssets, SetHasTheSevenCasesWithConsistentArrays) {
  const auto& set = assets();
  ASSERT_EQ(set.size(), 7u);
  const char* names[] = {"close_tubes_gap0.012_bulge0.04",
                         "close_tubes_gap0.004_bulge0.04",
                         "close_tubes_gap0.012_bulge0.14",
                         "thin_shell_t0.01",
                         "cavity_gap0.01",
                         "bevelled_box_h0.3_b0.03",
                         "thin_shell_t0.01_flipped_no_normals"};
  for (std::size_t i = 0; i < set.size(); ++i) {
    const HardAsset& a = set[i];
    SCOPED_TRACE(a.name);
    EXPECT_EQ(a.name, names[i]);
    EXPECT_EQ(a.low.source, a.name);
    EXPECT_EQ(a.high.source, a.name);
    EXPECT_GT(a.max_s, 0.0);
    ASSERT_TRUE(a.locate && a.expected_normal);
    for (const Mesh* m : {&a.low, &a.high}) {
      EXPECT_EQ(m->position_index.size() % 3, 0u);
      EXPECT_EQ(m->source_face.size(), m->triangle_count());
      if (m->has_normals()) {
        EXPECT_EQ(m->normal_index.size(), m->position_index.size());
      }
      for (std::uint32_t k : m->position_index) ASSERT_LT(k, m->positions.size());
      for (std::uint32_t k : m->normal_index) ASSERT_LT(k, m->normals.size());
      for (std::uint32_t k : m->uv_index) ASSERT_LT(k, m->uvs.size());
    }
    EXPECT_EQ(a.low_part.size(), a.low.triangle_count());
    EXPECT_EQ(a.high_part.size(), a.high.triangle_count());
    EXPECT_TRUE(a.low.has_uvs() && a.low.has_normals());
    EXPECT_EQ(a.low.uv_index.size(), a.low.position_index.size());
    EXPECT_EQ(a.high.has_normals(), !flipped(a));
    EXPECT_GE(a.high.triangle_count(), 50000u);
    EXPECT_LE(a.high.triangle_count(), 200000u);
    // Every part id is used on both meshes.
    const int parts = part_count(a);
    for (int p = 0; p < parts; ++p) {
      EXPECT_NE(std::find(a.low_part.begin(), a.low_part.end(), p), a.low_part.end()) << "part " << p;
      EXPECT_NE(std::find(a.high_part.begin(), a.high_part.end(), p), a.high_part.end()) << "part " << p;
    }
    for (int p : a.high_part) ASSERT_TRUE(p >= 0 && p < parts);
    std::printf("%-40s low %6zu high %7zu triangles, %d parts, max_s %.4f\n", a.name.c_str(), a.low.triangle_count(),
                a.high.triangle_count(), parts, a.max_s);
  }
}

TEST(HardAssets, MeshesAreClosedAndConsistentlyWound) {
  for (const HardAsset& a : assets()) {
    EXPECT_EQ(closed_problem(a.low), "") << a.name << " low";
    EXPECT_EQ(closed_problem(a.high), "") << a.name << " high";
  }
}

TEST(HardAssets, HighNormalsAreUnitAndFollowTheFaces) {
  for (const HardAsset& a : assets()) {
    if (!a.high.has_normals()) continue;
    const double side = flipped(a) ? -1.0 : 1.0;
    double worst = 0;
    for (std::size_t t = 0; t < a.high.triangle_count(); ++t) {
      const glm::dvec3 face = side * area_normal(a.high, t);
      for (int c = 0; c < 3; ++c) {
        const glm::dvec3 n(a.high.corner_normal(t, c));
        ASSERT_NEAR(glm::length(n), 1.0, 1e-6) << a.name << " triangle " << t;
        const double e = angle_deg(n, face);
        ASSERT_LE(e, 30.0) << a.name << " triangle " << t << " corner " << c;
        worst = std::max(worst, e);
      }
    }
    // A wrong derivative in a detail function would hardly show against the 30 degree bound; against
    // the area-weighted mean of the faces around each vertex normal (one-sided at hard edges) it does.
    std::vector<glm::dvec3> around(a.high.normals.size(), glm::dvec3(0.0));
    for (std::size_t t = 0; t < a.high.triangle_count(); ++t)
      for (int c = 0; c < 3; ++c) around[a.high.normal_index[3 * t + std::size_t(c)]] += side * area_normal(a.high, t);
    double worst_mean = 0, sum_mean = 0;
    for (std::size_t i = 0; i < around.size(); ++i) {
      const double e = angle_deg(glm::dvec3(a.high.normals[i]), around[i]);
      worst_mean = std::max(worst_mean, e);
      sum_mean += e;
    }
    std::printf("%-40s high normal to faces: max %.2f deg; to their mean: mean %.3f deg, max %.2f deg\n", a.name.c_str(), worst,
                sum_mean / double(around.size()), worst_mean);
    EXPECT_LT(worst_mean, 3.0) << a.name;
    EXPECT_LT(sum_mean / double(around.size()), 0.3) << a.name;
  }
}

TEST(HardAssets, FlippedHighKeepsItsNormalsOppositeToTheFaces) {
  const HardAsset box = procedural::make_bevelled_box(0.3, 0.03, 8, 3);
  const HardAsset f = procedural::flip_high_winding(box, true);
  EXPECT_EQ(f.name, box.name + "_flipped");
  ASSERT_TRUE(f.high.has_normals());
  EXPECT_EQ(closed_problem(f.high), "");
  for (std::size_t t = 0; t < f.high.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(f.high.corner_position(t, c), box.high.corner_position(t, c == 0 ? 0 : 3 - c));
      ASSERT_LE(angle_deg(glm::dvec3(f.high.corner_normal(t, c)), -area_normal(f.high, t)), 30.0) << "triangle " << t;
    }
  const HardAsset g = procedural::flip_high_winding(box, false);
  EXPECT_FALSE(g.high.has_normals());
  EXPECT_TRUE(g.high.normals.empty());
  EXPECT_EQ(g.high.source, box.name + "_flipped_no_normals");
}

TEST(HardAssets, LowNormalsAreUnitAndFollowTheFaces) {
  for (const HardAsset& a : assets())
    for (std::size_t t = 0; t < a.low.triangle_count(); ++t)
      for (int c = 0; c < 3; ++c) {
        const glm::dvec3 n(a.low.corner_normal(t, c));
        ASSERT_NEAR(glm::length(n), 1.0, 1e-6) << a.name << " triangle " << t;
        ASSERT_LE(angle_deg(n, area_normal(a.low, t)), 45.0) << a.name << " triangle " << t << " corner " << c;
      }
}

TEST(HardAssets, LowUVsAreIslandsInsideTheUnitSquare) {
  for (const HardAsset& a : assets()) {
    SCOPED_TRACE(a.name);
    const Mesh& m = a.low;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const glm::dvec2 p0(m.corner_uv(t, 0)), p1(m.corner_uv(t, 1)), p2(m.corner_uv(t, 2));
      const double area = 0.5 * ((p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x));
      ASSERT_GT(area, 1e-8) << "triangle " << t;
      for (const glm::dvec2& p : {p0, p1, p2}) ASSERT_TRUE(p.x >= 0 && p.x <= 1 && p.y >= 0 && p.y <= 1) << "triangle " << t;
    }
    // Islands: triangles sharing a UV corner. Their bounding boxes must be >= 0.01 apart.
    std::vector<std::uint32_t> root(m.uvs.size());
    std::iota(root.begin(), root.end(), 0u);
    auto find = [&](std::uint32_t x) {
      while (root[x] != x) x = root[x] = root[root[x]];
      return x;
    };
    for (std::size_t t = 0; t < m.triangle_count(); ++t)
      for (int c = 1; c < 3; ++c) root[find(m.uv_index[3 * t + std::size_t(c)])] = find(m.uv_index[3 * t]);
    std::unordered_map<std::uint32_t, std::array<double, 4>> box;  // min u, min v, max u, max v
    for (std::uint32_t k : m.uv_index) {
      auto it = box.emplace(find(k), std::array<double, 4>{2, 2, -1, -1}).first;
      const glm::dvec2 p(m.uvs[k]);
      it->second = {std::min(it->second[0], p.x), std::min(it->second[1], p.y), std::max(it->second[2], p.x),
                    std::max(it->second[3], p.y)};
    }
    std::vector<std::array<double, 4>> boxes;
    for (const auto& [k, b] : box) boxes.push_back(b);
    EXPECT_GE(boxes.size(), 3u);
    for (std::size_t i = 0; i < boxes.size(); ++i)
      for (std::size_t j = i + 1; j < boxes.size(); ++j) {
        const auto &p = boxes[i], &q = boxes[j];
        const double apart = std::max({q[0] - p[2], p[0] - q[2], q[1] - p[3], p[1] - q[3]});
        EXPECT_GE(apart, 0.01) << "islands " << i << " and " << j;
      }
  }
}

TEST(HardAssets, LowPolyIsWithinMaxSOfTheHighPoly) {
  // Points inside the low triangles (not the corners: at the box's corners the face-normal line
  // misses the rounded high-poly by design) along the interpolated normal, as the bake casts.
  const std::array<glm::dvec3, 4> bary = {
      glm::dvec3(1.0 / 3, 1.0 / 3, 1.0 / 3), {0.8, 0.1, 0.1}, {0.1, 0.8, 0.1}, {0.1, 0.1, 0.8}};
  for (const HardAsset& a : assets()) {
    const int parts = part_count(a);
    std::size_t samples = 0, own = 0, other = 0;
    double worst = 0;
    for (std::size_t t = 0; t < a.low.triangle_count(); ++t)
      for (const glm::dvec3& b : bary) {
        glm::dvec3 p(0.0), n(0.0);
        for (int c = 0; c < 3; ++c) {
          p += b[c] * pos(a.low, t, c);
          n += b[c] * glm::dvec3(a.low.corner_normal(t, c));
        }
        n = glm::normalize(n);
        ++samples;
        const procedural::SurfacePoint hit = a.locate(p, n, a.low_part[t]);
        if (hit.crossed) {
          ++own;
          ASSERT_LE(std::abs(hit.s), a.max_s);
          ASSERT_NEAR(glm::distance(hit.point, p + hit.s * n), 0.0, 1e-9);
          worst = std::max(worst, std::abs(hit.s));
          continue;
        }
        bool any = false;
        for (int q = 0; q < parts && !any; ++q) any = a.locate(p, n, q).crossed;
        ASSERT_TRUE(any) << a.name << ": no part of the high-poly within max_s of low triangle " << t;
        ++other;
      }
    std::printf("%-40s low samples %zu: own part crossed %zu, another part %zu, largest |s| %.5f (max_s %.5f)\n", a.name.c_str(),
                samples, own, other, worst, a.max_s);
    // Only the thin shell's rim, near its edges, may meet a face instead (hard_assets.h).
    EXPECT_GE(double(own), 0.95 * double(samples)) << a.name;
    if (a.name.rfind("thin_shell", 0) != 0) {
      EXPECT_EQ(own, samples) << a.name;
    }
  }
}

TEST(HardAssets, ExpectedNormalAtHighVerticesIsTheirNormal) {
  for (const HardAsset& a : assets()) {
    if (!a.high.has_normals()) continue;
    const std::size_t stride = std::max<std::size_t>(1, a.high.triangle_count() / 1500) | 1;
    double worst = 0, worst_s = 0;
    for (std::size_t t = 0; t < a.high.triangle_count(); t += stride)
      for (int c = 0; c < 3; ++c) {
        const glm::dvec3 p = pos(a.high, t, c), n(a.high.corner_normal(t, c));
        const procedural::SurfacePoint hit = a.locate(p, n, a.high_part[t]);
        ASSERT_TRUE(hit.crossed) << a.name << " triangle " << t << " corner " << c;
        const double e = angle_deg(a.expected_normal(p, n, a.high_part[t]), n);
        ASSERT_LE(e, 0.5) << a.name << " triangle " << t << " corner " << c;
        worst = std::max(worst, e);
        worst_s = std::max(worst_s, std::abs(hit.s));
      }
    std::printf("%-40s high vertices: max %.2e deg, max |s| %.2e\n", a.name.c_str(), worst, worst_s);
    EXPECT_LT(worst_s, 1e-6) << a.name;  // the vertices lie on the analytic surface up to float rounding
  }
}

TEST(HardAssets, CloseTubesAreGapApartWithTheBumpAtItsHeight) {
  const std::array<std::array<double, 2>, 3> cases = {{{0.012, 0.04}, {0.004, 0.04}, {0.012, 0.14}}};  // gap, bulge
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const HardAsset& a = assets()[i];
    const double gap = cases[i][0], bulge = cases[i][1];
    ASSERT_EQ(a.name.rfind("close_tubes", 0), 0u);
    std::vector<std::vector<glm::dvec3>> tubes;
    for (int p = 0; p < 5; ++p) tubes.push_back(part_vertices(a, p));
    for (int p = 0; p + 1 < 5; ++p) {
      const double d = min_distance(tubes[std::size_t(p)], tubes[std::size_t(p + 1)], 2 * gap);
      std::printf("%s: tubes %d and %d are %.6f apart\n", a.name.c_str(), p, p + 1, d);
      EXPECT_GE(d, 0.9 * gap) << a.name << " tubes " << p << ", " << p + 1;
      EXPECT_LE(d, 1.1 * gap) << a.name << " tubes " << p << ", " << p + 1;
    }
    double top = -1;
    for (const glm::dvec3& v : tubes[2]) top = std::max(top, v.y);
    EXPECT_NEAR(top, kTubeRadius + bulge, 0.02 * (kTubeRadius + bulge)) << a.name;
    // The other tubes have no bump.
    for (int p : {0, 1, 3, 4}) {
      double y = -1;
      for (const glm::dvec3& v : tubes[std::size_t(p)]) y = std::max(y, v.y);
      EXPECT_NEAR(y, kTubeRadius, 1e-6) << a.name << " tube " << p;
    }
  }
}

TEST(HardAssets, LocateGivesKnownAnswers) {
  constexpr double R = kTubeRadius, gap = 0.012, bulge = 0.04, pitch = 2 * R + gap;
  const HardAsset& tubes = assets()[0];
  auto expect_hit = [](const procedural::SurfacePoint& h, double s, const glm::dvec3& n, const char* what) {
    EXPECT_TRUE(h.crossed) << what;
    EXPECT_NEAR(h.s, s, 1e-12) << what;
    EXPECT_LT(angle_deg(h.normal, n), 1e-6) << what;
  };
  // The bump's top on the middle tube, and the neighbour across the gap (ripples vanish on x = axis + R).
  expect_hit(tubes.locate({0, R, 0}, {0, 1, 0}, 2), bulge, {0, 1, 0}, "bump top");
  expect_hit(tubes.locate({-pitch + R, 0, 0.1}, {1, 0, 0}, 1), 0.0, {1, 0, 0}, "tube 1, +x side");
  expect_hit(tubes.locate({-pitch + R, 0, 0.1}, {1, 0, 0}, 2), gap, {-1, 0, 0}, "tube 1's ray onto tube 2");
  expect_hit(tubes.locate({0, 0.02, 0.3}, {0, 0, 1}, 2), 0.0, {0, 0, 1}, "cap");
  // Above the bump the line misses it: the nearest point is the bump's top.
  const procedural::SurfacePoint miss = tubes.locate({0, R + bulge + 0.01, 0}, {1, 0, 0}, 2);
  EXPECT_FALSE(miss.crossed);
  EXPECT_LT(glm::distance(miss.point, glm::dvec3(0, R + bulge, 0)), 1e-9);
  EXPECT_LT(angle_deg(miss.normal, {0, 1, 0}), 1e-6);

  const HardAsset& shell = assets()[3];
  const double t = 0.01, amplitude = t / 4;
  expect_hit(shell.locate({0.025, 0.025, t / 2}, {0, 0, 1}, 0), amplitude, {0, 0, 1}, "egg-crate top");
  expect_hit(shell.locate({0, 0, -t / 2}, {0, 0, -1}, 1), amplitude, {0, 0, -1}, "wave crest below");
  expect_hit(shell.locate({0.4, 0, 0}, {1, 0, 0}, 2), t / 2, {1, 0, 0}, "rim");

  const HardAsset& cavity = assets()[4];
  expect_hit(cavity.locate({0.19, 0, 0}, {1, 0, 0}, 1), 0.0, {1, 0, 0}, "rod");
  expect_hit(cavity.locate({0.19, 0, 0}, {1, 0, 0}, 0), 0.01, {-1, 0, 0}, "rod's ray onto the bore");
  expect_hit(cavity.locate({0.25, 0, 0.25}, {0, 0, 1}, 0), 0.0, {0, 0, 1}, "end ring");

  const HardAsset& box = assets()[5];
  expect_hit(box.locate({0.3, 0, 0}, {1, 0, 0}, 0), 0.0, {1, 0, 0}, "face");
  const glm::dvec3 diagonal = glm::normalize(glm::dvec3(1, 1, 0));
  expect_hit(box.locate({0.3, 0.3, 0}, diagonal, 0), -0.03 * (std::sqrt(2.0) - 1), diagonal, "edge");
  const procedural::SurfacePoint corner = box.locate({0.3, 0.3, 0.3}, {1, 0, 0}, 0);
  EXPECT_FALSE(corner.crossed);  // the face-normal line from the low corner passes outside the rounded corner
  EXPECT_LT(angle_deg(corner.normal, {1, 1, 1}), 1e-6);
  EXPECT_LT(glm::distance(corner.point, glm::dvec3(0.27) + 0.03 / std::sqrt(3.0)), 1e-12);
}

TEST(HardAssets, WithoutACrossingLocateGivesTheNearestPoint) {
  // Lines that pass outside a part (above the middle tube's bump, above the thin shell's top):
  // the fallback must be at least as near to p as every high-poly vertex of the part (they lie on
  // the surface), and not much farther than the nearest one (their spacing).
  struct Case {
    const HardAsset* asset;
    int part;
    glm::dvec3 from, to;  // p runs over this segment
    double spacing;
  };
  const Case cases[] = {{&assets()[2], 2, {-0.08, 0.2, -0.2}, {0.08, 0.24, 0.2}, 0.006},
                        {&assets()[3], 0, {-0.45, -0.3, 0.03}, {0.45, 0.3, 0.05}, 0.005}};
  for (const Case& c : cases) {
    const std::vector<glm::dvec3> vertices = part_vertices(*c.asset, c.part);
    double worst = 0;
    for (int i = 0; i < 64; ++i) {
      const glm::dvec3 p = c.from + (c.to - c.from) * glm::dvec3(i / 63.0, (i * 37 % 64) / 63.0, (i * 11 % 64) / 63.0);
      const procedural::SurfacePoint hit = c.asset->locate(p, {1, 0, 0}, c.part);
      ASSERT_FALSE(hit.crossed) << c.asset->name << " p " << p.x << " " << p.y << " " << p.z;
      double nearest = 1e9;
      for (const glm::dvec3& v : vertices) nearest = std::min(nearest, glm::distance(p, v));
      const double d = glm::distance(p, hit.point);
      EXPECT_LE(d, nearest + 1e-6) << c.asset->name << " p " << p.x << " " << p.y << " " << p.z;
      EXPECT_GE(d, nearest - c.spacing) << c.asset->name;
      // The point is on the part's surface: a line through it along its normal crosses there.
      const procedural::SurfacePoint back = c.asset->locate(hit.point, hit.normal, c.part);
      EXPECT_TRUE(back.crossed);
      EXPECT_NEAR(back.s, 0.0, 1e-9);
      EXPECT_LT(angle_deg(back.normal, hit.normal), 1e-6);
      worst = std::max(worst, nearest - d);
    }
    std::printf("%s part %d: nearest vertex at most %.5f farther than the fallback point\n", c.asset->name.c_str(), c.part,
                worst);
  }
}
