// Robust hits on hard assets (tests/procedural/hard_assets.h), with default options: close parts
// with a bulge that forces a long reach, a thin shell, a rod in a bore, a bevelled box, a
// high-poly with flipped winding. Each baked texel is compared with the exact normal of the
// analytic surface its ray should land on (the part the texel's low-poly triangle belongs to).
#include <cmath>
#include <fstream>
#include <map>

#include <gtest/gtest.h>

#include "pipeline/bake.h"
#include "hard_asset_answers.h"
#include "hard_assets.h"
#include "io/mesh_io.h"
#include "test_support.h"

using namespace nmbake;
using procedural::HardAsset;
using test::angle_deg;

namespace {

using test::bake_options;

using Errors = procedural::KnownErrors;

// The baked map's angular error against the analytic answer, over the covered texel centres of
// the low-poly triangles whose part is in `parts` (all when empty).
Errors measure(const HardAsset& a, const BakeResult& r, const std::vector<int>& parts = {}) {
  return procedural::measure_against_known(a, procedural::known_texels(a, r.map.width), r, parts);
}

void record(const std::string& name, const Errors& e, const BakeResult& r) {
  std::printf(
      "measured: %s mean %.4f deg, over 1 deg %.3f%%, over 60 deg %zu, worst %.2f deg, texels %zu, misses %llu, "
      "backface_skips %llu, front %.4g-%.4g, rear %.4g-%.4g\n",
      name.c_str(), e.mean_deg, 100.0 * e.over1, e.over60_texels, e.worst_deg, e.texels, (unsigned long long)r.stats.trace.misses,
      (unsigned long long)r.stats.trace.backface_skips, r.stats.distances.vertex_front.min, r.stats.distances.vertex_front.max,
      r.stats.distances.vertex_rear.min, r.stats.distances.vertex_rear.max);
}

}  // namespace

TEST(RobustHits, CloseTubesWithABulgeBakeCleanByDefault) {
  // Gaps down to a tenth of the bulge: a global distance long enough for the bulge reaches into
  // the next tube; the automatic cage does not.
  for (const auto& [gap, bulge] : {std::pair{0.012, 0.04}, std::pair{0.004, 0.04}, std::pair{0.012, 0.14}}) {
    const HardAsset a = procedural::make_close_tubes(gap, bulge);
    const BakeResult r = bake_normal_map(a.low, a.high, nullptr, bake_options(512));
    const Errors e = measure(a, r);
    record(a.name, e, r);
    EXPECT_EQ(r.stats.distances.cage, BakeStats::CageSource::automatic);
    EXPECT_GT(e.texels, 50000u);
    EXPECT_LE(e.mean_deg, 0.25) << a.name;
    EXPECT_LE(e.over1, 0.005) << a.name;
    EXPECT_EQ(e.over60_texels, 0u) << a.name;
    EXPECT_EQ(e.other_surface, 0u) << a.name;
  }
}

TEST(RobustHits, ThinShellTakesNoNormalFromTheOtherSide) {
  const HardAsset a = procedural::make_thin_shell();
  const BakeResult r = bake_normal_map(a.low, a.high, nullptr, bake_options(512));
  const Errors faces = measure(a, r, {0, 1});
  record(a.name + " faces", faces, r);
  EXPECT_GT(faces.texels, 30000u);
  EXPECT_EQ(faces.other_surface, 0u);
  EXPECT_EQ(faces.over60_texels, 0u);
  EXPECT_LE(faces.mean_deg, 0.25);
  const Errors all = measure(a, r);
  record(a.name + " all", all, r);
  EXPECT_EQ(all.other_surface, 0u);
}

TEST(RobustHits, RodInABoreTakesNoNormalFromTheOtherPart) {
  const HardAsset a = procedural::make_cavity();
  const BakeResult r = bake_normal_map(a.low, a.high, nullptr, bake_options(512));
  const Errors e = measure(a, r);
  record(a.name, e, r);
  EXPECT_GT(e.texels, 50000u);
  EXPECT_EQ(e.other_surface, 0u);
  EXPECT_LE(double(e.over60_texels), 1e-4 * double(e.texels));  // the sharp edges of the pipe's end rings
  EXPECT_LE(e.mean_deg, 0.25);
}

TEST(RobustHits, BevelledBoxFollowsTheBevels) {
  const HardAsset a = procedural::make_bevelled_box();
  const BakeResult r = bake_normal_map(a.low, a.high, nullptr, bake_options(512));
  const Errors e = measure(a, r);
  record(a.name, e, r);
  EXPECT_GT(e.texels, 50000u);
  EXPECT_EQ(e.over60_texels, 0u);
  EXPECT_LE(e.mean_deg, 0.25);
  EXPECT_EQ(r.stats.trace.misses, 0u);
}

