// nmview's overlays (issue 36, item 2): nmbake's miss and suspect masks painted on the low-poly,
// the cage drawn as a wireframe, and the UV view (the map flat under the UV edges). A generated pair with a known wrong region:
// the low-poly is the 2 x 2 plane at z = 0 facing +Z (UV = (x + 1) / 2, (y + 1) / 2), the high-poly covers only its left half (x
// <= 0, at z = 0.01), so every ray of the right half (u > 0.5) misses; the cage is the plane grown to 2.4 x 2.4 at z = 0.1.
// nmbake bakes it with --cage, --miss-mask,
// --suspect-mask and --report, and nmview (headless, llvmpipe, as test_nmview.cpp) renders it
// from the front with the light from the eye, so every pixel has a known answer.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/image.h"
#include "io/image_io.h"
#include "overlays.h"
#include "test_support.h"
#include "tool_run.h"
#include "view.h"
#include "build_paths.h"

namespace {

namespace fs = std::filesystem;
using nmbake::test::contains;
using nmbake::test::scratch_dir;
using nmbake::test::write_file;
using nmview::test::quote;

constexpr int kOverlayPane = 128;         // screenshots are 2 panes of kOverlayPane x kOverlayPane
constexpr double kOverlayLit = 0.8;       // the lit plane facing the eye and the light (test_nmview_set.cpp)
constexpr double kOverlayHighZ = 0.01;    // the high-poly's height over the low-poly
constexpr double kOverlayCageHalf = 1.2;  // the cage's half width

struct OverlayScene {
  std::string dir, low, high, cage, map, miss, suspect, report;
};

// The pair, its cage and nmbake's bake of it (32 x 32: the masks' texels are 1/32 of the UV square).
const OverlayScene& overlay_scene() {
  static const OverlayScene scene = [] {
    OverlayScene s;
    s.dir = scratch_dir();
    s.low = s.dir + "/low.obj";
    s.high = s.dir + "/half_high.obj";
    s.cage = s.dir + "/cage.obj";
    s.map = s.dir + "/normal.png";
    s.miss = s.dir + "/miss.png";
    s.suspect = s.dir + "/suspect.png";
    s.report = s.dir + "/report.json";
    write_file(s.low,
               "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
               "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n");
    write_file(s.high, "v -1 -1 0.01\nv 0 -1 0.01\nv 0 1 0.01\nv -1 1 0.01\nvn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n");
    write_file(s.cage,
               "v -1.2 -1.2 0.1\nv 1.2 -1.2 0.1\nv 1.2 1.2 0.1\nv -1.2 1.2 0.1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
               "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n");
    // Run in the scene's folder with relative names, so the report names its files relative to its
    // own folder (the tests' current folder is another).
    const std::string bake_command = "cd " + quote(s.dir) + " && " + quote(nmbake::build::nmbake_exe()) +
                                     " low.obj half_high.obj --cage cage.obj -o normal.png --size 32 --miss-mask miss.png "
                                     "--suspect-mask suspect.png --report report.json --no-warnings";
    const nmview::test::ToolRun bake = nmview::test::run_tool(s.dir, "/bin/sh", "-c " + quote(bake_command));
    EXPECT_EQ(bake.exit_code, 0) << bake.err;
    return s;
  }();
  return scene;
}

struct OverlayColour {
  int r = 0, g = 0, b = 0;
};

struct OverlayShot {
  int width = 0, height = 0;
  std::vector<OverlayColour> pixels;
  OverlayColour at(int x, int y) const { return pixels[std::size_t(y) * std::size_t(width) + std::size_t(x)]; }
};

// nmview LOW MAP HIGH --screenshot from the front, light from the eye, no labels, `options` added.
OverlayShot overlay_render(const std::string& name, const std::string& options, int expected_exit = 0) {
  const OverlayScene& s = overlay_scene();
  const std::string shot = s.dir + "/" + name + ".png";
  const nmview::test::ToolRun r = nmview::test::nmview(
      s.dir, quote(s.low) + " " + quote(s.map) + " " + quote(s.high) + " --screenshot " + quote(shot) + " --size " +
                 std::to_string(2 * kOverlayPane) + "x" + std::to_string(kOverlayPane) + " --view 0,0 --light 0,0 " + options);
  EXPECT_EQ(r.exit_code, expected_exit) << r.err;
  if (r.exit_code != 0) return {};
  const nmbake::Image image = nmbake::read_image(shot);
  OverlayShot out{image.width, image.height, {}};
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const float* p = image.at(x, y);
      out.pixels.push_back({int(std::lround(p[0] * 255.0f)), int(std::lround(p[1] * 255.0f)), int(std::lround(p[2] * 255.0f))});
    }
  return out;
}

