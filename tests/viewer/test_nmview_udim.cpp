// nmview and UDIM tiles (issue 36, item 3): a map path with <UDIM> loads every tile on disk and each
// face samples its own tile; a face whose tile has no file is drawn magenta with one warning; a
// pattern with no tile is one error. The real binary runs headless as in test_nmview_set.cpp.
//
// The scene: a 2 x 2 plane at z = 0 facing +Z, its left half (x < 0) in tile 1001 (u = x + 1) and
// its right half in tile 1002 (u = x + 1 too, so 1..2), v = (y + 1) / 2; the reference is the same
// plane with u halved (one tile) and one map holding the two tiles' texels side by side. With the
// same texels over the same surface the screenshots agree everywhere but within a texel of the seam,
// where the single map filters across it and the tiles clamp to their edges.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/image.h"
#include "io/image_io.h"
#include "test_support.h"
#include "texture_set.h"
#include "tool_run.h"
#include "udim_tiles.h"
#include "view.h"

namespace nmview_udim_test {

namespace fs = std::filesystem;
using nmbake::test::contains;
using nmbake::test::scratch_dir;
using nmbake::test::write_file;
using nmview::test::error_line;
using nmview::test::quote;

constexpr int kUdimPane = 128;  // screenshots are panes of kUdimPane x kUdimPane
constexpr int kTileTexels = 16;

// The plane in two tiles (u_scale 1) or in one (u_scale 0.5).
std::string write_two_tile_plane(const std::string& path, double u_scale) {
  std::ostringstream obj;
  obj << "v -1 -1 0\nv 0 -1 0\nv 1 -1 0\nv -1 1 0\nv 0 1 0\nv 1 1 0\n";
  for (int row = 0; row < 2; ++row)
    for (int column = 0; column < 3; ++column) obj << "vt " << column * u_scale << " " << row << "\n";
  obj << "vn 0 0 1\n"  // vertex i has UV i: the seam's vertices 2 and 5 are shared at u = 1 (or 0.5)
         "f 1/1/1 2/2/1 5/5/1\nf 1/1/1 5/5/1 4/4/1\n"
         "f 2/2/1 3/3/1 6/6/1\nf 2/2/1 6/6/1 5/5/1\n";
  write_file(path, obj.str());
  return path;
}

// Tile `tile`'s texel (x, y) (row 0 = v = 1) as a unit normal: each tile tilts differently, both
// vary across the tile, so a face that samples the wrong tile or the wrong place shows it.
glm::dvec3 tile_normal(int tile, int x, int y) {
  const double sx = 2.0 * (x + 0.5) / kTileTexels - 1.0, sy = 2.0 * (y + 0.5) / kTileTexels - 1.0;
  const glm::dvec3 n = tile == 0 ? glm::dvec3(0.55 * sx, 0.2 * sy, 1.0) : glm::dvec3(0.6 - 0.2 * sx, 0.5 * sy, 1.0);
  return glm::normalize(n);
}

void put_normal(nmbake::Image& map, int x, int y, glm::dvec3 n) {
  for (int c = 0; c < 3; ++c) map.at(x, y)[c] = float(std::round((n[c] * 0.5 + 0.5) * 255.0) / 255.0);
}

// Tile `tile` (0: 1001, 1: 1002) alone, `size` texels a side (kTileTexels for the others).
void write_tile(const std::string& path, int tile, int size = kTileTexels) {
  nmbake::Image map(size, size, 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) put_normal(map, x, y, tile_normal(tile, x % kTileTexels, y % kTileTexels));
  nmbake::write_image(path, map);
}

// Both tiles side by side in one map, for the one-tile plane.
void write_joined_tiles(const std::string& path) {
  nmbake::Image map(2 * kTileTexels, kTileTexels, 3);
  for (int y = 0; y < kTileTexels; ++y)
    for (int x = 0; x < 2 * kTileTexels; ++x) put_normal(map, x, y, tile_normal(x / kTileTexels, x % kTileTexels, y));
  nmbake::write_image(path, map);
}

struct UdimScene {
  std::string dir, two_tiles, one_tile, pattern;
};

// The two planes, tiles 1001 and 1002 as tile.<UDIM>.png and the joined map as joined.png.
UdimScene make_udim_scene() {
  UdimScene s;
  s.dir = scratch_dir();
  s.two_tiles = write_two_tile_plane(s.dir + "/two_tiles.obj", 1.0);
  s.one_tile = write_two_tile_plane(s.dir + "/one_tile.obj", 0.5);
  s.pattern = s.dir + "/tile.<UDIM>.png";
  write_tile(s.dir + "/tile.1001.png", 0);
  write_tile(s.dir + "/tile.1002.png", 1);
  write_joined_tiles(s.dir + "/joined.png");
  return s;
}

struct Screenshot {
  int width = 0, height = 0;
  std::vector<int> rgb;  // 8-bit
  const int* at(int x, int y) const { return &rgb[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 3]; }
};

struct ViewRun {
  nmview::test::ToolRun run;
  Screenshot shot;
};

// nmview LOW MAP LOW (the plane is its own high-poly) at the front, `panes` panes.
ViewRun view_plane(const UdimScene& s, const std::string& low, const std::string& map, const std::string& name,
                   const std::string& show = "", int panes = 2) {
  ViewRun v;
  const std::string shot = s.dir + "/" + name + ".png";
  v.run = nmview::test::nmview(s.dir, quote(low) + " " + quote(map) + " " + quote(s.one_tile) + " --screenshot " + quote(shot) +
                                          " --size " + std::to_string(panes * kUdimPane) + "x" + std::to_string(kUdimPane) +
                                          " --view 0,0 --show nolabels" + (show.empty() ? "" : "," + show));
  if (v.run.exit_code != 0) return v;
  const nmbake::Image image = nmbake::read_image(shot);
  v.shot.width = image.width;
  v.shot.height = image.height;
  for (float value : image.pixels) v.shot.rgb.push_back(int(std::lround(value * 255.0f)));
  return v;
}

// Where object point (x, y, 0) of the plane lands in a pane (column, row from the top).
std::pair<int, int> pane_pixel(double x, double y) {
  // The camera frames the bounding sphere of both meshes: the plane's, radius sqrt 2.
  const nmview::CameraMatrices m = nmview::camera_matrices({0.0f, 0.0f, 1.0f}, {}, std::sqrt(2.0f), 1.0f);
  const glm::vec4 clip = m.projection * m.view * glm::vec4(float(x), float(y), 0.0f, 1.0f);
  return {int(std::floor((clip.x / clip.w * 0.5 + 0.5) * kUdimPane)),
          int(std::floor((1.0 - (clip.y / clip.w * 0.5 + 0.5)) * kUdimPane))};
}

// Pane `pane`'s largest channel difference between two screenshots over the plane, leaving out
// the pixels within `band` pixels of its seam (x = 0) and of its outer edges, where a single map
// repeats (the edge texels filter with the opposite side's) and a tile clamps; `count` gets the
// pixels over 2 steps.
int pane_difference(const Screenshot& a, const Screenshot& b, int pane, int band, int& count) {
  const auto [x0, y0] = pane_pixel(-1.0, 1.0);
  const auto [x1, y1] = pane_pixel(1.0, -1.0);
  const int seam_x = pane_pixel(0.0, 0.0).first;
  int worst = 0;
  count = 0;
  for (int y = y0 + band; y <= y1 - band; ++y)
    for (int x = x0 + band; x <= x1 - band; ++x) {
      if (std::abs(x - seam_x) <= band) continue;
      int d = 0;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(a.at(pane * kUdimPane + x, y)[c] - b.at(pane * kUdimPane + x, y)[c]));
      worst = std::max(worst, d);
      count += d > 2;
    }
  return worst;
}

