// The cage on the command line, through the nmbake binary and the bundled sample (128^2 maps):
// --save-cage writes the automatic cage and --cage bakes it back to the same map; --save-cage is
// refused before anything is written when it names an input, comes with --cage/--front/--rear or
// is not .obj; a cage inside the low-poly or with another topology is refused; --policy closest
// and a measured rear work with a cage; --keep-backfaces is reported. Each case checks the exit
// code, the one-line message and which files were (not) written.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include "io/image_io.h"
#include "io/mesh_io.h"
#include "nmdiff.h"
#include "test_support.h"

using namespace nmbake;
using test::CliRun;
using test::contains;
using test::run_nmbake;

namespace {

const int kSize = 128;

std::string low_path() { return test::data_path("sample/torus_low.obj"); }
std::string high_path() { return test::data_path("sample/torus_high.ply"); }

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
  ASSERT_TRUE(out.good()) << path;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::size_t count_lines_starting(const std::string& text, const std::string& start) {
  std::size_t n = 0;
  for (const std::string& line : lines_of(text)) n += line.rfind(start, 0) == 0;
  return n;
}

// A refusal is exactly one line, "error: ...", on stderr.
bool is_one_error_line(const std::string& err) {
  return err.rfind("error: ", 0) == 0 && !err.empty() && err.back() == '\n' && std::count(err.begin(), err.end(), '\n') == 1;
}

// "LOW HIGH -o <map> --size 128 --report r.json" with the sample's absolute paths.
std::string bake_args(const std::string& low, const std::string& map = "out.png") {
  return "'" + low + "' '" + high_path() + "' -o " + map + " --size " + std::to_string(kSize) + " --report r.json";
}
std::string bake_args_sample(const std::string& map = "out.png") { return bake_args(low_path(), map); }

Mesh load_low() {
  LoadOptions lo;
  lo.require_uvs = true;
  return load_mesh(low_path(), lo);
}

// The low-poly with every vertex moved by `offset` along its normal (the file's normals at its
// corners, averaged), written as OBJ with the low-poly's topology and UVs.
void write_offset_cage(const std::string& path, float offset) {
  Mesh m = load_low();
  ASSERT_TRUE(m.has_normals());
  std::vector<glm::vec3> n(m.positions.size(), glm::vec3(0.0f));
  for (std::size_t c = 0; c < m.position_index.size(); ++c) n[m.position_index[c]] += m.normals[m.normal_index[c]];
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    if (glm::length(n[i]) > 0.0f) m.positions[i] += offset * glm::normalize(n[i]);
  m.normals.clear();
  m.normal_index.clear();
  write_bytes(path, obj_text(m, "torus_low.obj moved by " + std::to_string(offset) + " along its normals"));
}

}  // namespace

// 1. The automatic cage, saved and baked back: the same bytes.
TEST(CageCli, SavedAutomaticCageBakesTheSameMap) {
  const std::string dir = test::scratch_dir();
  const CliRun saved = run_nmbake(bake_args_sample("auto.png") + " --save-cage cage.obj", "", dir);
  ASSERT_EQ(saved.code, 0) << saved.err;
  EXPECT_TRUE(contains(saved.out, "nmbake: wrote auto.png (128x128")) << saved.out;
  EXPECT_TRUE(contains(saved.err, "nmbake: automatic cage: front ")) << saved.err;
  EXPECT_EQ(saved.report["cage"]["source"], "automatic");
  EXPECT_EQ(saved.report["options"]["save_cage"], "cage.obj");  // what nmview --report draws as the cage
  ASSERT_TRUE(test::exists(dir + "/cage.obj"));

  const CliRun file = run_nmbake(bake_args_sample("file.png") + " --cage cage.obj", "", dir);
  ASSERT_EQ(file.code, 0) << file.err;
  EXPECT_TRUE(contains(file.out, "nmbake: wrote file.png (128x128")) << file.out;
  EXPECT_TRUE(contains(file.err, "nmbake: rear distances measured per vertex")) << file.err;
  EXPECT_EQ(file.report["cage"]["source"], "file");
  EXPECT_EQ(file.report["misses"], 0);

  const std::string a = read_bytes(dir + "/auto.png"), b = read_bytes(dir + "/file.png");
  EXPECT_FALSE(a.empty());
  EXPECT_TRUE(a == b) << "auto.png and file.png differ (" << a.size() << " and " << b.size() << " bytes) in " << dir;

  // The cage has the low-poly's vertices and one face per triangle.
  const std::string cage = read_bytes(dir + "/cage.obj"), low = read_bytes(low_path());
  EXPECT_EQ(count_lines_starting(cage, "v "), count_lines_starting(low, "v "));
  EXPECT_EQ(count_lines_starting(cage, "v "), 3072u);
  EXPECT_EQ(count_lines_starting(cage, "f "), load_low().triangle_count());
  EXPECT_EQ(count_lines_starting(cage, "f "), 6144u);
}