// Where object-space point (x, y, z) lands in the left pane (column, row from the top): the scene is
// re-centred on the centre of the union of both meshes' boxes and framed by its bounding sphere.
std::pair<int, int> overlay_pixel(double x, double y, double z) {
  const double centre_z = 0.5 * kOverlayHighZ;
  const float radius = float(std::sqrt(2.0 + centre_z * centre_z));
  const nmview::CameraMatrices m = nmview::camera_matrices({0.0f, 0.0f, 1.0f}, {}, radius, 1.0f);
  const glm::vec4 clip = m.projection * m.view * glm::vec4(float(x), float(y), float(z - centre_z), 1.0f);
  const double px = (clip.x / clip.w * 0.5 + 0.5) * kOverlayPane, py = (1.0 - (clip.y / clip.w * 0.5 + 0.5)) * kOverlayPane;
  return {int(std::floor(px)), int(std::floor(py))};
}

std::pair<int, int> overlay_pixel_of_uv(double u, double v) { return overlay_pixel(2 * u - 1, 2 * v - 1, 0.0); }

// The lit plane under paint of `colour` at coverage `a`, in 8-bit steps.
OverlayColour painted(glm::vec3 colour, double a) {
  auto channel = [&](float c) { return int(std::lround(255.0 * (kOverlayLit * (1.0 - a) + double(c) * a))); };
  return {channel(colour.r), channel(colour.g), channel(colour.b)};
}

void expect_colour(const OverlayColour& got, const OverlayColour& want, const std::string& where) {
  EXPECT_NEAR(got.r, want.r, 3) << where;
  EXPECT_NEAR(got.g, want.g, 3) << where;
  EXPECT_NEAR(got.b, want.b, 3) << where;
}

// The plain render (no overlay shown, the report's loaded), made once for the tests that compare with it.
const OverlayShot& overlay_plain_shot() {
  static const OverlayShot shot = overlay_render("plain", "--report " + quote(overlay_scene().report) + " --show nolabels");
  return shot;
}

const double kSamples[] = {0.1, 0.2, 0.3, 0.4, 0.6, 0.7, 0.8, 0.9};

TEST(NmviewOverlays, BakeMissesTheRightHalf) {
  const OverlayScene& s = overlay_scene();
  const nmbake::Image miss = nmbake::read_image(s.miss);
  ASSERT_EQ(miss.width, 32);
  // Image column x is u = (x + 0.5) / 32: every texel right of the middle missed, none left of it.
  for (int y = 0; y < miss.height; ++y)
    for (int x = 0; x < miss.width; ++x) EXPECT_NEAR(miss.at(x, y)[0], x >= 16 ? 1.0f : 0.0f, 1e-3f) << x << "," << y;
}

TEST(NmviewOverlays, ReportsMissedHalfPaintedMagenta) {
  const OverlayScene& s = overlay_scene();
  const OverlayShot with = overlay_render("masks", "--report " + quote(s.report) + " --show nolabels,masks");
  const OverlayShot& without = overlay_plain_shot();
  ASSERT_FALSE(with.pixels.empty());
  ASSERT_FALSE(without.pixels.empty());
  const OverlayColour grey = painted({0.0f, 0.0f, 0.0f}, 0.0);
  const OverlayColour magenta = painted(nmview::kMissColour, nmview::kMaskStrength);
  for (double u : kSamples)
    for (double v : kSamples) {
      const auto [x, y] = overlay_pixel_of_uv(u, v);
      const std::string where = "uv " + std::to_string(u) + "," + std::to_string(v);
      expect_colour(with.at(x, y), u > 0.5 ? magenta : grey, where);
      expect_colour(without.at(x, y), grey, where + " (masks off)");
    }
}

TEST(NmviewOverlays, SuspectsOrangeAndMissesOverThem) {
  // Synthetic masks of other sizes: suspects on the top half (v > 0.5, image rows 0..7 of 16),
  // misses on the right half of a 4 x 4 image.
  const OverlayScene& s = overlay_scene();
  const std::string dir = scratch_dir();
  nmbake::Image suspect(16, 16, 1), miss(4, 4, 1);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) suspect.at(x, y)[0] = y < 8 ? 1.0f : 0.0f;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) miss.at(x, y)[0] = x >= 2 ? 1.0f : 0.0f;
  nmbake::write_image(dir + "/suspect.png", suspect);
  nmbake::write_image(dir + "/miss.png", miss);
  const OverlayShot shot =
      overlay_render("synthetic", "--suspect-mask " + quote(dir + "/suspect.png") + " --miss-mask " + quote(dir + "/miss.png") +
                                      " --report " + quote(s.report) + " --show nolabels,masks");
  ASSERT_FALSE(shot.pixels.empty());
  const double k = nmview::kMaskStrength, both = k + k * (1.0 - k);
  const glm::vec3 both_colour = (nmview::kMissColour * float(k) + nmview::kSuspectColour * float(k * (1.0 - k))) / float(both);
  for (double u : kSamples)
    for (double v : kSamples) {
      const auto [x, y] = overlay_pixel_of_uv(u, v);
      const OverlayColour want = u > 0.5 && v > 0.5 ? painted(both_colour, both)
                                 : u > 0.5          ? painted(nmview::kMissColour, k)
                                 : v > 0.5          ? painted(nmview::kSuspectColour, k)
                                                    : painted({0.0f, 0.0f, 0.0f}, 0.0);
      expect_colour(shot.at(x, y), want, "uv " + std::to_string(u) + "," + std::to_string(v));
    }
}

