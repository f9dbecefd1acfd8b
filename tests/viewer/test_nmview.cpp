// Runs the real nmview (and nmbake for the maps) headless, as CI does: DISPLAY and
// WAYLAND_DISPLAY unset, LIBGL_ALWAYS_SOFTWARE=1 so that EGL surfaceless renders with llvmpipe even
// on a machine with a GPU.
//
// Golden screenshots live in data/viewer/. NMBAKE_REGENERATE=1 rewrites them (the test then
// reports itself skipped). On a mismatch the actual image and a difference image (|a-b| x 8) are
// left in the test's scratch folder and named in the failure.
//
// Tolerance of the golden comparison, per 8-bit channel: mean |a-b| <= 0.5 and at most 0.5 % of
// the pixels off by more than 16. Software rendering is deterministic on one machine, but another
// Mesa/LLVM version may round shading by a unit or two (FMA contraction, different vector widths)
// and move a silhouette or wireframe edge by a pixel (rasterization and MSAA sample positions), so
// few pixels may move a lot and many may move a little; a real rendering change (a wrong sign, a
// flipped map, a moved light or camera) moves far more than that.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <sys/wait.h>

#include "core/image.h"
#include "gl_context.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "scene_maker.h"
#include "tool_run.h"
#include "test_support.h"
#include "build_paths.h"

namespace {

namespace fs = std::filesystem;
using nmbake::test::scratch_dir;

using Result = nmview::test::ToolRun;
using nmview::test::quote;

Result run(const std::string& dir, const std::string& program, const std::string& args) {
  return nmview::test::run_tool(dir, program, args);
}

using nmview::test::nmview;

void bake(const std::string& dir, const std::string& low, const std::string& high, const std::string& map,
          const std::string& options = "") {
  Result r = run(dir, nmbake::build::nmbake_exe(),
                 quote(low) + " " + quote(high) + " -o " + quote(map) + " --size 512 --quiet " + options);
  ASSERT_EQ(r.exit_code, 0) << "nmbake failed:\n" << r.out << r.err;
}

struct Summary {
  double psnr = 0, rmse = 1, within2 = 0;
};

std::string last_line(const std::string& out) {
  std::string text = out;
  while (!text.empty() && text.back() == '\n') text.pop_back();
  return text.substr(text.rfind('\n') == std::string::npos ? 0 : text.rfind('\n') + 1);
}

// The last stdout line of --compare: "psnr=<dB> rmse=<0..1> within2=<fraction> ..." (the interior).
Summary parse_summary(const std::string& out) {
  const std::string last = last_line(out);
  char psnr[32] = {};
  Summary s;
  EXPECT_EQ(std::sscanf(last.c_str(), "psnr=%31s rmse=%lf within2=%lf", psnr, &s.rmse, &s.within2), 3) << "last line: " << last;
  s.psnr = std::strtod(psnr, nullptr);
  return s;
}

struct Sphere {
  std::string low, high, map;
};

Sphere make_sphere_scene(const std::string& dir) {
  Sphere s{dir + "/sphere_low.obj", dir + "/sphere_high.obj", dir + "/wave_map.png"};
  nmview::test::write_uv_sphere(s.low, 32, 16);
  nmview::test::write_bumpy_sphere(s.high, 64, 32);
  nmview::test::write_wave_map(s.map, 256, 128);
  return s;
}

// 8-bit channel values of an image file (RGB).
std::vector<int> read_rgb8(const std::string& path, int& width, int& height) {
  nmbake::Image image = nmbake::read_image(path);
  width = image.width;
  height = image.height;
  std::vector<int> v;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) v.push_back(int(std::lround(image.at(x, y)[std::min(c, image.channels - 1)] * 255.0f)));
  return v;
}

