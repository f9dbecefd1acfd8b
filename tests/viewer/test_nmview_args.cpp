// nmview's argument order (issue 36, item 5): nmbake's `nmview LOW HIGH -m MAP` (also --map) and
// nmview's own `nmview LOW MAP HIGH`, meshes told from images by their content (viewer/inputs.h),
// and one line naming the file for a file that is neither, a missing one, no map or two maps.
// classify_file and resolve_inputs are checked in this process; the forms end to end with the real
// binary headless as in test_nmview_set.cpp (DISPLAY unset, LIBGL_ALWAYS_SOFTWARE=1), on a 2 x 2
// plane and an 8 x 8 map tilted so that the map visibly changes the left pane.
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/image.h"
#include "inputs.h"
#include "io/image_io.h"
#include "test_support.h"
#include "tool_run.h"
#include "build_paths.h"

namespace {

using nmbake::test::contains;
using nmbake::test::read_file;
using nmbake::test::scratch_dir;
using nmbake::test::write_file;
using nmview::FileKind;
using nmview::test::quote;

const char* kPlaneObj =
    "# a 2 x 2 plane facing +Z\n"
    "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
    "vn 0 0 1\n"
    "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";

// An 8 x 8 tangent-space map of one normal tilted towards +U: (200, 128, 230), in the format of
// `format` (an extension), at `path` whatever its name.
void write_tilted_map(const std::string& path, const std::string& format = ".png") {
  nmbake::Image map(8, 8, 3);
  for (std::size_t i = 0; i < map.pixels.size(); i += 3) {
    map.pixels[i] = 200.0f / 255.0f;
    map.pixels[i + 1] = 128.0f / 255.0f;
    map.pixels[i + 2] = 230.0f / 255.0f;
  }
  const std::string written = path + ".written" + format;
  nmbake::write_image(written, map);
  ASSERT_EQ(std::rename(written.c_str(), path.c_str()), 0) << path;
}

std::string bytes(const char* data, std::size_t size) { return std::string(data, size); }

TEST(NmviewFileKinds, MeshesAndImagesAreToldApartByContent) {
  const std::string dir = scratch_dir();
  const auto at = [&](const std::string& name) { return dir + "/" + name; };
  // Images: written by the baker's own writer, one named as no image is.
  for (const char* ext : {".png", ".tif", ".exr"}) write_tilted_map(at(std::string("m") + ext), ext);
  write_tilted_map(at("png_named.obj"));
  write_tilted_map(at("tga_named.dat"), ".tga");  // TGA has no signature: OpenImageIO's header probe
  // Meshes: our readers' formats and the signatures of Assimp's, one named as no mesh is.
  write_file(at("plane.obj"), kPlaneObj);
  write_file(at("obj_named.png"), kPlaneObj);
  write_file(at("p.ply"), "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n");
  write_file(at("p.off"), "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  write_file(at("a.stl"), "solid x\nendsolid x\n");
  std::string binary_stl(84 + 50, '\0');
  binary_stl[80] = 1;  // one triangle
  write_file(at("b.data"), binary_stl);
  write_file(at("s.gltf"), "{\n  \"asset\": {\"version\": \"2.0\"}\n}\n");
  write_file(at("s.glb"), bytes("glTF\x02\0\0\0\x0c\0\0\0", 12));
  write_file(at("s.fbx"), "Kaydara FBX Binary  " + std::string(20, '\0'));
  write_file(at("s.dae"), "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\">\n");
  // Neither: text, and bytes with no signature under a name that says nothing.
  write_file(at("notes.txt"), "bake notes: low first, then high\n");
  std::string noise;
  for (int i = 0; i < 3000; ++i) noise += char((i * 7919 + 13) % 251 + 1);
  write_file(at("noise.bin"), noise);
  ASSERT_EQ(::mkfifo(at("fifo.png").c_str(), 0600), 0);

  const struct {
    const char* name;
    FileKind kind;
  } cases[] = {
      {"m.png", FileKind::image},         {"m.tif", FileKind::image},         {"m.exr", FileKind::image},
      {"png_named.obj", FileKind::image}, {"tga_named.dat", FileKind::image}, {"plane.obj", FileKind::mesh},
      {"obj_named.png", FileKind::mesh},  {"p.ply", FileKind::mesh},          {"p.off", FileKind::mesh},
      {"a.stl", FileKind::mesh},          {"b.data", FileKind::mesh},         {"s.gltf", FileKind::mesh},
      {"s.glb", FileKind::mesh},          {"s.fbx", FileKind::mesh},          {"s.dae", FileKind::mesh},
      {"notes.txt", FileKind::neither},   {"noise.bin", FileKind::neither},   {"missing.png", FileKind::unknown},
      {"fifo.png", FileKind::unknown},    {"set_<MAP>.png", FileKind::image},
  };
  for (const auto& c : cases) EXPECT_EQ(int(nmview::classify_file(at(c.name))), int(c.kind)) << c.name;
}

TEST(NmviewFileKinds, EachFormResolvesToLowMapHigh) {
  const std::string dir = scratch_dir();
  const std::string low = dir + "/low.obj", high = dir + "/high.obj", map = dir + "/map.png", notes = dir + "/notes.txt";
  write_file(low, kPlaneObj);
  write_file(high, kPlaneObj);
  write_tilted_map(map);
  write_file(notes, "not a mesh\n");
  const auto expect = [&](const std::vector<std::string>& files, const std::string& m, const std::string& want_map,
                          const std::string& label) {
    const nmview::InputFiles r = nmview::resolve_inputs(files, m);
    EXPECT_EQ(r.low, low) << label;
    EXPECT_EQ(r.map, want_map) << label;
    EXPECT_EQ(r.high, high) << label;
  };
  expect({low, map, high}, "", map, "LOW MAP HIGH");
  expect({low, high}, map, map, "LOW HIGH -m MAP");
  expect({low, high, map}, "", map, "LOW HIGH MAP");
  expect({map, low, high}, "", map, "MAP LOW HIGH");
  // A map that cannot be looked into takes the place the meshes leave.
  expect({low, high, dir + "/missing.png"}, "", dir + "/missing.png", "LOW HIGH MISSING");
  expect({low, dir + "/missing.png", high}, "", dir + "/missing.png", "LOW MISSING HIGH");
  // Nothing decides: LOW MAP HIGH as before, for the loaders to report.
  const nmview::InputFiles two_missing = nmview::resolve_inputs({low, dir + "/a", dir + "/b"}, "");
  EXPECT_EQ(two_missing.map, dir + "/a");

  const auto usage = [&](const std::vector<std::string>& files, const std::string& m, const std::string& message) {
    try {
      nmview::resolve_inputs(files, m);
      ADD_FAILURE() << "accepted; expected: " << message;
    } catch (const nmbake::UsageError& e) {
      EXPECT_TRUE(contains(e.what(), message)) << e.what();
    }
  };
  usage({low, high}, "", "no map given");
  usage({low, map}, "", "no high-poly mesh given");
  usage({low, high, low}, "", "are all meshes and no map is given");
  usage({low, map, map}, "", "are both images");
  usage({low, map, high}, map, "and three files");
  usage({map, high}, map, map + ": an image where the low-poly mesh was expected");
  usage({low, high}, high, "-m " + high + ": a mesh where the map was expected");
  for (const auto& [files, m] : {std::pair{std::vector<std::string>{low, notes, high}, std::string()},
                                 std::pair{std::vector<std::string>{low, high}, notes}}) {
    try {
      nmview::resolve_inputs(files, m);
      ADD_FAILURE() << "a file that is neither was accepted";
    } catch (const nmbake::InputError& e) {
      EXPECT_TRUE(contains(e.what(), notes + ": neither a mesh nor an image")) << e.what();
    }
  }
}

// The binary: every accepted form renders the same screenshot, the map applied (it differs from
// --no-map's); each refused form is one line naming the file, with the exit code of its kind.
struct PlaneScene {
  std::string dir, low, high, map;
};

PlaneScene make_plane_scene() {
  PlaneScene s;
  s.dir = scratch_dir();
  // The map under a name that says nothing of what it is: only its content tells.
  s.low = s.dir + "/low.obj";
  s.high = s.dir + "/high.obj";
  s.map = s.dir + "/normal.map";
  write_file(s.low, kPlaneObj);
  write_file(s.high, kPlaneObj);
  write_tilted_map(s.map);
  return s;
}

nmview::test::ToolRun nmview_run(const PlaneScene& s, const std::string& args) {
  return nmview::test::run_tool(s.dir, nmbake::build::nmview_exe(), args);
}

std::string screenshot(const PlaneScene& s, const std::string& name, const std::string& inputs) {
  const std::string shot = s.dir + "/" + name + ".png";
  const nmview::test::ToolRun r =
      nmview_run(s, inputs + " --screenshot " + quote(shot) + " --size 64x32 --view 0,0 --light 20,10 --show nolabels");
  EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
  if (r.exit_code != 0) return "";
  const nmbake::Image image = nmbake::read_image(shot);
  return std::string(reinterpret_cast<const char*>(image.pixels.data()), image.pixels.size() * sizeof(float));
}

TEST(NmviewArgs, BothOrdersAndMapOptionGiveTheSameScreenshot) {
  const PlaneScene s = make_plane_scene();
  const std::string low = quote(s.low), high = quote(s.high), map = quote(s.map);
  const std::string present = screenshot(s, "present", low + " " + map + " " + high);
  ASSERT_FALSE(present.empty());
  EXPECT_EQ(screenshot(s, "dash_m", low + " " + high + " -m " + map), present) << "LOW HIGH -m MAP";
  EXPECT_EQ(screenshot(s, "long_map", low + " " + high + " --map " + map), present) << "LOW HIGH --map MAP";
  EXPECT_EQ(screenshot(s, "map_last", low + " " + high + " " + map), present) << "LOW HIGH MAP";
  EXPECT_NE(screenshot(s, "no_map", low + " " + map + " " + high + " --no-map"), present) << "the map must show";
}

TEST(NmviewArgs, RefusedFormsNameTheFileInOneLine) {
  const PlaneScene s = make_plane_scene();
  write_file(s.dir + "/notes.txt", "low first, then high\n");
  const std::string low = quote(s.low), high = quote(s.high), map = quote(s.map), notes = quote(s.dir + "/notes.txt"),
                    shot = s.dir + "/shot.png";
  const struct {
    std::string args;
    int code;
    std::string message;
  } cases[] = {
      {low + " " + notes + " " + high, 2, "notes.txt: neither a mesh nor an image"},
      {low + " " + high + " -m " + notes, 2, "notes.txt: neither a mesh nor an image"},
      {low + " " + high + " " + quote(s.dir + "/missing.png"), 2, "missing.png: cannot read image: no such file"},
      {quote(s.dir + "/missing.obj") + " " + map + " " + high, 2, "missing.obj: cannot open"},
      {low + " " + high, 1, "error: no map given: give nmview LOW HIGH -m MAP or nmview LOW MAP HIGH"},
      {low + " " + map + " " + map, 1, "are both images"},
      {low + " " + map + " " + high + " -m " + map, 1, "and three files"},
  };
  for (const auto& c : cases) {
    const nmview::test::ToolRun r = nmview_run(s, c.args + " --screenshot " + quote(shot) + " --size 64x32");
    EXPECT_EQ(r.exit_code, c.code) << c.args << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, c.message)) << c.args << "\n" << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args << "\n" << r.err;
    struct stat st {};
    EXPECT_NE(::stat(shot.c_str(), &st), 0) << c.args << ": no screenshot on an error";
  }
}

}  // namespace