bool is_missing_colour(const int* c) { return c[0] == 255 && c[1] == 0 && c[2] == 255; }

// Lines of stderr holding `word`.
int lines_with(const std::string& err, const std::string& word) {
  std::istringstream in(err);
  int n = 0;
  for (std::string line; std::getline(in, line);) n += contains(line, word);
  return n;
}

TEST(NmviewUdim, TilesMatchTheSameTexelsInOneMap) {
  const UdimScene s = make_udim_scene();
  const ViewRun udim = view_plane(s, s.two_tiles, s.pattern, "udim", "diff", 3);
  const ViewRun single = view_plane(s, s.one_tile, s.dir + "/joined.png", "single", "diff", 3);
  ASSERT_EQ(udim.run.exit_code, 0) << udim.run.err;
  ASSERT_EQ(single.run.exit_code, 0) << single.run.err;
  EXPECT_TRUE(contains(udim.run.err, "tile.<UDIM>.png: UDIM tiles 1001, 1002")) << udim.run.err;
  EXPECT_EQ(lines_with(udim.run.err, "warning"), 0) << udim.run.err;
  // A texel is about 2.4 pixels here: two texels either side of the seam and inside the edges are
  // left out. Lit pane and difference pane alike; the high-poly's pane is the same plane.
  const int texel_pixels = (pane_pixel(1.0, 0.0).first - pane_pixel(0.0, 0.0).first) / kTileTexels;
  EXPECT_GE(texel_pixels, 2);
  for (int pane : {0, 1, 2}) {
    int count = 0;
    EXPECT_LE(pane_difference(udim.shot, single.shot, pane, 2 * texel_pixels, count), 3) << "pane " << pane;
    EXPECT_EQ(count, 0) << "pane " << pane;
  }
  // The control: the first tile alone, as before <UDIM>, repeats over the right half, which then
  // differs; the left half does not.
  const ViewRun first = view_plane(s, s.two_tiles, s.dir + "/tile.1001.png", "first_only", "diff", 3);
  ASSERT_EQ(first.run.exit_code, 0) << first.run.err;
  EXPECT_TRUE(contains(first.run.err, "2 of the low-poly's triangles lie beyond the unit UV square (UDIM tiles 1002)"))
      << first.run.err;
  EXPECT_TRUE(contains(first.run.err, "(" + s.dir + "/tile.<UDIM>.png)")) << first.run.err;
  int count = 0;
  EXPECT_GT(pane_difference(first.shot, single.shot, 0, 2 * texel_pixels, count), 20);
  EXPECT_GT(count, kUdimPane * kUdimPane / 8);
  const auto [right_x, right_y] = pane_pixel(0.5, 0.0);
  const auto [left_x, left_y] = pane_pixel(-0.5, 0.0);
  EXPECT_NE(std::vector<int>(first.shot.at(right_x, right_y), first.shot.at(right_x, right_y) + 3),
            std::vector<int>(single.shot.at(right_x, right_y), single.shot.at(right_x, right_y) + 3));
  EXPECT_EQ(std::vector<int>(first.shot.at(left_x, left_y), first.shot.at(left_x, left_y) + 3),
            std::vector<int>(single.shot.at(left_x, left_y), single.shot.at(left_x, left_y) + 3));
}

