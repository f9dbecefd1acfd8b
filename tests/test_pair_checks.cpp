// A user's common mistakes with the pair of meshes (issue 34, items 3-5): meshes that do not lie in
// one place or differ greatly in size (a unit mismatch), UVs stacked many layers deep (tiled UVs),
// and LOW and HIGH given the wrong way round. The known answers are the boxes and UV layouts the
// tests build; the command refuses (exit 2, one line naming both files) or warns as the README says.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "cli/pair_checks.h"
#include "core/normals.h"
#include "core/uv_overlap.h"
#include "io/mesh_io.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::contains;
using test::run_nmbake;

Mesh transformed(Mesh m, float scale, glm::vec3 shift) {
  for (glm::vec3& p : m.positions) p = p * scale + shift;
  return m;
}

// Every UV moved by (du, dv) and scaled by s about the origin.
Mesh uv_moved(Mesh m, float s, float du, float dv) {
  for (glm::vec2& uv : m.uvs) uv = uv * s + glm::vec2(du, dv);
  return m;
}

// a's triangles followed by b's.
Mesh joined(const Mesh& a, const Mesh& b) { return merge_meshes({a, b}); }

// UVs repeating k times along u: each triangle's u times k, less the whole tiles of its centroid
// (a UV per corner).
Mesh tiled_uvs(Mesh m, int k) {
  std::vector<glm::vec2> uvs;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const float cu = (m.corner_uv(t, 0).x + m.corner_uv(t, 1).x + m.corner_uv(t, 2).x) / 3.0f * float(k);
    for (int c = 0; c < 3; ++c) uvs.push_back({m.corner_uv(t, c).x * float(k) - std::floor(cu), m.corner_uv(t, c).y});
  }
  m.uvs = uvs;
  for (std::size_t i = 0; i < m.uv_index.size(); ++i) m.uv_index[i] = std::uint32_t(i);
  return m;
}

void write_obj(const std::string& path, const Mesh& m) { std::ofstream(path) << obj_text(m, "test_pair_checks"); }

TEST(PairBoxes, SameBoxesMatch) {
  const Mesh low = test::make_torus(24, 12), high = test::make_torus(96, 48);
  const PairBoxes b = compare_boxes(low, high);
  EXPECT_EQ(b.mismatch, PairBoxes::Mismatch::none);
  EXPECT_NEAR(b.size_ratio, 1.0, 0.02);
  EXPECT_DOUBLE_EQ(b.overlap, 1.0);
}

TEST(PairBoxes, HundredTimesTheSizeIsAUnitMismatch) {
  const Mesh low = test::make_torus(24, 12), high = transformed(test::make_torus(96, 48), 100.0f, {0, 0, 0});
  const PairBoxes b = compare_boxes(low, high);
  EXPECT_EQ(b.mismatch, PairBoxes::Mismatch::size);
  EXPECT_NEAR(b.size_ratio, 100.0, 3.0);
  const std::string text = mismatch_text(b, "low.obj", "high.obj", false);
  EXPECT_TRUE(contains(text, "high.obj (HIGH) is ")) << text;
  EXPECT_TRUE(contains(text, "low.obj (LOW)")) << text;
  EXPECT_TRUE(contains(text, "centimetres against metres")) << text;
  EXPECT_TRUE(contains(text, "--allow-mismatch")) << text;
  EXPECT_EQ(text.find('\n'), std::string::npos);
  // Nine times the size is still one scene (a head against a whole figure).
  EXPECT_EQ(compare_boxes(low, transformed(low, 9.0f, {0, 0, 0})).mismatch, PairBoxes::Mismatch::none);
  // And the other way round: a low-poly 1000 times the high-poly's size.
  const PairBoxes mm = compare_boxes(transformed(low, 1000.0f, {0, 0, 0}), low);
  EXPECT_EQ(mm.mismatch, PairBoxes::Mismatch::size);
  EXPECT_TRUE(contains(mismatch_text(mm, "low.obj", "high.obj", false), "millimetres against metres"));
}

TEST(PairBoxes, MovedAwayLiesApart) {
  const Mesh low = test::make_torus(24, 12);
  // Moved by twice its width: apart; by a tenth: still one place.
  const PairBoxes far = compare_boxes(low, transformed(low, 1.0f, {5.0f, 0, 0}));
  EXPECT_EQ(far.mismatch, PairBoxes::Mismatch::apart);
  EXPECT_DOUBLE_EQ(far.overlap, 0.0);
  EXPECT_TRUE(contains(mismatch_text(far, "l.obj", "h.obj", false), "do not lie in one place"));
  EXPECT_EQ(compare_boxes(low, transformed(low, 1.0f, {0.27f, 0, 0})).mismatch, PairBoxes::Mismatch::none);
  // Moved by most of its width along one axis: they share under a quarter of it.
  EXPECT_EQ(compare_boxes(low, transformed(low, 1.0f, {2.2f, 0, 0})).mismatch, PairBoxes::Mismatch::apart);
}