TEST(RobustHits, FlippedWindingBakesLikeTheSoundMesh) {
  // A broken export: the high-poly wound the other way, with its (outward) normals kept, or
  // without normals (they are computed, inverted, from the winding; the probes find it inverted).
  const HardAsset sound = procedural::make_thin_shell();
  const BakeResult ref = bake_normal_map(sound.low, sound.high, nullptr, bake_options(256));
  for (bool keep_normals : {true, false}) {
    const HardAsset a = procedural::flip_high_winding(sound, keep_normals);
    const BakeResult r = bake_normal_map(a.low, a.high, nullptr, bake_options(256));
    const Errors e = measure(a, r, {0, 1});
    record(a.name, e, r);
    EXPECT_EQ(r.stats.distances.high_facing, keep_normals ? BakeStats::HighFacing::sound : BakeStats::HighFacing::inverted)
        << a.name;
    EXPECT_TRUE(r.stats.distances.backfaces_skipped);
    EXPECT_EQ(e.other_surface, 0u) << a.name;
    EXPECT_LE(e.mean_deg, 0.3) << a.name;
    if (keep_normals) {
      EXPECT_TRUE(r.map.pixels == ref.map.pixels) << "the same map as the sound mesh's";
    }
  }
}

TEST(RobustHits, SuspectTexelsAreCountedAndMasked) {
  // Rays from one tube into the next (back faces kept, one global distance long enough for the
  // bulge) tilt whole stripes of texels: suspect. The default bake has next to none.
  const HardAsset a = procedural::make_close_tubes(0.012, 0.04);
  BakeOptions o = bake_options(256);
  o.suspect_mask = true;
  o.samples = 4;
  const BakeResult r = bake_normal_map(a.low, a.high, nullptr, o);
  o.keep_backfaces = true;
  o.front = o.rear = 0.06f;
  const BakeResult bad = bake_normal_map(a.low, a.high, nullptr, o);
  std::printf("measured: suspect share default %.4f%%, back faces kept with --front/--rear 0.06 %.2f%%\n",
              100.0 * r.stats.pad.suspect_share, 100.0 * bad.stats.pad.suspect_share);
  EXPECT_LT(r.stats.pad.suspect_share, kSuspectShareWarn);
  EXPECT_GT(bad.stats.pad.suspect_share, 0.05);
  for (const BakeResult* b : {&r, &bad}) {
    ASSERT_EQ(b->suspect_mask.width, 256);
    std::size_t ones = 0, outside = 0;
    for (std::size_t i = 0; i < b->suspect_mask.pixels.size(); ++i) {
      ones += b->suspect_mask.pixels[i] == 1.0f;
      outside += b->suspect_mask.pixels[i] != 0.0f && !b->coverage[i];
    }
    EXPECT_EQ(ones, b->stats.pad.suspect_texels);
    EXPECT_EQ(outside, 0u);
    EXPECT_EQ(b->stats.pad.suspect_share, double(b->stats.pad.suspect_texels) / double(b->stats.trace.texels_covered));
  }
  // Every texel facing away is suspect; the region holds the most of them of its 8 x 8 grid.
  EXPECT_GE(bad.stats.pad.suspect_texels, bad.stats.pad.texels_facing_away);
  EXPECT_GT(bad.stats.pad.suspect_region_share, 1.0 / 64.0);
  EXPECT_DOUBLE_EQ(bad.stats.pad.suspect_region[2] - bad.stats.pad.suspect_region[0], 0.125);
  EXPECT_DOUBLE_EQ(bad.stats.pad.suspect_region[3] - bad.stats.pad.suspect_region[1], 0.125);
}