void expect_matches_golden(const std::string& actual, const std::string& golden_name) {
  const std::string golden = nmbake::test::data_path("viewer/" + golden_name);
  if (const char* regen = std::getenv("NMBAKE_REGENERATE"); regen && std::string(regen) == "1") {
    fs::create_directories(fs::path(golden).parent_path());
    fs::copy_file(actual, golden, fs::copy_options::overwrite_existing);
    GTEST_SKIP() << "regenerated " << golden;
  }
  ASSERT_TRUE(fs::exists(golden)) << golden << " is missing; run the test with NMBAKE_REGENERATE=1 to create it";
  int aw = 0, ah = 0, gw = 0, gh = 0;
  const std::vector<int> a = read_rgb8(actual, aw, ah), g = read_rgb8(golden, gw, gh);
  ASSERT_EQ(aw, gw);
  ASSERT_EQ(ah, gh);

  double sum = 0;
  std::size_t far_pixels = 0;
  nmbake::Image diff(aw, ah, 3);
  for (std::size_t p = 0; p < std::size_t(aw) * std::size_t(ah); ++p) {
    int worst = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      int d = std::abs(a[3 * p + c] - g[3 * p + c]);
      sum += d;
      worst = std::max(worst, d);
      diff.pixels[3 * p + c] = std::min(1.0f, float(d) * 8.0f / 255.0f);
    }
    if (worst > 16) ++far_pixels;
  }
  const double mean = sum / (3.0 * aw * ah);
  const double far_share = double(far_pixels) / (double(aw) * ah);
  const bool ok = mean <= 0.5 && far_share <= 0.005;
  std::string diff_path = actual.substr(0, actual.size() - 4) + "-diff.png";
  if (!ok) nmbake::write_image(diff_path, diff);
  EXPECT_TRUE(ok) << actual << " differs from " << golden << ": mean |diff| " << mean << " (limit 0.5), " << 100.0 * far_share
                  << " % of pixels off by > 16 (limit 0.5 %); difference image x8: " << diff_path
                  << "; if the change is intended, rerun with NMBAKE_REGENERATE=1";
}

TEST(NmviewGolden, SphereWithWaveMap) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  const std::string shot = dir + "/sphere.png";
  Result r = nmview(dir, quote(s.low) + " " + quote(s.map) + " " + quote(s.high) + " --screenshot " + quote(shot) +
                             " --size 480x240 --view 30,20 --light -30,30");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("EGL"), std::string::npos) << r.err;
  std::cout << r.err;
  expect_matches_golden(shot, "golden_sphere_convention.png");  // with the decoded convention in the left label
}

TEST(NmviewGolden, SphereWithToggles) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  const std::string shot = dir + "/sphere_toggles.png";
  Result r = nmview(dir, quote(s.low) + " " + quote(s.map) + " " + quote(s.high) + " --screenshot " + quote(shot) +
                             " --size 720x240 --view -60,35 --light 20,10 --show wire,diff");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_matches_golden(shot, "golden_sphere_wire_angle.png");  // the angle difference pane
}

TEST(NmviewGolden, SphereTangentColours) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  const std::string shot = dir + "/sphere_tangent.png";
  Result r = nmview(dir, quote(s.low) + " " + quote(s.map) + " " + quote(s.high) + " --screenshot " + quote(shot) +
                             " --size 480x240 --view 0,0 --show tangent");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_matches_golden(shot, "golden_sphere_tangent.png");
}

TEST(NmviewGolden, SphereWithoutMap) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  const std::string shot = dir + "/sphere_nomap.png";
  Result r = nmview(
      dir, quote(s.low) + " " + quote(s.map) + " " + quote(s.high) + " --screenshot " + quote(shot) + " --size 480x240 --no-map");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  expect_matches_golden(shot, "golden_sphere_nomap.png");
}