TEST(PairBoxes, CoordinatesBeyondTheRayTracerAreLeftToTheBake) {
  // The bake refuses them with its own line (test_hostile_geometry); no mismatch is claimed here.
  const Mesh low = test::make_torus(24, 12);
  EXPECT_EQ(compare_boxes(low, transformed(low, 1e18f, {0, 0, 0})).mismatch, PairBoxes::Mismatch::none);
}

TEST(PairBoxes, FlatLowOverAReliefIsOnePlace) {
  // A plane low-poly floating just above a relief that lies wholly below it (disjoint boxes by a
  // hair) and a small detail high-poly inside a big low-poly's box are legal bakes.
  const Mesh plane = transformed(test::make_grid(4, 4), 1.0f, {0, 0, 0.01f});
  Mesh relief = test::make_height_field(
      32, 32, [](double x, double y) { return -0.05 - 0.05 * std::sin(3 * x) * std::cos(3 * y); },
      [](double, double) { return glm::dvec3(0, 0, 1); });
  EXPECT_EQ(compare_boxes(plane, relief).mismatch, PairBoxes::Mismatch::none);
  const Mesh bolt = transformed(test::make_torus(24, 12), 0.2f, {0.3f, 0.3f, 0.0f});
  EXPECT_EQ(compare_boxes(plane, bolt).mismatch, PairBoxes::Mismatch::none);
}

TEST(UvOverlap, LayoutWithoutOverlapCountsNone) {
  const UvOverlap o = measure_uv_overlap(test::make_torus(32, 16), 128, 128, false);
  EXPECT_EQ(o.covered, 128u * 128u);  // the torus's UVs tile the square exactly
  EXPECT_EQ(o.overlapped, 0u);
  EXPECT_DOUBLE_EQ(o.mean_layers(), 1.0);
}

TEST(UvOverlap, StackedHalvesAndTiledUvs) {
  const Mesh grid = uv_moved(test::make_grid(8, 8), 0.5f, 0.25f, 0.25f);  // the middle quarter of the map
  // Mirrored halves stacked: two layers everywhere they cover, none three deep; allowed.
  const UvOverlap two = measure_uv_overlap(joined(grid, grid), 64, 64, false);
  EXPECT_EQ(two.covered, 32u * 32u);
  EXPECT_EQ(two.overlapped, two.covered);
  EXPECT_EQ(two.stacked, 0u);
  EXPECT_DOUBLE_EQ(two.mean_layers(), 2.0);
  EXPECT_FALSE(overlap_refused(two));
  EXPECT_TRUE(contains(overlap_text(two, 1024, "low.obj", true), "100.0% of the covered texels lie under more than one"));
  // Five copies: tiled, refused.
  Mesh five = grid;
  for (int k = 0; k < 4; ++k) five = joined(five, grid);
  const UvOverlap tiled = measure_uv_overlap(five, 64, 64, false);
  EXPECT_DOUBLE_EQ(tiled.mean_layers(), 5.0);
  EXPECT_DOUBLE_EQ(tiled.stacked_share(), 1.0);
  EXPECT_TRUE(overlap_refused(tiled));
  EXPECT_TRUE(contains(overlap_text(tiled, 0, "low.obj", false), "--allow-overlap"));
  // A small stacked part (one copy of a sixteenth of the layout three deep) is warned of, not refused.
  const Mesh part = uv_moved(test::make_grid(2, 2), 0.1f, 0.3f, 0.3f);
  const UvOverlap small = measure_uv_overlap(joined(joined(grid, part), part), 64, 64, false);
  EXPECT_GT(small.stacked, 0u);
  EXPECT_LT(small.stacked_share(), kStackedShareRefuse);
  EXPECT_FALSE(overlap_refused(small));
}

TEST(UvOverlap, UdimTilesDoNotOverlapEachOther) {
  const Mesh grid = test::make_grid(8, 8);
  const Mesh tiles = joined(grid, uv_moved(grid, 1.0f, 1.0f, 0.0f));  // tiles 1001 and 1002
  const UvOverlap udim = measure_uv_overlap(tiles, 32, 32, true);
  EXPECT_EQ(udim.covered, 2u * 32u * 32u);
  EXPECT_EQ(udim.overlapped, 0u);
  // Without UDIM only the unit square counts: the second tile lies outside it.
  const UvOverlap unit = measure_uv_overlap(tiles, 32, 32, false);
  EXPECT_EQ(unit.covered, 32u * 32u);
  EXPECT_EQ(unit.overlapped, 0u);
  // Stacked in one tile they do overlap.
  EXPECT_EQ(measure_uv_overlap(joined(grid, grid), 32, 32, true).overlapped, 32u * 32u);
}