TEST(RobustHits, SamplesThatDisagreeMakeATexelSuspect) {
  // A plane whose two halves are tilted 50 degrees either way, seen from a flat low-poly: texels
  // on the crease have samples on both halves; their mean is short (cos 50 = 0.64 < 0.8).
  Mesh low = test::make_grid(1, 1);
  Mesh high = test::make_grid(128, 8);  // a vertex column at x = 1/64, the middle of texel column 32
  const double tilt = 50.0 * 3.14159265358979323846 / 180.0;
  for (glm::vec3& p : high.positions) p.z = float(std::abs(p.x - 1.0 / 64.0) * std::tan(tilt));
  // A sharp crease: each side's triangles carry its own normal.
  high.normals = {glm::vec3(-std::sin(tilt), 0, std::cos(tilt)), glm::vec3(std::sin(tilt), 0, std::cos(tilt))};
  high.normal_index.clear();
  for (std::size_t t = 0; t < high.triangle_count(); ++t) {
    const float cx = high.corner_position(t, 0).x + high.corner_position(t, 1).x + high.corner_position(t, 2).x;
    for (int c = 0; c < 3; ++c) high.normal_index.push_back(cx > 3.0f / 64.0f ? 1u : 0u);
  }
  BakeOptions o = bake_options(64);
  o.samples = 16;
  o.front = o.rear = 2.0f;
  o.suspect_mask = true;
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  // Column 32 straddles the crease: half its samples on each side.
  std::size_t crease = 0;
  for (int y = 0; y < 64; ++y) crease += r.suspect_mask.at(32, y)[0] == 1.0f;
  std::printf("measured: crease texels suspect %zu of 64, all suspect %zu\n", crease, r.stats.pad.suspect_texels);
  EXPECT_EQ(r.stats.pad.texels_facing_away, 0u);
  EXPECT_EQ(crease, 64u);
  EXPECT_EQ(r.stats.pad.suspect_texels, crease);
  // With one sample per texel nothing can disagree.
  o.samples = 1;
  EXPECT_EQ(bake_normal_map(low, high, nullptr, o).stats.pad.suspect_texels, 0u);
}

TEST(RobustHits, SculptsHaveAlmostNoTexelFacingAway) {
  // ../shared/data/sculpts with default options: at most 0.1% of covered texels facing away
  // (earlier nmbake: 0.69% on suz_L3 and 0.82% on suz_L4 at 1024^2, the Suzannes' eye rims).
  int baked = 0;
  for (const char* name : {"suz_L3", "suz_L4", "torus_demo", "torus_s3"}) {
    const std::string dir = test::shared_data_path(std::string("sculpts/") + name);
    if (!test::exists(dir + "/high.ply")) continue;
    LoadOptions lo;
    lo.require_uvs = true;
    const Mesh low = load_mesh(dir + "/low.obj", lo), high = load_mesh(dir + "/high.ply");
    BakeOptions o = bake_options(1024);
    const BakeResult r = bake_normal_map(low, high, nullptr, o);
    const double share = double(r.stats.pad.texels_facing_away) / double(r.stats.trace.texels_covered);
    std::printf("measured: %s facing away %zu of %zu (%.4f%%), suspect %.4f%%, misses %llu of %llu samples\n", name,
                r.stats.pad.texels_facing_away, r.stats.trace.texels_covered, 100.0 * share, 100.0 * r.stats.pad.suspect_share,
                (unsigned long long)r.stats.trace.misses, (unsigned long long)r.stats.trace.samples_covered);
    EXPECT_LE(share, 0.001) << name;
    EXPECT_LE(double(r.stats.trace.misses), 0.001 * double(r.stats.trace.samples_covered)) << name;
    ++baked;
  }
  if (!baked) GTEST_SKIP() << "../shared/data/sculpts not found";
}

TEST(RobustHits, SuspectTexelsAreWarnedAboutAndWrittenByTheCli) {
  const HardAsset a = procedural::make_close_tubes(0.012, 0.04, 24, 8, 96, 48);
  const std::string dir = test::scratch_dir();
  for (const auto& [name, mesh] : {std::pair{"low.obj", &a.low}, std::pair{"high.obj", &a.high}}) {
    std::ofstream(dir + "/" + name) << obj_text(*mesh, a.name);
  }
  const std::string files = "low.obj high.obj -o map.png --size 128 --report r.json --suspect-mask s.png";
  test::CliRun bad = test::run_nmbake(files + " --keep-backfaces --front 0.06 --rear 0.06", "", dir);
  ASSERT_EQ(bad.code, 0) << bad.err;
  EXPECT_GT(bad.report["suspect_share"].get<double>(), kSuspectShareWarn);
  EXPECT_TRUE(test::contains(bad.err,
                             "of covered texels are suspect (normal tilted over 85 degrees from the low-poly's, or samples "
                             "disagreeing)"))
      << bad.err;
  EXPECT_TRUE(test::exists(dir + "/s.png"));
  EXPECT_EQ(bad.report["options"]["suspect_mask"], "s.png");
  test::CliRun good = test::run_nmbake(files, "", dir);
  ASSERT_EQ(good.code, 0) << good.err;
  EXPECT_LT(good.report["suspect_share"].get<double>(), kSuspectShareWarn);
  EXPECT_FALSE(test::contains(good.err, "are suspect")) << good.err;
  EXPECT_EQ(good.report["cage"]["source"], "automatic");
}