// --compare's last line's `name=` value.
double compare_field(const std::string& out, const std::string& name) {
  std::string last = out;
  while (!last.empty() && last.back() == '\n') last.pop_back();
  last = last.substr(last.rfind('\n') + 1);
  const std::size_t at = last.find(" " + name + "=");
  EXPECT_NE(at, std::string::npos) << name << " in: " << last;
  return at == std::string::npos ? -1.0 : std::atof(last.c_str() + at + name.size() + 2);
}

TEST(NmviewUdim, CompareReadsEachFacesTile) {
  const UdimScene s = make_udim_scene();
  const auto compare = [&](const std::string& low, const std::string& map) {
    return nmview::test::nmview(s.dir, quote(low) + " " + quote(map) + " " + quote(s.one_tile) + " --compare --size 128x64");
  };
  const nmview::test::ToolRun udim = compare(s.two_tiles, s.pattern);
  const nmview::test::ToolRun single = compare(s.one_tile, s.dir + "/joined.png");
  const nmview::test::ToolRun first = compare(s.two_tiles, s.dir + "/tile.1001.png");
  ASSERT_EQ(udim.exit_code, 0) << udim.err;
  ASSERT_EQ(single.exit_code, 0) << single.err;
  ASSERT_EQ(first.exit_code, 0) << first.err;
  // The high-poly is the flat plane, so the angle is the maps' tilt: the same texels give the same
  // mean but for the seam's few pixels; the first tile repeated gives another.
  const double a = compare_field(udim.out, "angle_mean"), b = compare_field(single.out, "angle_mean");
  const double c = compare_field(first.out, "angle_mean");
  std::printf("angle_mean: udim %.3f, one map %.3f, first tile only %.3f\n", a, b, c);
  EXPECT_GT(b, 5.0);
  EXPECT_NEAR(a, b, 0.01 * b);
  EXPECT_GT(std::abs(c - b), 0.2 * b);
}