// A low-poly baked from itself decodes to its own shading: both panes agree.
void expect_self_bake_matches(const std::string& dir, const std::string& low) {
  const std::string map = dir + "/self.png";
  bake(dir, low, low, map);
  if (::testing::Test::HasFatalFailure()) return;
  Result r = nmview(dir, quote(low) + " " + quote(map) + " " + quote(low) + " --compare --size 800x400 --screenshot " +
                             quote(dir + "/worst.png"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Summary s = parse_summary(r.out);
  std::cout << "self-check " << low << ": " << last_line(r.out) << "\n";
  EXPECT_GE(s.psnr, 45.0);
  EXPECT_LE(s.rmse, 0.006);
  EXPECT_GE(s.within2, 0.99);
  // The normals agree to the 8-bit map's rounding (0.32 degrees), and no convention is flagged.
  EXPECT_NE(last_line(r.out).find(" verdict=good"), std::string::npos) << last_line(r.out);
  EXPECT_TRUE(fs::exists(dir + "/worst.png"));
}

TEST(NmviewSelfCheck, SphereBakedFromItself) {
  const std::string dir = scratch_dir();
  expect_self_bake_matches(dir, make_sphere_scene(dir).low);
}

TEST(NmviewSelfCheck, TorusLowBakedFromItself) {
  const std::string low = nmbake::test::shared_data_path("sculpts/torus_demo/low.obj");
  if (!nmbake::test::exists(low)) GTEST_SKIP() << low << " is absent (../shared not checked out)";
  expect_self_bake_matches(scratch_dir(), low);
}

// The interior figures of `map` on LOW/HIGH with the map and without, as `nmview LOW MAP HIGH
// --compare --size 800x400 [--no-map]` prints them (psnr, rmse, within2 of its last line), measured
// in this process (tool_run.h compare_interior: the scene loaded once for both). NmviewDecoding and
// the verdict tests run the binary's --compare.
struct MapOnOff {
  Summary on, off;
};

MapOnOff compare_map_on_off(const std::string& low, const std::string& map, const std::string& high) {
  nmview::test::make_headless();
  const nmview::HeadlessContext context;
  const std::vector<nmview::ErrorSums> sums = nmview::test::compare_interior(low, map, high, 400, 400, {true, false});
  MapOnOff figures;
  for (const bool map_on : {true, false}) {
    const nmview::ErrorSums& e = sums[map_on ? 0 : 1];
    Summary& s = map_on ? figures.on : figures.off;
    s.psnr = e.psnr();
    s.rmse = e.rmse();
    s.within2 = e.within2();
  }
  return figures;
}

// On a real sculpt the baked map must bring the low-poly's appearance clearly closer to the
// high-poly's than the bare low-poly.
TEST(NmviewSculpt, TorusDemoMapImprovesAppearance) {
  const std::string low = nmbake::test::shared_data_path("sculpts/torus_demo/low.obj");
  const std::string high = nmbake::test::shared_data_path("sculpts/torus_demo/high.ply");
  if (!nmbake::test::exists(low) || !nmbake::test::exists(high))
    GTEST_SKIP() << "sculpts/torus_demo is absent (../shared not checked out)";
  const std::string dir = scratch_dir(), map = dir + "/torus_map.png";
  bake(dir, low, high, map);
  if (::testing::Test::HasFatalFailure()) return;
  const MapOnOff figures = compare_map_on_off(low, map, high);
  const Summary &with_map = figures.on, &without_map = figures.off;
  std::cout << "torus_demo map on:  psnr=" << with_map.psnr << " rmse=" << with_map.rmse << " within2=" << with_map.within2
            << "\n"
            << "torus_demo map off: psnr=" << without_map.psnr << " rmse=" << without_map.rmse
            << " within2=" << without_map.within2 << "\n";
  // Measured with llvmpipe over the interior (pixels both models cover, away from the silhouette):
  // 21.4 dB with the map, 19.7 dB without, and 2.3 times the share within 2/255. The gain is small
  // because the high-poly's relief lies on average 0.018 outside the low-poly surface (bake report:
  // hit distance -0.007..0.032), so every bump is drawn a few pixels away from where the low-poly
  // shows its normal; with the high-poly's vertices moved onto the low-poly surface (same normals,
  // no parallax) the same map gives 41.5 dB against 20.8 dB. NmviewDecoding checks the decoding
  // itself on a scene without parallax.
  EXPECT_GE(with_map.psnr, without_map.psnr + 1.0);
  EXPECT_GE(with_map.within2, 2.0 * without_map.within2);
}

// The same on a procedural sculpt that needs no shared data: a sphere with bumps much finer than
// the low-poly's triangles and of small height, so the map can carry nearly all of it.
TEST(NmviewSculpt, BumpySphereMapImprovesAppearance) {
  const std::string dir = scratch_dir();
  const std::string low = dir + "/sphere_low.obj", high = dir + "/bumpy_high.obj", map = dir + "/bumpy_map.png";
  nmview::test::write_uv_sphere(low, 32, 16);
  nmview::test::write_bumpy_sphere(high, 512, 256, 40.0, 0.01);
  bake(dir, low, high, map);
  if (::testing::Test::HasFatalFailure()) return;
  const MapOnOff figures = compare_map_on_off(low, map, high);
  const Summary &with_map = figures.on, &without_map = figures.off;
  std::cout << "bumpy sphere map on:  psnr=" << with_map.psnr << " rmse=" << with_map.rmse << " within2=" << with_map.within2
            << "\n"
            << "bumpy sphere map off: psnr=" << without_map.psnr << " rmse=" << without_map.rmse
            << " within2=" << without_map.within2 << "\n";
  EXPECT_GE(with_map.psnr, without_map.psnr + 2.0);
  EXPECT_GE(with_map.within2, 2.0 * without_map.within2);
}

// --- decoding the map as it was baked ----------------------------------------------------------

// A smooth-shaded cube and the same surface with all of its detail in the normals: no parallax,
// no silhouette difference, and a tangent frame that turns strongly across every triangle, so a
// correct decoding is nearly exact and every wrong convention shows.
struct NormalCube {
  std::string dir, low, high;
};

NormalCube make_normal_cube() {
  NormalCube c{scratch_dir(), "", ""};
  c.low = c.dir + "/cube_low.obj";
  c.high = c.dir + "/cube_high.obj";
  nmview::test::write_smooth_cube(c.low);
  nmview::test::write_normal_detail_cube(c.high, 24);
  return c;
}

std::string bake_cube(const NormalCube& c, const std::string& name, const std::string& options) {
  const std::string map = c.dir + "/" + name;
  Result r = run(c.dir, nmbake::build::nmbake_exe(),
                 quote(c.low) + " " + quote(c.high) + " -o " + quote(map) + " --size 256 --quiet " + options);
  EXPECT_EQ(r.exit_code, 0) << "nmbake failed:\n" << r.out << r.err;
  return map;
}

Summary compare_cube(const NormalCube& c, const std::string& map, const std::string& options = "") {
  Result r = nmview(c.dir, quote(c.low) + " " + quote(map) + " " + quote(c.high) + " --compare --size 400x200 " + options +
                               " --screenshot " + quote(c.dir + "/worst.png"));
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const Summary s = parse_summary(r.out);
  std::cout << fs::path(map).filename().string() << " " << options << ": " << last_line(r.out) << "\n";
  return s;
}

// The default map on the cube and its figures, which every NmviewDecoding test compares against:
// baked and measured once in this process (the scene is the same each time).
struct DefaultCube {
  NormalCube cube;
  std::string map;
  Summary summary;
};

const DefaultCube& default_cube() {
  static const DefaultCube made = [] {
    DefaultCube d{make_normal_cube(), "", {}};
    d.map = bake_cube(d.cube, "default.png", "");
    d.summary = compare_cube(d.cube, d.map);
    return d;
  }();
  return made;
}

TEST(NmviewDecoding, DetailInTheNormalsIsReproduced) {
  const DefaultCube& d = default_cube();
  const Summary& on = d.summary;
  const Summary off = compare_cube(d.cube, d.map, "--no-map");
  // Measured with llvmpipe: 53.6 dB with the map, 19.9 dB without.
  EXPECT_GE(on.psnr, 45.0);
  EXPECT_GE(on.within2, 0.95);
  EXPECT_GE(on.psnr, off.psnr + 20.0);
}

// A map baked with `bake_options` decodes from its metadata as well as the default map; forcing the
// wrong convention is clearly worse. The same pixels without metadata (as from another baker) are
// wrong by default and right with `flags`.
void expect_decoded_like_default(const std::string& name, const std::string& bake_options, const std::string& wrong_override,
                                 const std::string& flags) {
  const NormalCube c = make_normal_cube();
  const Summary& reference = default_cube().summary;
  const std::string map = bake_cube(c, name, bake_options);
  const Summary right = compare_cube(c, map), wrong = compare_cube(c, map, wrong_override);
  // 16-bit TIFF maps are a little more exact than the 8-bit default.
  EXPECT_GE(right.psnr, reference.psnr - 1.5);
  EXPECT_LE(right.psnr, reference.psnr + 3.0);
  EXPECT_GE(right.within2, reference.within2 - 0.01);
  EXPECT_LE(wrong.psnr, reference.psnr - 10.0);

  const std::string bare = c.dir + "/bare.png";
  nmbake::write_image(bare, nmbake::read_image(map));
  ASSERT_EQ(nmbake::read_image_metadata(bare).count("nmbake:space"), 0u);
  EXPECT_LE(compare_cube(c, bare).psnr, reference.psnr - 10.0);
  const Summary overridden = compare_cube(c, bare, flags);
  EXPECT_NEAR(overridden.psnr, reference.psnr, 1.5);
}

// Measured with llvmpipe (interior PSNR): default 53.6 dB; green down 55.1 dB (16-bit TIFF), read
// as green up 17.0 dB; object space 52.4 dB, read as tangent space 9 dB; per-vertex bitangent
// 53.5 dB, read per pixel 34.4 dB.
TEST(NmviewDecoding, GreenDownFromTiffMetadata) {
  expect_decoded_like_default("green_down.tif", "--green down", "--green up", "--green down");
}

TEST(NmviewDecoding, ObjectSpaceFromMetadata) {
  expect_decoded_like_default("object.png", "--space object", "--space tangent", "--space object");
}

TEST(NmviewDecoding, PerVertexBitangentFromMetadata) {
  expect_decoded_like_default("vertex.png", "--bitangent vertex", "--bitangent pixel", "--bitangent vertex");
}

TEST(NmviewDecoding, BadOverridesAreUsageErrors) {
  const NormalCube c = make_normal_cube();
  const std::string map = bake_cube(c, "default.png", ""), object = bake_cube(c, "object.png", "--space object");
  const std::string inputs = quote(c.low) + " " + quote(map) + " " + quote(c.high) + " --compare --size 64x32";
  Result r = nmview(c.dir, inputs + " --green sideways");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("--green"), std::string::npos) << r.err;
  r = nmview(c.dir, inputs + " --space world");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  r = nmview(c.dir, quote(c.low) + " " + quote(object) + " " + quote(c.high) + " --compare --size 64x32 --green down");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("tangent-space maps only"), std::string::npos) << r.err;
}