bool is_cage_green(const OverlayColour& c) { return c.g > 150 && c.r < 110 && c.b < 110; }

TEST(NmviewOverlays, CageEdgesDrawnAroundTheModel) {
  const OverlayScene& s = overlay_scene();
  const OverlayShot with = overlay_render("cage", "--report " + quote(s.report) + " --show nolabels,cage");
  const OverlayShot& without = overlay_plain_shot();
  ASSERT_FALSE(with.pixels.empty());
  ASSERT_FALSE(without.pixels.empty());
  // The low-poly's footprint in the left pane, grown by 2 pixels; the cage's outline 1.2 / 1 as far out.
  const auto [left, top] = overlay_pixel(-1.0, 1.0, 0.0);
  const auto [right, bottom] = overlay_pixel(1.0, -1.0, 0.0);
  const auto [cage_left, cage_top] = overlay_pixel(-kOverlayCageHalf, kOverlayCageHalf, 0.1);
  int outside_with = 0, outside_without = 0, right_pane = 0;
  for (int y = 0; y < with.height; ++y)
    for (int x = 0; x < with.width; ++x) {
      const bool in_left = x < kOverlayPane;
      const bool outside = x < left - 2 || x > right + 2 || y < top - 2 || y > bottom + 2;
      if (in_left && outside && is_cage_green(with.at(x, y))) ++outside_with;
      if (in_left && outside && is_cage_green(without.at(x, y))) ++outside_without;
      if (!in_left && is_cage_green(with.at(x, y))) ++right_pane;
    }
  // Four sides of about (right - left) * 1.2 pixels each, at least one pixel wide.
  EXPECT_GT(outside_with, 3 * (right - left)) << "cage outline at " << cage_left << "," << cage_top;
  EXPECT_EQ(outside_without, 0);
  EXPECT_EQ(right_pane, 0) << "the cage is drawn over the low-poly pane only";
  // The outline's top-left corner is green (within a pixel).
  bool corner = false;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) corner = corner || is_cage_green(with.at(cage_left + dx, cage_top + dy));
  EXPECT_TRUE(corner);
}

// The UV view's pixel of (u, v) in the left pane (column, row from the top): the UV square fills
// the square pane, v up.
std::pair<int, int> overlay_uv_view_pixel(double u, double v) {
  const nmview::UvSquare square = nmview::uv_square(kOverlayPane, kOverlayPane);
  return {square.x + int(std::floor(u * square.side)), kOverlayPane - 1 - (square.y + int(std::floor(v * square.side)))};
}

TEST(NmviewOverlays, UvViewShowsTheMapUnderItsEdgesAndMasks) {
  const OverlayScene& s = overlay_scene();
  const OverlayShot shot = overlay_render("uv", "--report " + quote(s.report) + " --show nolabels,uv,masks");
  ASSERT_FALSE(shot.pixels.empty());
  // The map's texel at (u, v) in 8-bit steps (image row 0 is v = 1).
  const nmbake::Image map = nmbake::read_image(s.map);
  auto texel = [&](double u, double v) {
    const float* p = map.at(int(u * map.width), int((1.0 - v) * map.height));
    return glm::vec3(p[0], p[1], p[2]);
  };
  auto over = [](glm::vec3 under, glm::vec3 paint, double a) {
    auto channel = [&](float b, float c) { return int(std::lround(255.0 * (double(b) * (1.0 - a) + double(c) * a))); };
    return OverlayColour{channel(under.r, paint.r), channel(under.g, paint.g), channel(under.b, paint.b)};
  };
  // Off the two triangles' edges (the square's sides and its diagonal u = v): the map's texel, the
  // missed right half painted.
  for (double u : kSamples)
    for (double v : kSamples) {
      if (std::abs(u - v) < 0.15) continue;
      const auto [x, y] = overlay_uv_view_pixel(u, v);
      const OverlayColour want =
          u > 0.5 ? over(texel(u, v), nmview::kMissColour, nmview::kMaskStrength) : over(texel(u, v), {}, 0.0);
      expect_colour(shot.at(x, y), want, "uv " + std::to_string(u) + "," + std::to_string(v));
    }
  // On the diagonal, within a pixel: the edge's white over the map, at least half of it (a 1-pixel
  // line's multisampled coverage of a pixel varies); only the left half, whose map is unpainted.
  for (double t : {0.1, 0.2, 0.3, 0.4}) {
    const auto [x, y] = overlay_uv_view_pixel(t, t);
    const OverlayColour map_colour = over(texel(t + 0.05, t - 0.05), {}, 0.0);
    const OverlayColour full = over(texel(t + 0.05, t - 0.05), glm::vec3(nmview::kUvEdgeColour), double(nmview::kUvEdgeColour.a));
    int brightest = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) brightest = std::max(brightest, shot.at(x + dx, y + dy).r);
    EXPECT_GE(brightest - map_colour.r, (full.r - map_colour.r) / 2) << "near uv " << t << "," << t;
  }
}