TEST(RobustHits, CullingLeavesTheAutomaticCagesMapUnchanged) {
  // Rays search beyond a cage limited by a neighbouring tube as far out as the bulge: the BVH
  // must keep what they reach there.
  // A copy of the high-poly 0.1 beyond the tubes' ends, within the probes' reach but not the
  // rays': the BVH is rebuilt without it, and must not lose the bulge on the way.
  const HardAsset a = procedural::make_close_tubes(0.012, 0.14, 24, 8, 96, 48);
  Mesh high = a.high;
  const std::uint32_t np = std::uint32_t(high.positions.size()), nn = std::uint32_t(high.normals.size());
  for (const glm::vec3& p : a.high.positions) high.positions.push_back(p + glm::vec3(0.0f, 0.0f, 0.7f));
  high.normals.insert(high.normals.end(), a.high.normals.begin(), a.high.normals.end());
  for (std::uint32_t i : a.high.position_index) high.position_index.push_back(i + np);
  for (std::uint32_t i : a.high.normal_index) high.normal_index.push_back(i + nn);
  high.source_face.assign(high.triangle_count(), 0);
  BakeOptions o = bake_options(128);
  const BakeResult on = bake_normal_map(a.low, high, nullptr, o);
  o.cull_far = false;
  const BakeResult off = bake_normal_map(a.low, high, nullptr, o);
  std::printf("measured: culled %zu of %zu\n", on.stats.select.high_triangles_culled, high.triangle_count());
  EXPECT_GT(on.stats.select.high_triangles_culled, a.high.triangle_count() / 2);
  EXPECT_TRUE(on.map.pixels == off.map.pixels);
  EXPECT_EQ(on.stats.trace.hits, off.stats.trace.hits);
  EXPECT_GT(on.stats.distances.cage_front_limited, 0u);
}

TEST(RobustHits, CageStopsBeforeANeighbouringPartsHighPoly) {
  // Two facing sheets 0.1 apart: A at z = 0 facing up, B at z = 0.1 facing down, B's high-poly
  // standing 0.07 out towards A (at z = 0.03), past the half-way point. A's cage stops before it
  // (0.9 x 0.03), not at half way (0.05) nor at the scene-wide front distance B's bulge sets.
  auto sheet = [](float z, bool down, float u0) {
    Mesh m = test::make_grid(4, 4);
    for (glm::vec3& p : m.positions) p.z = z;
    for (glm::vec2& t : m.uvs) t.x = u0 + 0.45f * t.x;
    m.normals = {glm::vec3(0, 0, down ? -1.0f : 1.0f)};
    m.normal_index.assign(m.position_index.size(), 0);
    if (down)
      for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        std::swap(m.position_index[3 * t + 1], m.position_index[3 * t + 2]);
        std::swap(m.uv_index[3 * t + 1], m.uv_index[3 * t + 2]);
      }
    return m;
  };
  auto join = [](Mesh a, const Mesh& b) {
    const std::uint32_t np = std::uint32_t(a.positions.size()), nt = std::uint32_t(a.uvs.size()),
                        nn = std::uint32_t(a.normals.size());
    a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
    a.uvs.insert(a.uvs.end(), b.uvs.begin(), b.uvs.end());
    a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
    for (std::uint32_t i : b.position_index) a.position_index.push_back(i + np);
    for (std::uint32_t i : b.uv_index) a.uv_index.push_back(i + nt);
    for (std::uint32_t i : b.normal_index) a.normal_index.push_back(i + nn);
    a.source_face.assign(a.triangle_count(), 0);
    return a;
  };
  const Mesh low = join(sheet(0.0f, false, 0.0f), sheet(0.1f, true, 0.55f));
  const Mesh high = join(sheet(0.0f, false, 0.0f), sheet(0.03f, true, 0.55f));
  const BakeResult r = bake_normal_map(low, high, nullptr, bake_options(64));
  ASSERT_EQ(r.cage_positions.size(), low.positions.size());
  std::printf("measured: scene front %.4f, A's cage at z %.5f\n", r.stats.distances.scene_front, double(r.cage_positions[0].z));
  EXPECT_GT(r.stats.distances.scene_front, 0.08);
  for (std::size_t i = 0; i < 25; ++i) {  // A's vertices
    EXPECT_LE(r.cage_positions[i].z, 0.9f * 0.03f + 1e-5f) << "vertex " << i;
    EXPECT_GE(r.cage_positions[i].z, 0.02f) << "vertex " << i;
  }
  EXPECT_EQ(r.stats.trace.misses, 0u);
  EXPECT_EQ(r.stats.pad.texels_facing_away, 0u);
}