// --- bad input: the baker's errors, one line, its exit codes -----------------------------------

// Notes may come first; the error is the one last line "error: <what>".
void expect_error(const Result& r, int code, const std::string& fragment) {
  EXPECT_EQ(r.exit_code, code) << r.err;
  std::string err = r.err;
  ASSERT_FALSE(err.empty());
  ASSERT_EQ(err.back(), '\n') << err;
  err.pop_back();
  const std::string last = err.substr(err.rfind('\n') == std::string::npos ? 0 : err.rfind('\n') + 1);
  EXPECT_EQ(last.rfind("error: ", 0), 0u) << r.err;
  EXPECT_NE(last.find(fragment), std::string::npos) << "expected '" << fragment << "' in: " << r.err;
  EXPECT_EQ(err.find("error: "), err.rfind("error: ")) << "more than one error line: " << r.err;
}

TEST(NmviewErrors, MissingMap) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  expect_error(
      nmview(dir, quote(s.low) + " " + quote(dir + "/none.png") + " " + quote(s.high) + " --screenshot " + quote(dir + "/x.png")),
      2, "none.png");
}

TEST(NmviewErrors, MapThatIsNotAnImage) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  std::ofstream(dir + "/text.png") << "this is not an image\n";
  expect_error(nmview(dir, quote(s.low) + " " + quote(dir + "/text.png") + " " + quote(s.high) + " --compare"), 2, "text.png");
}