// 2. --save-cage naming the low-poly, however spelt, is refused and leaves it as it was. The
// low-poly is a copy in the scratch folder so that a failure cannot overwrite data/sample.
TEST(CageCli, SaveCageOntoTheLowPolyIsRefused) {
  const std::string dir = test::scratch_dir();
  const std::string low = dir + "/low.obj";
  std::filesystem::copy_file(low_path(), low);
  std::filesystem::create_symlink("low.obj", dir + "/link.obj");
  const std::string before = read_bytes(low);
  ASSERT_FALSE(before.empty());
  struct Case {
    std::string low_arg, save;
  };
  for (const Case& c : {Case{low, low}, Case{"low.obj", "./low.obj"}, Case{"low.obj", "link.obj"}, Case{low, "link.obj"}}) {
    SCOPED_TRACE("low " + c.low_arg + ", --save-cage " + c.save);
    const CliRun r = run_nmbake(bake_args(c.low_arg) + " --save-cage " + c.save, "", dir);
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(is_one_error_line(r.err)) << r.err;
    EXPECT_TRUE(contains(r.err, "error: --save-cage " + c.save + " is the same file as " + c.low_arg + "; nothing written"))
        << r.err;
    EXPECT_TRUE(read_bytes(low) == before) << low << " was changed";
    EXPECT_TRUE(std::filesystem::is_symlink(dir + "/link.obj"));
    EXPECT_FALSE(test::exists(dir + "/out.png"));
    EXPECT_FALSE(test::exists(dir + "/r.json"));
  }
}

// 3. --save-cage writes the automatic cage only: with --front, --rear or --cage, or to a file that
// is not OBJ, it is a bad command line and nothing is written.
TEST(CageCli, SaveCageWithoutAnAutomaticCageOrAsNonObjIsRefused) {
  const std::string dir = test::scratch_dir();
  std::filesystem::copy_file(low_path(), dir + "/c.obj");  // a valid cage: the refusal is the options'
  for (const std::string& extra : std::vector<std::string>{"--front 0.01", "--rear 0.01", "--cage c.obj"}) {
    SCOPED_TRACE(extra);
    const CliRun r = run_nmbake(bake_args_sample() + " --save-cage x.obj " + extra, "", dir);
    EXPECT_EQ(r.code, 1);
    EXPECT_TRUE(is_one_error_line(r.err)) << r.err;
    EXPECT_TRUE(
        contains(r.err, "error: --save-cage writes the automatic cage, which is made only without --cage, --front and --rear"))
        << r.err;
    EXPECT_FALSE(test::exists(dir + "/x.obj"));
    EXPECT_FALSE(test::exists(dir + "/out.png"));
    EXPECT_FALSE(test::exists(dir + "/r.json"));
  }
  const CliRun r = run_nmbake(bake_args_sample() + " --save-cage x.png", "", dir);
  EXPECT_EQ(r.code, 1);
  EXPECT_TRUE(is_one_error_line(r.err)) << r.err;
  EXPECT_TRUE(contains(r.err, "error: --save-cage x.png: the cage is written as OBJ (.obj)")) << r.err;
  EXPECT_FALSE(test::exists(dir + "/x.png"));
  EXPECT_FALSE(test::exists(dir + "/out.png"));
  EXPECT_FALSE(test::exists(dir + "/r.json"));
}

// 4. A cage moved inwards (every vertex 0.02 along minus its normal) is invalid input. The same
// writer with +0.02 makes an accepted cage (RearIsMeasuredPerVertexWithACageAlone bakes one).
TEST(CageCli, CageInsideTheLowPolyIsRefused) {
  const std::string dir = test::scratch_dir();
  write_offset_cage(dir + "/inside.obj", -0.02f);
  const CliRun r = run_nmbake(bake_args_sample() + " --cage inside.obj", "", dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_TRUE(is_one_error_line(r.err)) << r.err;
  EXPECT_TRUE(contains(r.err, "error: inside.obj: the cage lies inside the low-poly")) << r.err;
  EXPECT_FALSE(test::exists(dir + "/out.png"));
  EXPECT_FALSE(test::exists(dir + "/r.json"));
}

// 5. A cage whose faces are not the low-poly's: one face fewer, or the same faces in another order.
TEST(CageCli, CageWithAnotherTopologyIsRefused) {
  const std::string dir = test::scratch_dir();
  std::vector<std::string> head, faces;
  for (const std::string& line : lines_of(read_bytes(low_path()))) (line.rfind("f ", 0) == 0 ? faces : head).push_back(line);
  ASSERT_EQ(faces.size(), 6144u);
  auto write_cage = [&](const std::string& name, const std::vector<std::string>& f) {
    std::string text;
    for (const std::string& line : head) text += line + "\n";
    for (const std::string& line : f) text += line + "\n";
    write_bytes(dir + "/" + name, text);
  };
  std::vector<std::string> fewer(faces.begin(), faces.end() - 1), shuffled = faces;
  std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(12111));
  write_cage("one_face_fewer.obj", fewer);
  write_cage("shuffled.obj", shuffled);
  for (const std::string& name : std::vector<std::string>{"one_face_fewer.obj", "shuffled.obj"}) {
    SCOPED_TRACE(name);
    const CliRun r = run_nmbake(bake_args_sample() + " --cage " + name, "", dir);
    EXPECT_EQ(r.code, 2);
    EXPECT_TRUE(is_one_error_line(r.err)) << r.err;
    EXPECT_TRUE(contains(r.err, "error: " + name + ": the cage must have the low-poly's topology")) << r.err;
    EXPECT_FALSE(test::exists(dir + "/out.png"));
    EXPECT_FALSE(test::exists(dir + "/r.json"));
  }
}