TEST(NmviewUdim, MissingTileIsMagentaWithOneWarning) {
  const UdimScene s = make_udim_scene();
  fs::remove(s.dir + "/tile.1002.png");
  const ViewRun v = view_plane(s, s.two_tiles, s.pattern, "missing", "diff", 3);
  ASSERT_EQ(v.run.exit_code, 0) << v.run.err;
  EXPECT_EQ(lines_with(v.run.err, "warning"), 1) << v.run.err;
  EXPECT_TRUE(contains(v.run.err, "warning: " + s.pattern +
                                      ": no file for the UDIM tile(s) 1002 (2 triangles); their faces "
                                      "are drawn magenta, unlit"))
      << v.run.err;
  // The right half is magenta in the lit pane and in the difference pane, the left half in neither.
  for (double x : {0.2, 0.5, 0.8})
    for (double y : {-0.6, 0.0, 0.6}) {
      const auto [px, py] = pane_pixel(x, y);
      const auto [qx, qy] = pane_pixel(-x, y);
      EXPECT_TRUE(is_missing_colour(v.shot.at(px, py))) << x << "," << y;
      EXPECT_TRUE(is_missing_colour(v.shot.at(2 * kUdimPane + px, py))) << x << "," << y;
      EXPECT_FALSE(is_missing_colour(v.shot.at(qx, qy))) << -x << "," << y;
      EXPECT_FALSE(is_missing_colour(v.shot.at(2 * kUdimPane + qx, qy))) << -x << "," << y;
    }
  // Without the map (--no-map) nothing is missing: the right half is lit like the left.
  const nmview::test::ToolRun bare =
      nmview::test::nmview(s.dir, quote(s.two_tiles) + " " + quote(s.pattern) + " " + quote(s.one_tile) + " --screenshot " +
                                      quote(s.dir + "/bare.png") + " --size 256x128 --view 0,0 --show nolabels --no-map");
  ASSERT_EQ(bare.exit_code, 0) << bare.err;
  const nmbake::Image image = nmbake::read_image(s.dir + "/bare.png");
  const auto [px, py] = pane_pixel(0.5, 0.0);
  const auto [qx, qy] = pane_pixel(-0.5, 0.0);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(image.at(px, py)[c], image.at(qx, qy)[c]) << c;
}

TEST(NmviewUdim, PatternWithoutTilesIsOneError) {
  const UdimScene s = make_udim_scene();
  const std::string pattern = s.dir + "/none.<UDIM>.png";
  const ViewRun v = view_plane(s, s.two_tiles, pattern, "none");
  EXPECT_EQ(v.run.exit_code, 2) << v.run.err;  // as a missing map
  EXPECT_EQ(error_line(v.run.err), "error: " + pattern + ": no UDIM tile exists (<UDIM> replaced by 1001 to 2000: " + s.dir +
                                       "/none.1001.png, " + s.dir + "/none.1002.png, ...)");
  EXPECT_FALSE(fs::exists(s.dir + "/none.png"));
  // Tiles of two sizes are refused, naming both.
  write_tile(s.dir + "/tile.1002.png", 1, 2 * kTileTexels);
  const ViewRun sizes = view_plane(s, s.two_tiles, s.pattern, "sizes");
  EXPECT_EQ(sizes.run.exit_code, 2) << sizes.run.err;
  EXPECT_EQ(error_line(sizes.run.err), "error: " + s.dir + "/tile.1002.png is 32x32 but " + s.dir +
                                           "/tile.1001.png is 16x16; every UDIM tile of a map must have one size (bake "
                                           "them with one --size)");
}

TEST(NmviewUdim, BakedTileSetIsFoundAndShown) {
  // nmbake's own tiles and set (names and metadata as it writes them) through <MAP> and <UDIM>.
  const UdimScene s = make_udim_scene();
  const nmbake::test::CliRun bake = nmbake::test::run_nmbake(
      quote(s.two_tiles) + " " + quote(s.two_tiles) + " -o 'b_<MAP>.<UDIM>.png' --maps normal,ao --size 16 --ao-rays 2 --quiet",
      "", s.dir);
  ASSERT_EQ(bake.code, 0) << bake.err;
  const ViewRun v = view_plane(s, s.two_tiles, s.dir + "/b_<MAP>.<UDIM>.png", "baked", "ao");
  ASSERT_EQ(v.run.exit_code, 0) << v.run.err;
  EXPECT_TRUE(contains(v.run.err, "UDIM tiles normal 1001, 1002; ao 1001, 1002")) << v.run.err;
  EXPECT_EQ(lines_with(v.run.err, "warning"), 0) << v.run.err;
  // A plane alone is open to the sky: AO 1 on both tiles, shown unlit as white.
  for (double x : {-0.5, 0.5}) {
    const auto [px, py] = pane_pixel(x, 0.0);
    for (int c = 0; c < 3; ++c) EXPECT_GE(v.shot.at(px, py)[c], 250) << x;
  }
  // The ao map's second tile missing: its faces are left without AO, magenta where it is shown.
  fs::remove(s.dir + "/b_ao.1002.png");
  const ViewRun no_ao = view_plane(s, s.two_tiles, s.dir + "/b_<MAP>.<UDIM>.png", "no_ao", "ao");
  ASSERT_EQ(no_ao.run.exit_code, 0) << no_ao.run.err;
  EXPECT_EQ(lines_with(no_ao.run.err, "warning"), 1) << no_ao.run.err;
  EXPECT_TRUE(contains(no_ao.run.err, "no file for the UDIM tile(s) ao 1002 (2 triangles)")) << no_ao.run.err;
  EXPECT_TRUE(is_missing_colour(no_ao.shot.at(pane_pixel(0.5, 0.0).first, pane_pixel(0.5, 0.0).second)));
  EXPECT_FALSE(is_missing_colour(no_ao.shot.at(pane_pixel(-0.5, 0.0).first, pane_pixel(-0.5, 0.0).second)));
}