TEST(UvOverlap, CountsDoNotDependOnThreads) {
  Mesh five = test::make_torus(16, 8);
  for (int k = 0; k < 2; ++k) five = joined(five, uv_moved(test::make_torus(16, 8), 0.7f, 0.1f * float(k), 0.2f));
  const UvOverlap one = measure_uv_overlap(five, 100, 70, false, 1), many = measure_uv_overlap(five, 100, 70, false, 3);
  EXPECT_EQ(one.covered, many.covered);
  EXPECT_EQ(one.overlapped, many.overlapped);
  EXPECT_EQ(one.stacked, many.stacked);
  EXPECT_EQ(one.layers, many.layers);
}

TEST(SwapWarning, LowWithManyMoreTrianglesThanHigh) {
  const auto w = swap_warning(46080, 480, true, "sculpt.obj", "low.obj");
  ASSERT_TRUE(w);
  EXPECT_TRUE(contains(*w, "sculpt.obj (LOW) has 46,080 triangles and low.obj (HIGH) 480")) << *w;
  EXPECT_TRUE(contains(*w, "wrong way round")) << *w;
  EXPECT_FALSE(swap_warning(46080, 480, false, "sculpt.obj", "low.obj"));  // a HIGH without UVs is no low-poly
  EXPECT_FALSE(swap_warning(6144, 98304, true, "low.obj", "high.ply"));
  EXPECT_FALSE(swap_warning(1000, 500, true, "low.obj", "high.ply"));  // twice: a coarse high-poly, not a swap
}

// The command: refused with exit 2 and one line, nothing written; baked with the flag and warned.
TEST(PairChecksCli, ScaledHighIsRefusedNamingBothBoxes) {
  const std::string dir = test::scratch_dir();
  write_obj(dir + "/low.obj", test::make_torus(24, 12));
  write_obj(dir + "/high_cm.obj", transformed(test::make_torus(96, 48), 100.0f, {0, 0, 0}));
  const test::CliRun refused = run_nmbake("low.obj high_cm.obj -o n.png --size 64 --report r.json", "", dir);
  EXPECT_EQ(refused.code, 2);
  EXPECT_TRUE(contains(refused.err, "error: high_cm.obj (HIGH) is ")) << refused.err;
  EXPECT_TRUE(contains(refused.err, "LOW's box is (")) << refused.err;
  EXPECT_TRUE(contains(refused.err, "HIGH's (")) << refused.err;
  EXPECT_FALSE(contains(refused.err, "inverted")) << refused.err;
  EXPECT_FALSE(contains(refused.err, "--front/--rear")) << refused.err;
  EXPECT_FALSE(test::exists(dir + "/n.png"));
  EXPECT_FALSE(test::exists(dir + "/r.json"));
  const test::CliRun baked = run_nmbake("low.obj high_cm.obj -o n.png --size 64 --report r.json --allow-mismatch", "", dir);
  EXPECT_EQ(baked.code, 0);
  EXPECT_TRUE(test::exists(dir + "/n.png"));
  EXPECT_TRUE(contains(baked.err, "baked anyway: --allow-mismatch")) << baked.err;
  EXPECT_FALSE(contains(baked.err, "check --front/--rear")) << baked.err;
  EXPECT_EQ(baked.report["pair"]["mismatch"], "size");
  EXPECT_GT(baked.report["pair"]["size_ratio"].get<double>(), 90.0);
}

TEST(PairChecksCli, MovedHighIsRefused) {
  const std::string dir = test::scratch_dir();
  write_obj(dir + "/low.obj", test::make_torus(24, 12));
  write_obj(dir + "/high.obj", transformed(test::make_torus(96, 48), 1.0f, {0, 10.0f, 0}));
  const test::CliRun refused = run_nmbake("low.obj high.obj -o n.png --size 64", "", dir);
  EXPECT_EQ(refused.code, 2);
  EXPECT_TRUE(contains(refused.err, "error: low.obj (LOW) and high.obj (HIGH) do not lie in one place")) << refused.err;
  EXPECT_EQ(std::count(refused.err.begin(), refused.err.end(), '\n'), 1) << refused.err;
  // Batch jobs take the flag as their option too.
  test::write_file(
      dir + "/jobs.json",
      R"({"jobs": [{"low": "low.obj", "high": "high.obj", "output": "b.png", "options": {"size": 32, "allow-mismatch": true}}]})");
  EXPECT_EQ(run_nmbake("--batch jobs.json --quiet", "", dir).code, 0);
  EXPECT_TRUE(test::exists(dir + "/b.png"));
}