// 6. --policy closest with the saved cage: no misses, and within a small angle of the default map.
TEST(CageCli, ClosestPolicyWorksWithACage) {
  const std::string dir = test::scratch_dir();
  const CliRun saved = run_nmbake(bake_args_sample("auto.png") + " --save-cage cage.obj", "", dir);
  ASSERT_EQ(saved.code, 0) << saved.err;
  const CliRun r = run_nmbake(bake_args_sample("closest.png") + " --cage cage.obj --policy closest", "", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "nmbake: wrote closest.png (128x128")) << r.out;
  EXPECT_EQ(r.report["options"]["policy"], "closest");
  EXPECT_EQ(r.report["cage"]["source"], "file");
  EXPECT_EQ(r.report["misses"], 0);

  diff::DiffOptions d;
  d.mask = diff::uv_layout_mask(load_low(), kSize, kSize);
  const diff::DiffStats s = diff::compare_normal_maps(read_image(dir + "/closest.png"), read_image(dir + "/auto.png"), d);
  std::printf("closest against default: %s\n", diff::summary_line(s).c_str());
  EXPECT_GT(s.texels_compared, std::size_t(kSize) * kSize / 2);
  EXPECT_LT(s.mean_deg, 1.0);
}

// 7. With --cage and no --rear the rear is measured per vertex (reported); a given --rear is used
// as it is and cage.rear stays 0 (nothing measured), misses or not.
TEST(CageCli, RearIsMeasuredPerVertexWithACageAlone) {
  const std::string dir = test::scratch_dir();
  const CliRun saved = run_nmbake(bake_args_sample("auto.png") + " --save-cage cage.obj", "", dir);
  ASSERT_EQ(saved.code, 0) << saved.err;

  const CliRun measured = run_nmbake(bake_args_sample() + " --cage cage.obj", "", dir);
  ASSERT_EQ(measured.code, 0) << measured.err;
  EXPECT_TRUE(contains(measured.err, "nmbake: rear distances measured per vertex")) << measured.err;
  EXPECT_GT(measured.report["cage"]["rear"]["max"].get<double>(), 0.0);
  EXPECT_GT(measured.report["cage"]["rear"]["min"].get<double>(), 0.0);
  EXPECT_EQ(measured.report["misses"], 0);

  std::filesystem::remove(dir + "/out.png");
  const CliRun given = run_nmbake(bake_args_sample() + " --cage cage.obj --rear 0.0001", "", dir);
  ASSERT_EQ(given.code, 0) << given.err;
  EXPECT_TRUE(test::exists(dir + "/out.png"));
  EXPECT_FALSE(contains(given.err, "rear distances measured")) << given.err;
  EXPECT_EQ(given.report["cage"]["source"], "file");
  EXPECT_EQ(given.report["cage"]["rear"]["max"], 0.0);
  EXPECT_EQ(given.report["cage"]["rear"]["mean"], 0.0);
  EXPECT_NEAR(given.report["options"]["rear"].get<double>(), 0.0001, 1e-9);
  std::printf("misses with --rear 0.0001: %s\n", given.report["misses"].dump().c_str());
}

// 8. --keep-backfaces: the first hit, and the report says back faces were not skipped.
TEST(CageCli, KeepBackfacesIsReported) {
  const std::string dir = test::scratch_dir();
  const CliRun r = run_nmbake(bake_args_sample() + " --keep-backfaces", "", dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "nmbake: wrote out.png (128x128")) << r.out;
  EXPECT_TRUE(test::exists(dir + "/out.png"));
  EXPECT_EQ(r.report["backfaces_skipped"], false);
  EXPECT_EQ(r.report["options"]["keep_backfaces"], true);
  EXPECT_EQ(r.report["backface_skips"], 0);
}