TEST(NmviewErrors, GreyMapIsRejected) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  nmbake::write_image(dir + "/grey.png", nmbake::Image(16, 16, 1, 0.5f));
  expect_error(nmview(dir, quote(s.low) + " " + quote(dir + "/grey.png") + " " + quote(s.high) + " --compare"), 2, "needs RGB");
}

TEST(NmviewErrors, LowPolyWithoutUvs) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  expect_error(nmview(dir, quote(s.high) + " " + quote(s.map) + " " + quote(s.high) + " --compare"), 2, "UV");
}

TEST(NmviewErrors, MissingHighPoly) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  expect_error(nmview(dir, quote(s.low) + " " + quote(s.map) + " " + quote(dir + "/nope.ply") + " --compare"), 2, "nope.ply");
}

TEST(NmviewErrors, BadFlags) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  const std::string inputs = quote(s.low) + " " + quote(s.map) + " " + quote(s.high);
  expect_error(nmview(dir, inputs + " --size 1600by800 --compare"), 1, "--size");
  expect_error(nmview(dir, inputs + " --view 30 --compare"), 1, "--view");
  expect_error(nmview(dir, inputs + " --light a,b --compare"), 1, "--light");
  expect_error(nmview(dir, inputs + " --frobnicate"), 1, "frobnicate");
  expect_error(nmview(dir, quote(s.low) + " " + quote(s.map)), 1, "high");
}

