// nmview and the texture set (issue 35): a map path with <MAP> loads every map of the set that
// exists, AO multiplies the lit render, and --show MAP draws one map unlit in its own colours.
// The real binary runs headless as in test_nmview.cpp (DISPLAY unset, LIBGL_ALWAYS_SOFTWARE=1),
// on a 2 x 2 plane at z = 0 facing +Z (UV = (x + 1) / 2, (y + 1) / 2) with maps written here, so
// that every screenshot pixel has a known answer: the pixel of a point is found with the
// viewer's own camera (view.h), and the left pane of a WxH screenshot is its left W/2 columns.
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "core/image.h"
#include "core/maps.h"
#include "interactive.h"
#include "io/image_io.h"
#include "test_support.h"
#include "tool_run.h"
#include "texture_set.h"
#include "view.h"

namespace {

namespace fs = std::filesystem;
using nmbake::MapKind;
using nmbake::test::contains;
using nmbake::test::read_file;
using nmbake::test::scratch_dir;
using nmbake::test::write_file;

constexpr int kPane = 128;  // screenshots are 2 panes of kPane x kPane

using Result = nmview::test::ToolRun;
using nmview::test::error_line;
using nmview::test::quote;

using nmview::test::nmview;

// The plane as low- and high-poly (the same file twice is fine for the viewer).
std::string write_plane(const std::string& dir) {
  const std::string path = dir + "/plane.obj";
  write_file(path,
             "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
             "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
             "vn 0 0 1\n"
             "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n");
  return path;
}

void write_flat_normal(const std::string& path) {
  nmbake::Image map(8, 8, 3);
  for (std::size_t i = 0; i < map.pixels.size(); i += 3) {
    map.pixels[i] = map.pixels[i + 1] = 128.0f / 255.0f;
    map.pixels[i + 2] = 1.0f;
  }
  nmbake::write_image(path, map);
}

// The grey value of each UV quadrant: [0] u < 0.5, v < 0.5; [1] u >= 0.5, v < 0.5; [2] u < 0.5,
// v >= 0.5; [3] u >= 0.5, v >= 0.5 (8-bit steps).
constexpr int kQuadrantValues[4] = {40, 100, 170, 230};

// A one-channel 16 x 16 map of kQuadrantValues (image row 0 is v = 1).
void write_quadrant_grey(const std::string& path, const int (&values)[4]) {
  nmbake::Image map(16, 16, 1);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x) map.at(x, y)[0] = float(values[(x >= 8 ? 1 : 0) + (y < 8 ? 2 : 0)]) / 255.0f;
  nmbake::write_image(path, map);
}

// Where UV (u, v) of the plane lands in a screenshot's left pane (column, row from the top), for
// nmview's camera at `view` framing the plane's bounding sphere (radius sqrt 2).
std::pair<int, int> pixel_of_uv(double u, double v, const nmview::OrbitView& view) {
  const nmview::CameraMatrices m = nmview::camera_matrices(view, {}, std::sqrt(2.0f), 1.0f);
  const glm::vec4 clip = m.projection * m.view * glm::vec4(float(2 * u - 1), float(2 * v - 1), 0.0f, 1.0f);
  const double x = (clip.x / clip.w * 0.5 + 0.5) * kPane, y = (1.0 - (clip.y / clip.w * 0.5 + 0.5)) * kPane;
  return {int(std::floor(x)), int(std::floor(y))};
}

struct Rgb {
  int r = 0, g = 0, b = 0;
  bool operator<(const Rgb& o) const { return std::tie(r, g, b) < std::tie(o.r, o.g, o.b); }
  bool operator==(const Rgb& o) const { return r == o.r && g == o.g && b == o.b; }
};

struct Shot {
  int width = 0, height = 0;
  std::vector<Rgb> pixels;
  Rgb at(int x, int y) const { return pixels[std::size_t(y) * std::size_t(width) + std::size_t(x)]; }
};

Shot read_shot(const std::string& path) {
  const nmbake::Image image = nmbake::read_image(path);
  Shot s{image.width, image.height, {}};
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const float* p = image.at(x, y);
      s.pixels.push_back({int(std::lround(p[0] * 255.0f)), int(std::lround(p[1] * 255.0f)), int(std::lround(p[2] * 255.0f))});
    }
  return s;
}

// A plane scene with a set written as set_<MAP>.png: the flat normal map and `extra` maps.
struct SetScene {
  std::string dir, plane, pattern;
};

SetScene make_set(const std::vector<MapKind>& extra) {
  SetScene s;
  s.dir = scratch_dir();
  s.plane = write_plane(s.dir);
  s.pattern = s.dir + "/set_<MAP>.png";
  write_flat_normal(s.dir + "/set_normal.png");
  for (MapKind k : extra) write_quadrant_grey(s.dir + "/set_" + nmbake::map_name(k) + ".png", kQuadrantValues);
  return s;
}