TEST(PairChecksCli, TiledUvsAreRefusedAndStackedHalvesWarned) {
  const std::string dir = test::scratch_dir();
  const Mesh torus = test::make_torus(24, 12);
  // UVs for a texture tiling 6 times around the ring: each sixth of it covers the whole square.
  write_obj(dir + "/tiled.obj", tiled_uvs(torus, 6));
  write_obj(dir + "/high.obj", test::make_torus(96, 48));
  const test::CliRun refused = run_nmbake("tiled.obj high.obj -o n.png --size 64", "", dir);
  EXPECT_EQ(refused.code, 2);
  EXPECT_TRUE(contains(refused.err, "tiled.obj (LOW): its UVs lie")) << refused.err;
  EXPECT_TRUE(contains(refused.err, "--allow-overlap")) << refused.err;
  EXPECT_FALSE(test::exists(dir + "/n.png"));
  const test::CliRun allowed = run_nmbake("tiled.obj high.obj -o n.png --size 64 --allow-overlap --report r.json", "", dir);
  EXPECT_EQ(allowed.code, 0);
  EXPECT_GT(allowed.report["uv_overlap"]["stacked_share"].get<double>(), 0.9);
  EXPECT_NEAR(allowed.report["uv_overlap"]["mean_layers"].get<double>(), 6.0, 0.5);
  // Mirrored halves stacked: baked, with one warning giving the share.
  Mesh half = torus;
  for (glm::vec2& uv : half.uvs) uv.x = uv.x < 0.5f ? uv.x : 1.0f - uv.x;
  write_obj(dir + "/halves.obj", half);
  const test::CliRun halves = run_nmbake("halves.obj high.obj -o h.png --size 64 --report r.json", "", dir);
  EXPECT_EQ(halves.code, 0);
  EXPECT_TRUE(contains(halves.err, "UV islands overlap (")) << halves.err;
  EXPECT_TRUE(contains(halves.err, "100.0% of the covered texels lie under more than one triangle (2.00 layers")) << halves.err;
  EXPECT_NEAR(halves.report["uv_overlap"]["share"].get<double>(), 1.0, 0.05);
  EXPECT_LT(halves.report["uv_overlap"]["stacked_share"].get<double>(), kStackedShareRefuse);
}

TEST(PairChecksCli, SwappedLowAndHighAreNamed) {
  const std::string dir = test::scratch_dir();
  write_obj(dir + "/dense.obj", test::make_torus(96, 48));   // 9,216 triangles, with UVs
  write_obj(dir + "/coarse.obj", test::make_torus(24, 12));  // 576
  const test::CliRun swapped = run_nmbake("dense.obj coarse.obj -o n.png --size 64 --report r.json", "", dir);
  EXPECT_EQ(swapped.code, 0);
  EXPECT_TRUE(contains(swapped.err, "dense.obj (LOW) has 9,216 triangles and coarse.obj (HIGH) 576")) << swapped.err;
  EXPECT_EQ(run_nmbake("dense.obj coarse.obj -o n.png --size 64 --strict", "", dir).code, 5);
  // A LOW without UVs (the sculpt given first): the error says which role it had.
  Mesh sculpt = test::make_torus(96, 48);
  sculpt.uvs.clear();
  sculpt.uv_index.clear();
  write_obj(dir + "/sculpt.obj", sculpt);
  const test::CliRun no_uvs = run_nmbake("sculpt.obj coarse.obj -o n.png --size 64", "", dir);
  EXPECT_EQ(no_uvs.code, 2);
  EXPECT_TRUE(contains(no_uvs.err, "has no UVs (given as LOW")) << no_uvs.err;
  EXPECT_TRUE(contains(no_uvs.err, "nmbake LOW HIGH")) << no_uvs.err;
  // Other errors name the role too.
  test::write_file(dir + "/broken.obj", "v 0 0 0\nf 1 2 3\n");
  const test::CliRun broken = run_nmbake("coarse.obj broken.obj -o n.png --size 64", "", dir);
  EXPECT_EQ(broken.code, 2);
  EXPECT_TRUE(contains(broken.err, "(given as HIGH)")) << broken.err;
}

}  // namespace
}  // namespace nmbake