TEST(NmviewErrors, WindowWithoutDisplayIsReportedNotCrashed) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  expect_error(nmview(dir, quote(s.low) + " " + quote(s.map) + " " + quote(s.high)), 3, "--screenshot");
}

TEST(NmviewInputs, MapOfAnySizeIsFine) {
  const std::string dir = scratch_dir();
  const Sphere s = make_sphere_scene(dir);
  nmview::test::write_flat_map(dir + "/odd.png", 37, 19);
  Result r = nmview(dir, quote(s.low) + " " + quote(dir + "/odd.png") + " " + quote(s.low) + " --compare --size 200x100");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_GE(parse_summary(r.out).within2, 0.99);
}

// --- --uv-set: the low-poly's UV set the map was baked into ------------------------------------

// Mean |a - b| of the 8-bit channels of two same-size screenshots over the left (pane 0) or the
// right (pane 1) half.
double pane_difference(const std::string& a_path, const std::string& b_path, int pane) {
  int aw = 0, ah = 0, bw = 0, bh = 0;
  const std::vector<int> a = read_rgb8(a_path, aw, ah), b = read_rgb8(b_path, bw, bh);
  EXPECT_TRUE(aw == bw && ah == bh);
  if (aw != bw || ah != bh) return 0.0;
  double sum = 0.0;
  const int x0 = pane * aw / 2, x1 = x0 + aw / 2;
  for (int y = 0; y < ah; ++y)
    for (int x = x0; x < x1; ++x)
      for (int c = 0; c < 3; ++c) sum += std::abs(a[3 * (std::size_t(y) * aw + x) + c] - b[3 * (std::size_t(y) * aw + x) + c]);
  return sum / (3.0 * (x1 - x0) * ah);
}