TEST(NmviewOverlays, OptionErrorsSayWhatIsMissing) {
  const OverlayScene& s = overlay_scene();
  const std::string files = quote(s.low) + " " + quote(s.map) + " " + quote(s.high);
  const std::string shot = " --screenshot " + quote(s.dir + "/error.png");
  auto run = [&](const std::string& options) { return nmview::test::nmview(s.dir, files + shot + " " + options); };

  nmview::test::ToolRun r = run("--show masks");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "--show masks: no mask given")) << r.err;

  // A report of a bake with its own automatic cage names none.
  const std::string plain_report = s.dir + "/plain_report.json";
  write_file(plain_report, R"({"options": {"cage": null, "miss_mask": null, "suspect_mask": null}})");
  r = run("--report " + quote(plain_report) + " --show cage");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "--show cage: no cage given")) << r.err;
  EXPECT_TRUE(contains(r.err, "--save-cage")) << r.err;

  r = run("--report " + quote(s.map) + " --show masks");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "not JSON")) << r.err;

  const std::string lost_report = s.dir + "/lost_report.json";
  write_file(lost_report, R"({"options": {"miss_mask": "gone/miss.png"}})");
  r = run("--report " + quote(lost_report));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "names the miss mask 'gone/miss.png', found neither")) << r.err;

  r = run("--miss-mask " + quote(s.dir + "/no_such_mask.png") + " --show masks");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_TRUE(contains(r.err, "no_such_mask.png")) << r.err;

  r = nmview::test::nmview(s.dir, files + " --screenshot " + quote(s.miss) + " --report " + quote(s.report));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "is the same file as")) << r.err;

  r = run("--show masks,bogus");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(contains(r.err, "masks, cage, uv")) << r.err;
}

TEST(OverlayUnits, UniqueEdgesOfTwoTriangles) {
  // A quad's two triangles share the diagonal 0-2: five edges, each once, lower index first.
  const std::vector<std::uint32_t> edges = nmview::unique_edges({0, 1, 2, 0, 2, 3});
  EXPECT_EQ(edges, (std::vector<std::uint32_t>{0, 1, 0, 2, 0, 3, 1, 2, 2, 3}));
  // A degenerate triangle's repeated corner adds no zero-length edge.
  EXPECT_EQ(nmview::unique_edges({4, 4, 5}), (std::vector<std::uint32_t>{4, 5}));
}

TEST(OverlayUnits, ReportPathsFromTheCurrentFolderElseBesideTheReport) {
  const OverlayScene& s = overlay_scene();
  const nmview::OverlayFiles found = nmview::read_report_overlays(s.report);
  EXPECT_EQ(fs::weakly_canonical(found.miss_mask), fs::weakly_canonical(s.miss));
  EXPECT_EQ(fs::weakly_canonical(found.suspect_mask), fs::weakly_canonical(s.suspect));
  EXPECT_EQ(fs::weakly_canonical(found.cage), fs::weakly_canonical(s.cage));
  // The options win over the report; the report fills the rest.
  nmview::OverlayFiles given;
  given.miss_mask = "mine.png";
  const nmview::OverlayFiles merged = nmview::merge_overlay_files(given, found);
  EXPECT_EQ(merged.miss_mask, "mine.png");
  EXPECT_EQ(merged.cage, found.cage);
  EXPECT_THROW(nmview::read_report_overlays(s.dir + "/none.json"), nmbake::InputError);
  // A bake with the automatic cage and --save-cage names no cage but the saved one: that is drawn.
  const std::string saved = s.dir + "/saved_cage_report.json";
  std::ofstream(saved) << R"({"options": {"cage": null, "miss_mask": null, "save_cage": ")" << s.cage << R"("}})";
  EXPECT_EQ(fs::weakly_canonical(nmview::read_report_overlays(saved).cage), fs::weakly_canonical(s.cage));
}

}  // namespace