// `show`: --show's items beside nolabels.
Shot render(const SetScene& s, const std::string& name, const std::string& options, const std::string& show = "") {
  const std::string shot = s.dir + "/" + name + ".png";
  const Result r = nmview(s.dir, quote(s.plane) + " " + quote(s.pattern) + " " + quote(s.plane) + " --screenshot " + quote(shot) +
                                     " --size " + std::to_string(2 * kPane) + "x" + std::to_string(kPane) + " --show nolabels" +
                                     (show.empty() ? "" : "," + show) + " " + options);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (r.exit_code != 0) return {};
  std::cout << r.err;
  return read_shot(shot);
}

// Lambert of the shaders with the light from the eye on a plane facing it: 0.8 * (0.1 + 0.9).
constexpr double kLitFacing = 0.8;

TEST(NmviewSet, AoDarkensTheLitRenderByItsFactor) {
  const SetScene s = make_set({MapKind::ao});
  const nmview::OrbitView front{0.0f, 0.0f, 1.0f};
  const Shot with = render(s, "with_ao", "--view 0,0 --light 0,0");
  const Shot without = render(s, "without_ao", "--view 0,0 --light 0,0 --no-ao");
  ASSERT_FALSE(with.pixels.empty());
  ASSERT_FALSE(without.pixels.empty());
  for (int q = 0; q < 4; ++q) {
    const double u = q % 2 ? 0.75 : 0.25, v = q >= 2 ? 0.75 : 0.25;
    const auto [x, y] = pixel_of_uv(u, v, front);
    const double ao = kQuadrantValues[q] / 255.0;
    const double lit = without.at(x, y).r / 255.0, darkened = with.at(x, y).r / 255.0;
    EXPECT_NEAR(lit, kLitFacing, 1.5 / 255.0) << "quadrant " << q;
    // 8-bit AO times 8-bit shading: within 1.5 steps of the product.
    EXPECT_NEAR(darkened, kLitFacing * ao, 1.5 / 255.0) << "quadrant " << q << " ao " << ao;
    EXPECT_NEAR(darkened / lit, ao, 0.02) << "quadrant " << q;
  }
}

TEST(NmviewSet, GreyMapIsShownAsItsValues) {
  const SetScene s = make_set({MapKind::ao, MapKind::curvature});
  const nmview::OrbitView view{20.0f, 15.0f, 1.0f};
  const Shot shot = render(s, "curvature", "--view 20,15", "curvature");
  ASSERT_FALSE(shot.pixels.empty());
  for (int q = 0; q < 4; ++q) {
    const auto [x, y] = pixel_of_uv(q % 2 ? 0.75 : 0.25, q >= 2 ? 0.75 : 0.25, view);
    const Rgb c = shot.at(x, y);
    // Unlit, grey as grey, no AO: the texel's 8-bit value exactly (16-bit texture, linear output).
    EXPECT_NEAR(c.r, kQuadrantValues[q], 1) << "quadrant " << q << " at " << x << "," << y;
    EXPECT_EQ(c.g, c.r);
    EXPECT_EQ(c.b, c.r);
  }
}

// ID colours of the checker below, saturated so no background grey and no blend of two equals one.
const Rgb kIds[3] = {{230, 40, 40}, {40, 200, 60}, {30, 60, 220}};

// A 64 x 64 RGB map of one-texel cells cycling through kIds: any filtering that blends texels
// makes colours that are none of them.
void write_id_checker(const std::string& path) {
  nmbake::Image map(64, 64, 3);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const Rgb& c = kIds[(x + 2 * y) % 3];
      map.at(x, y)[0] = float(c.r) / 255.0f;
      map.at(x, y)[1] = float(c.g) / 255.0f;
      map.at(x, y)[2] = float(c.b) / 255.0f;
    }
  nmbake::write_image(path, map);
}

// Left-pane pixels: {ID colours seen with counts, pixels that are neither background nor an ID}.
std::pair<std::map<Rgb, int>, int> classify_left_pane(const Shot& shot) {
  std::map<Rgb, int> ids;
  int other = 0;
  for (int y = 0; y < shot.height; ++y)
    for (int x = 0; x < shot.width / 2; ++x) {
      const Rgb c = shot.at(x, y);
      if (std::find(std::begin(kIds), std::end(kIds), c) != std::end(kIds)) ++ids[c];
      else if (!(c.r == c.g && c.g == c.b)) ++other;  // the background is a grey gradient
    }
  return {ids, other};
}