TEST(NmviewUdim, TileRulesAsTheBaker) {
  // The centroid's tile, as nmbake's pipeline/udim.cpp: an edge belongs to the tile above it.
  EXPECT_EQ(nmview::udim_cell({0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}), 0);
  EXPECT_EQ(nmview::udim_cell({1.0f, 0.0f}, {2.0f, 0.0f}, {2.0f, 1.0f}), 1);
  EXPECT_EQ(nmview::udim_cell({0.5f, 1.0f}, {0.5f, 1.0f}, {0.5f, 1.0f}), 10);
  EXPECT_EQ(nmview::udim_cell({9.5f, 99.5f}, {9.6f, 99.5f}, {9.5f, 99.6f}), 999);
  EXPECT_EQ(nmview::udim_cell({-0.5f, 0.5f}, {0.2f, 0.5f}, {0.2f, 0.6f}), -1);
  EXPECT_EQ(nmview::udim_cell({10.5f, 0.5f}, {10.6f, 0.5f}, {10.5f, 0.6f}), -1);
  EXPECT_EQ(nmview::udim_cell({NAN, 0.5f}, {0.2f, 0.5f}, {0.2f, 0.6f}), -1);
  EXPECT_EQ(nmview::udim_tile_path("a.<UDIM>/b.<UDIM>.png", 1011), "a.1011/b.1011.png");

  const std::string dir = scratch_dir();
  for (const char* name : {"t.1001.png", "t.1012.png", "t.2000.png", "t.1000.png", "t.2001.png", "t.01001.png", "t.x.png"})
    write_file(dir + "/" + name, "x");
  const std::vector<nmview::UdimTileFile> files = nmview::find_udim_files(dir + "/t.<UDIM>.png");
  std::vector<int> numbers;
  for (const nmview::UdimTileFile& f : files) numbers.push_back(f.number);
  EXPECT_EQ(numbers, (std::vector<int>{1001, 1012, 2000}));
  EXPECT_EQ(files[1].path, dir + "/t.1012.png");

  const nmview::UdimUse use = nmview::count_udim_use({0, 0, 1, 11, -1, 11});
  EXPECT_EQ(use.outside, 1u);
  const std::vector<int> missing = nmview::missing_udim_tiles(use, {1001});
  EXPECT_EQ(missing, (std::vector<int>{1002, 1012}));
  EXPECT_EQ(nmview::describe_missing_tiles(use, missing), "1002 (1 triangle), 1012 (2 triangles)");

  // <UDIM> and <MAP> together: each member is found through its tiles.
  write_file(dir + "/c_normal.1001.png", "x");
  write_file(dir + "/c_ao.1002.png", "x");
  const nmview::TextureSetFiles set = nmview::find_texture_set(dir + "/c_<MAP>.<UDIM>.png");
  EXPECT_TRUE(set.udim);
  ASSERT_EQ(set.found.size(), 2u);
  EXPECT_EQ(set.found[1].path, dir + "/c_ao.<UDIM>.png");
  ASSERT_EQ(set.found[1].tiles.size(), 1u);
  EXPECT_EQ(set.found[1].tiles[0].number, 1002);
}

TEST(NmviewUdim, PaneLabelNamesTheTileRange) {
  EXPECT_EQ(nmview::udim_range_label({1001, 1002, 1003, 1004}), "MAP 1001-1004");
  EXPECT_EQ(nmview::udim_range_label({1004, 1001, 1003, 1002}), "MAP 1001-1004");  // any order
  EXPECT_EQ(nmview::udim_range_label({1001, 1002, 1011}), "MAP 1001-1011, 3 TILES");
  EXPECT_EQ(nmview::udim_range_label({1002}), "MAP 1002");
  EXPECT_EQ(nmview::udim_range_label({}), "");
}

}  // namespace nmview_udim_test