// A UV sphere (32 x 16 quads, outward normals) of `radius` around `centre`, as OBJ.
void write_sphere_obj(const std::string& path, glm::dvec3 centre, double radius) {
  std::ofstream out(path);
  const int segments = 32, rings = 16;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      const double theta = M_PI * r / rings, phi = 2.0 * M_PI * s / segments;
      const glm::dvec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      const glm::dvec3 p = centre + radius * n;
      out << "v " << p.x << " " << p.y << " " << p.z << "\nvn " << n.x << " " << n.y << " " << n.z << "\n";
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const int a = r * (segments + 1) + s + 1, b = a + segments + 1;  // OBJ counts from 1
      out << "f " << a << "//" << a << " " << a + 1 << "//" << a + 1 << " " << b + 1 << "//" << b + 1 << " " << b << "//" << b
          << "\n";
    }
}

// cube_with_2UVs.DAE has two UV layouts of one cube. A map baked into set 0 (the cube against a
// sphere through its faces, so every face shades from its middle out) is another picture on the
// left pane when nmview reads set 1, and the same one with --uv-set 0 as without; the high-poly's
// pane does not change. Sets from 8 on are refused as a usage error, a set the file lacks as bad
// input (the baker's errors).
TEST(NmviewUvSet, SetOneOfATwoSetCubeRendersDifferently) {
  const std::string dir = scratch_dir();
  const std::string cube = nmbake::test::data_path("assimp/cube_with_2UVs.DAE");
  const nmbake::Mesh mesh = nmbake::load_mesh(cube);
  glm::dvec3 lo(1e30), hi(-1e30);
  for (const glm::vec3& p : mesh.positions) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
  // 0.6 of the half diagonal: out of the face middles (0.58), inside the edges (0.82) and corners.
  write_sphere_obj(dir + "/sphere.obj", 0.5 * (lo + hi) + mesh.origin, 0.6 * 0.5 * glm::length(hi - lo));
  const std::string map = dir + "/map_baked_into_set0.png";
  bake(dir, cube, dir + "/sphere.obj", map, "--allow-overlap");  // each face on the whole square
  if (HasFatalFailure()) return;
  const std::string inputs = quote(cube) + " " + quote(map) + " " + quote(cube) + " --size 320x160 --screenshot ";
  for (const std::string& run :
       {std::string("default.png"), std::string("set0.png --uv-set 0"), std::string("set1.png --uv-set 1")}) {
    Result r = nmview(dir, inputs + quote(dir) + "/" + run);
    ASSERT_EQ(r.exit_code, 0) << run << ": " << r.err;
  }
  const double same = pane_difference(dir + "/default.png", dir + "/set0.png", 0);
  const double low_pane = pane_difference(dir + "/set0.png", dir + "/set1.png", 0);
  const double high_pane = pane_difference(dir + "/set0.png", dir + "/set1.png", 1);
  std::printf("mean |set 0 - set 1| (8-bit): low pane %.3f, high pane %.3f; default vs --uv-set 0: %.3f\n", low_pane, high_pane,
              same);
  EXPECT_EQ(same, 0.0);
  EXPECT_GE(low_pane, 2.0) << "--uv-set 1 shows the map as set 0 does";
  EXPECT_EQ(high_pane, 0.0);
  expect_error(nmview(dir, inputs + quote(dir + "/x.png") + " --uv-set 8"), 1, "--uv-set");
  expect_error(nmview(dir, inputs + quote(dir + "/x.png") + " --uv-set 2"), 2, "(UV set 2) has no UVs");
  EXPECT_FALSE(fs::exists(dir + "/x.png"));
}

}  // namespace