TEST(NmviewSet, IdMapShowsOnlyItsColours) {
  SetScene s = make_set({});
  write_id_checker(s.dir + "/set_material-id.png");
  // Minified (64 texels over ~50 pixels) at an angle, so that linear filtering, mipmaps or
  // multisampled edges would all mix colours.
  const Shot shot = render(s, "ids", "--view 25,20", "material-id");
  ASSERT_FALSE(shot.pixels.empty());
  const auto [ids, other] = classify_left_pane(shot);
  EXPECT_EQ(other, 0) << "pixels of mixed colours over the model";
  ASSERT_EQ(ids.size(), 3u);
  int covered = 0;
  for (const auto& [c, n] : ids) covered += n;
  EXPECT_GT(covered, kPane * kPane / 5) << "the plane covers a good part of the pane";

  // The control: the same texels as a non-ID map (position) are filtered and anti-aliased, so the
  // check above can fail.
  fs::rename(s.dir + "/set_material-id.png", s.dir + "/set_position.png");
  const Shot blended = render(s, "blended", "--view 25,20", "position");
  ASSERT_FALSE(blended.pixels.empty());
  EXPECT_GT(classify_left_pane(blended).second, kPane * kPane / 10);
}

TEST(NmviewSet, MapTokenFindsTheSet) {
  const std::string dir = scratch_dir();
  const std::string pattern = dir + "/crate_<MAP>.png";
  for (const char* name : {"normal", "ao", "curvature", "object-id"}) write_file(dir + "/crate_" + name + ".png", "x");
  write_file(dir + "/crate_.png", "x");
  write_file(dir + "/crate_AO.png", "x");
  const nmview::TextureSetFiles files = nmview::find_texture_set(pattern);
  EXPECT_TRUE(files.has_token);
  std::vector<MapKind> found;
  for (const nmview::SetFile& f : files.found) {
    found.push_back(f.kind);
    EXPECT_EQ(f.path, dir + "/crate_" + nmbake::map_name(f.kind) + ".png");
  }
  EXPECT_EQ(found, (std::vector<MapKind>{MapKind::normal, MapKind::ao, MapKind::curvature, MapKind::object_id}));
  EXPECT_EQ(files.missing.size(), std::size_t(nmbake::kMapKinds) - 4);
  EXPECT_EQ(nmview::describe_set(files),
            "found normal, ao, curvature, object-id; not found: object-normal, bent-normal, height, thickness, position, "
            "material-id, vertex-color");
  EXPECT_NO_THROW(nmview::require_normal_map(files));
  // Without <MAP>: the one file, as the normal map, whether it exists or not.
  const nmview::TextureSetFiles single = nmview::find_texture_set(dir + "/other.png");
  ASSERT_EQ(single.found.size(), 1u);
  EXPECT_EQ(single.found[0].kind, MapKind::normal);
  EXPECT_FALSE(single.has_token);
}

TEST(NmviewSet, BakedSetIsFoundAndShown) {
  // nmbake's own set (names and metadata as it writes them), shown through <MAP>.
  const std::string dir = scratch_dir();
  const std::string plane = write_plane(dir);
  const nmbake::test::CliRun bake = nmbake::test::run_nmbake(quote(plane) + " " + quote(plane) +
                                                                 " -o 'baked_<MAP>.png' --maps normal,ao,curvature,material-id "
                                                                 "--size 32 --ao-rays 4 --quiet",
                                                             "", dir);
  ASSERT_EQ(bake.code, 0) << bake.err;
  const std::string shot = dir + "/shot.png";
  const Result r = nmview(dir, quote(plane) + " " + quote(dir + "/baked_<MAP>.png") + " " + quote(plane) + " --screenshot " +
                                   quote(shot) + " --size 64x32 --show ao");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.err, "found normal, ao, curvature, material-id; not found: object-normal")) << r.err;
  EXPECT_FALSE(contains(r.err, "warning")) << r.err;
  // The set's members are inputs: a screenshot over one is refused before anything is written.
  const std::string before = read_file(dir + "/baked_ao.png");
  const Result over = nmview(dir, quote(plane) + " " + quote(dir + "/baked_<MAP>.png") + " " + quote(plane) + " --screenshot " +
                                      quote(dir + "/baked_ao.png") + " --size 64x32");
  EXPECT_EQ(over.exit_code, 1) << over.err;
  EXPECT_TRUE(contains(error_line(over.err), "baked_ao.png is the same file as")) << over.err;
  EXPECT_EQ(read_file(dir + "/baked_ao.png"), before);
}

