// Thin, close parts with a coarse low-poly (issue 34, item 1): legs, fingers, antennae and tails
// whose decimated low-poly lies outside the high surface at its corners and inside it between
// them (tests/procedural/thin_parts.h), and a coarse prism under close rippled tubes with a known
// answer (hard_assets.h). The automatic cage must do as well as the best fixed ray distance of a
// sweep: no more missed samples, no more suspect texels. (nmview --compare's figure:
// tests/viewer/test_thin_parts_view.cpp.)
#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "hard_asset_answers.h"
#include "hard_assets.h"
#include "pipeline/bake.h"
#include "test_support.h"
#include "thin_parts.h"

namespace nmbake {
namespace {

// The ray distances of the sweep, as shares of the scene diagonal (front = rear), and Blender's
// usual pair (cage extrusion 1.5%, max ray distance 3%).
constexpr double kSweep[] = {0.005, 0.01, 0.015, 0.02, 0.03, 0.05};
constexpr double kBlenderFront = 0.015, kBlenderRear = 0.03;
// How much worse than the best fixed distance the automatic cage may be: 0.02 percentage points of
// the samples (misses) and of the covered texels (suspect).
constexpr double kShareTolerance = 2e-4;

struct Figures {
  double misses = 0.0, suspect = 0.0;  // share of the covered samples, of the covered texels
};

Figures bake_figures(const Mesh& low, const Mesh& high, double front, double rear) {
  BakeOptions o;
  o.width = o.height = 256;
  o.front = float(front);
  o.rear = float(rear);
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  return {double(r.stats.trace.misses) / double(std::max<std::uint64_t>(1, r.stats.trace.hits + r.stats.trace.misses)),
          r.stats.pad.suspect_share};
}

TEST(ThinParts, FamilyIsCoarseOverFine) {
  for (const procedural::ThinPartsSpec& spec : procedural::thin_parts_family()) {
    const procedural::ThinParts p = procedural::make_thin_parts(spec);
    const double ratio = double(p.low.triangle_count()) / double(p.high.triangle_count());
    EXPECT_GE(ratio, 0.01) << spec.name;
    EXPECT_LE(ratio, 0.05) << spec.name;
    EXPECT_LE(p.high.triangle_count(), 40000u) << spec.name;
    EXPECT_EQ(p.low.uv_index.size(), p.low.position_index.size());
    for (const glm::vec2& uv : p.low.uvs) EXPECT_TRUE(uv.x > 0.0f && uv.x < 1.0f && uv.y > 0.0f && uv.y < 1.0f) << spec.name;
  }
}

TEST(ThinParts, AutomaticCageIsNoWorseThanTheBestFixedDistance) {
  for (const procedural::ThinPartsSpec& spec : procedural::thin_parts_family()) {
    const procedural::ThinParts p = procedural::make_thin_parts(spec);
    const double d = procedural::diagonal(p);
    const Figures automatic = bake_figures(p.low, p.high, -1.0, -1.0);
    Figures best{1.0, 1.0};
    auto add = [&](const char* label, double front, double rear) {
      const Figures f = bake_figures(p.low, p.high, front * d, rear * d);
      std::printf("measured: %s %s misses %.3f%%, suspect %.3f%%\n", spec.name.c_str(), label, 100.0 * f.misses,
                  100.0 * f.suspect);
      best.misses = std::min(best.misses, f.misses);
      best.suspect = std::min(best.suspect, f.suspect);
    };
    for (double s : kSweep) add(("fixed " + std::to_string(s)).c_str(), s, s);
    add("blender", kBlenderFront, kBlenderRear);
    std::printf("measured: %s automatic misses %.3f%%, suspect %.3f%%\n", spec.name.c_str(), 100.0 * automatic.misses,
                100.0 * automatic.suspect);
    EXPECT_LE(automatic.misses, best.misses + kShareTolerance) << spec.name;
    EXPECT_LE(automatic.suspect, best.suspect + kShareTolerance) << spec.name;
  }
}

// The known texels with the answers along the automatic cage's own rays: the line from each
// texel's low-poly point through its cage point (the interpolated cage corners).
std::vector<procedural::KnownTexel> along_cage_rays(const procedural::HardAsset& a, std::vector<procedural::KnownTexel> known,
                                                    const std::vector<glm::vec3>& cage) {
  for (procedural::KnownTexel& kt : known) {
    glm::dvec3 p(0.0), pc(0.0);
    for (int c = 0; c < 3; ++c) {
      p += kt.b[c] * glm::dvec3(a.low.corner_position(kt.tri, c));
      pc += kt.b[c] * glm::dvec3(cage[a.low.position_index[3 * std::size_t(kt.tri) + std::size_t(c)]]);
    }
    if (glm::length(pc - p) > 1e-9) kt.normal = procedural::known_normal(a, p, glm::normalize(pc - p), kt.part);
  }
  return known;
}

// Known answer: close rippled tubes (hard_assets.h) over hexagonal prisms of two rings: the
// prisms' faces lie 0.0067 inside the tubes, farther than half the 0.004 gap between them, their
// corners on them. Every texel's normal is the analytic normal where its ray crosses its own tube
// (no miss, no other surface): the automatic cage's rays, within 0.25 degrees on average and 1%
// over 1 degree; the fixed distances' (along the ray normals) for comparison.
TEST(ThinParts, CoarsePrismUnderCloseTubesGetsTheAnalyticNormals) {
  const procedural::HardAsset a = procedural::make_close_tubes(0.004, 0.0, 6, 2, 96, 48);
  const std::vector<procedural::KnownTexel> known = procedural::known_texels(a, 256);
  auto bake = [&](const char* label, float distance) {
    BakeOptions o;
    o.width = o.height = 256;
    o.padding = 0;
    o.front = o.rear = distance;
    const BakeResult r = bake_normal_map(a.low, a.high, nullptr, o);
    const procedural::KnownErrors e =
        procedural::measure_against_known(a, r.cage_positions.empty() ? known : along_cage_rays(a, known, r.cage_positions), r);
    std::printf("measured: prism %s mean %.4f deg, over 1 deg %.3f%%, worst %.2f deg, texels %zu, misses %llu\n", label,
                e.mean_deg, 100.0 * e.over1, e.worst_deg, e.texels, (unsigned long long)r.stats.trace.misses);
    return std::pair{e, r.stats.trace.misses};
  };
  for (float d : {0.01f, 0.02f}) bake(("fixed " + std::to_string(d)).c_str(), d);
  const auto [e, misses] = bake("automatic", -1.0f);
  EXPECT_GT(e.texels, 30000u);
  EXPECT_EQ(misses, 0u);
  EXPECT_EQ(e.other_surface, 0u);
  EXPECT_LE(e.mean_deg, 0.25);
  EXPECT_LE(e.over1, 0.01);
}

}  // namespace
}  // namespace nmbake