TEST(NmviewSet, SetWithNoMapsIsAnInputError) {
  const std::string dir = scratch_dir();
  const std::string plane = write_plane(dir);
  const std::string pattern = dir + "/none_<MAP>.png";
  const Result r =
      nmview(dir, quote(plane) + " " + quote(pattern) + " " + quote(plane) + " --screenshot " + quote(dir + "/s.png"));
  EXPECT_EQ(r.exit_code, 2) << r.err;  // as a missing map
  EXPECT_EQ(error_line(r.err), "error: " + pattern + ": no file of the texture set exists (<MAP> replaced by each of " +
                                   nmbake::map_name_list() + ": " + dir + "/none_normal.png, " + dir + "/none_ao.png, ...)");
  EXPECT_FALSE(fs::exists(dir + "/s.png"));

  // A set without its normal map: the lit render has nothing to light with.
  write_quadrant_grey(dir + "/none_ao.png", kQuadrantValues);
  const Result no_normal =
      nmview(dir, quote(plane) + " " + quote(pattern) + " " + quote(plane) + " --screenshot " + quote(dir + "/s.png"));
  EXPECT_EQ(no_normal.exit_code, 2) << no_normal.err;
  EXPECT_EQ(error_line(no_normal.err),
            "error: " + pattern + ": the set has ao but no normal map (" + dir + "/none_normal.png); the lit render needs one");
}

TEST(NmviewSet, SetMemberThatIsNotAFileIsRefused) {
  // A FIFO found for a name is a member like any other: read by the loader, which refuses it at
  // once (exit 2, as a FIFO normal map) instead of waiting for a writer.
  const SetScene s = make_set({});
  ASSERT_EQ(::mkfifo((s.dir + "/set_ao.png").c_str(), 0600), 0);
  const Result r =
      nmview(s.dir, quote(s.plane) + " " + quote(s.pattern) + " " + quote(s.plane) + " --screenshot " + quote(s.dir + "/s.png"));
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(contains(error_line(r.err), s.dir + "/set_ao.png")) << r.err;
  EXPECT_FALSE(fs::exists(s.dir + "/s.png"));
}

TEST(NmviewSet, ShowRefusesMapsNotInTheSet) {
  const SetScene s = make_set({MapKind::ao});
  const std::string shot = s.dir + "/s.png";
  const std::string inputs = quote(s.plane) + " " + quote(s.pattern) + " " + quote(s.plane) + " --screenshot " + quote(shot);
  const Result missing = nmview(s.dir, inputs + " --show height");
  EXPECT_EQ(missing.exit_code, 1) << missing.err;
  EXPECT_TRUE(contains(error_line(missing.err), "has no height map (found normal, ao; not found:")) << missing.err;
  const Result two = nmview(s.dir, inputs + " --show ao,normal");
  EXPECT_EQ(two.exit_code, 1) << two.err;
  EXPECT_TRUE(contains(error_line(two.err), "--show: ao and normal")) << two.err;
  // A plain normal map has no set: --show ao says how to give one.
  const Result plain = nmview(s.dir, quote(s.plane) + " " + quote(s.dir + "/set_normal.png") + " " + quote(s.plane) +
                                         " --screenshot " + quote(shot) + " --show ao");
  EXPECT_EQ(plain.exit_code, 1) << plain.err;
  EXPECT_TRUE(contains(error_line(plain.err), "<MAP>")) << plain.err;
  EXPECT_FALSE(fs::exists(shot));
}

TEST(NmviewSet, DisplayRgbRepeatsGreyAndFlipsRows) {
  nmbake::Image grey(2, 2, 1);
  grey.pixels = {0.1f, 0.2f, 0.3f, 0.4f};  // row 0 (v = 1): 0.1 0.2
  const std::vector<float> rgb = nmview::display_rgb(grey);
  ASSERT_EQ(rgb.size(), 12u);
  EXPECT_EQ(std::vector<float>(rgb.begin(), rgb.begin() + 6), (std::vector<float>{0.3f, 0.3f, 0.3f, 0.4f, 0.4f, 0.4f}));
  EXPECT_EQ(std::vector<float>(rgb.begin() + 6, rgb.end()), (std::vector<float>{0.1f, 0.1f, 0.1f, 0.2f, 0.2f, 0.2f}));
  nmbake::Image rgba(1, 1, 4);
  rgba.pixels = {0.5f, 0.6f, 0.7f, 0.0f};
  EXPECT_EQ(nmview::display_rgb(rgba), (std::vector<float>{0.5f, 0.6f, 0.7f}));
  EXPECT_TRUE(nmview::shown_texel_exact(MapKind::object_id));
  EXPECT_TRUE(nmview::shown_texel_exact(MapKind::material_id));
  EXPECT_FALSE(nmview::shown_texel_exact(MapKind::vertex_color));
}

TEST(NmviewSet, KeyCyclesLitThenEachMap) {
  nmview::Toggles t;
  const std::vector<MapKind> maps{MapKind::normal, MapKind::ao, MapKind::curvature};
  std::vector<std::string> seen;
  for (int i = 0; i < 5; ++i) {
    nmview::cycle_display(t, maps);
    seen.push_back(t.show_map ? nmbake::map_name(t.shown) : "lit");
  }
  EXPECT_EQ(seen, (std::vector<std::string>{"normal", "ao", "curvature", "lit", "normal"}));
}

}  // namespace
