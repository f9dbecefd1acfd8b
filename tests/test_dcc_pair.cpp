// One scene exported by two real modelling tools bakes the same map (issue 20: "an FBX and a glTF
// exported from the same scene give the same map, mean <= 0.05 degrees").
//
// The Assimp test set has no scene in both FBX and glTF (or DAE and glTF): its glTF files come
// from COLLADA2GLTF, Blender or generators, with no FBX or DAE of the same scene beside them. The
// one pair of real exports of one scene is the spider (data/assimp, BSD-3-clause):
// `spider.obj`, written by MilkShape 3D, and `spider.fbx`, written by Blender 2.76's FBX exporter
// in centimetres (UnitScaleFactor 1, so nmbake scales it by 0.01), 1368 triangles in 19 parts.
// After that scale both files hold the same positions and UVs, and the same normals but at 84
// triangles, so the spider is the pair used here: FBX against OBJ instead of FBX against glTF.
//
// A mesh baked onto itself gives a flat map, and so does a high-poly the rays miss (misses are
// written flat), so the low-poly here is the spider's surface with smooth normals (positions and
// UVs written back as OBJ by nmbake::obj_text, normals computed) and the high-poly a file with its
// own normals (hard edges): the map records where the file's shading differs from the smooth one,
// and a high-poly misplaced by a wrong scale, axis or node transform bakes another map.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/mesh_io.h"
#include "nmdiff.h"
#include "pipeline/bake.h"
#include "test_support.h"

namespace nmbake {
namespace {

const std::string kObj = test::data_path("assimp/spider.obj");
const std::string kFbx = test::data_path("assimp/spider.fbx");
constexpr int kSize = 256;

// spider.obj as shipped has one normal of length 0 (line 1560), for which nmbake drops all the
// file's normals (mesh_io.h): the copy gives that one normal +Y, so that the OBJ keeps its normals
// as the FBX does (Blender wrote a unit normal there).
std::string obj_with_normals(const std::string& dir) {
  std::string text = test::read_file(kObj);
  const std::string zero = "vn 0.000000 0.000000 0.000000";
  const std::size_t at = text.find(zero);
  EXPECT_NE(at, std::string::npos) << "spider.obj changed: its zero normal is gone";
  if (at != std::string::npos) text.replace(at, zero.size(), "vn 0 1 0");
  EXPECT_EQ(text.find(zero), std::string::npos) << "spider.obj has more than one zero normal";
  test::write_file(dir + "/spider_normals.obj", text);
  return dir + "/spider_normals.obj";
}

// The mesh's positions and UVs without its normals, as OBJ (normals get computed smooth).
std::string smooth_copy(const std::string& path, const std::string& out) {
  test::write_file(out, obj_text(load_mesh(path), "smooth copy of " + path));
  return out;
}

struct Bake {
  Image map;
  std::vector<std::uint8_t> mask;  // texels covered by the low-poly's UV layout
};

Bake bake_dcc_files(const std::string& low_path, const std::string& high_path) {
  const test::MeshPair pair = test::load_pair(low_path, high_path);
  BakeOptions o;
  o.width = o.height = kSize;
  return {bake_normal_map(pair.low, pair.high, nullptr, o).map, diff::uv_layout_mask(pair.low, kSize, kSize)};
}

// Mean angle between two maps over the covered texels, degrees.
double mean_difference(const Bake& a, const Bake& b, const char* what) {
  diff::DiffOptions options;
  options.mask = a.mask;
  const diff::DiffStats stats = diff::compare_normal_maps(a.map, b.map, options);
  std::printf("%-44s %s\n", what, diff::summary_line(stats).c_str());
  return stats.mean_deg;
}

// Mean tilt of a map's covered texels from flat (0, 0, 1), degrees: how much there is to compare.
double mean_tilt(const Bake& a) {
  Bake flat{Image(kSize, kSize, 3), a.mask};
  for (std::size_t i = 0; i < flat.map.pixels.size(); i += 3) {
    flat.map.pixels[i] = flat.map.pixels[i + 1] = 0.5f;
    flat.map.pixels[i + 2] = 1.0f;
  }
  return mean_difference(a, flat, "map against flat:");
}

// Largest distance from a point of `a` to the nearest point of `b` (brute force: < 1000 points).
double farthest_nearest(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  double worst = 0.0;
  for (const glm::vec3& p : a) {
    double nearest = 1e300;
    for (const glm::vec3& q : b) nearest = std::min(nearest, double(glm::length(p - q)));
    worst = std::max(worst, nearest);
  }
  return worst;
}

// Known answer first: after the FBX's unit scale both files hold one surface, in place, Y up.
TEST(DccPair, SpiderFbxAndObjHoldTheSameSurfaceInMetres) {
  MeshLoadInfo obj_info, fbx_info;
  const Mesh obj = load_mesh(kObj, {}, &obj_info), fbx = load_mesh(kFbx, {}, &fbx_info);
  EXPECT_EQ(obj_info.unit_scale, 1.0);
  EXPECT_DOUBLE_EQ(fbx_info.unit_scale, 0.01);  // centimetres
  EXPECT_EQ(obj.triangle_count(), 1368u);
  EXPECT_EQ(fbx.triangle_count(), obj.triangle_count());
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : obj.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const double diagonal = glm::length(hi - lo);
  const double obj_to_fbx = farthest_nearest(obj.positions, fbx.positions);
  const double fbx_to_obj = farthest_nearest(fbx.positions, obj.positions);
  std::printf("diagonal %.4f; farthest OBJ point from the FBX %.3g, FBX from the OBJ %.3g\n", diagonal, obj_to_fbx, fbx_to_obj);
  EXPECT_LE(obj_to_fbx, 1e-5 * diagonal);
  EXPECT_LE(fbx_to_obj, 1e-5 * diagonal);
}

// For each triangle of `a`, the triangle of `b` with the same corner positions (which both files
// hold exactly, see above) and by how many corners it is turned; {npos, 0} when there is none.
std::vector<std::pair<std::size_t, int>> match_triangles(const Mesh& a, const Mesh& b) {
  using Key = std::array<float, 9>;
  const auto key = [](const Mesh& m, std::size_t t, int turn) {
    Key k{};
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < 3; ++i) k[std::size_t(3 * c + i)] = m.corner_position(t, (c + turn) % 3)[i];
    return k;
  };
  std::map<Key, std::pair<std::size_t, int>> in_b;  // each triangle of b under its three turns
  for (std::size_t t = 0; t < b.triangle_count(); ++t)
    for (int turn = 0; turn < 3; ++turn) in_b[key(b, t, turn)] = {t, turn};
  std::vector<std::pair<std::size_t, int>> match(a.triangle_count(), {std::string::npos, 0});
  for (std::size_t t = 0; t < a.triangle_count(); ++t)
    if (const auto it = in_b.find(key(a, t, 0)); it != in_b.end()) match[t] = it->second;
  return match;
}

// `b`'s triangles in `a`'s order (each as matched, its corners turned alike): where UV islands
// overlap the bake keeps the lowest-numbered triangle, and the two files number them differently.
Mesh in_order_of(const Mesh& b, const Mesh& a) {
  Mesh out = b;
  out.position_index.clear();
  out.normal_index.clear();
  out.uv_index.clear();
  out.source_face.clear();
  out.triangle_object.clear();
  out.objects.clear();
  for (const auto& [t, turn] : match_triangles(a, b))
    for (int c = 0; c < 3 && t != std::string::npos; ++c) {
      const std::size_t k = 3 * t + std::size_t((c + turn) % 3);
      out.position_index.push_back(b.position_index[k]);
      out.normal_index.push_back(b.normal_index[k]);
      out.uv_index.push_back(b.uv_index[k]);
      out.source_face.push_back(b.source_face[t]);
    }
  return out;
}

// As the high-poly the FBX bakes the OBJ's map, under the smooth surface of either file.
TEST(DccPair, SpiderFbxAndObjBakeTheSameMapAsHighPoly) {
  const std::string dir = test::scratch_dir();
  const std::string obj = obj_with_normals(dir);
  const std::string obj_low = smooth_copy(kObj, dir + "/obj_smooth.obj");
  const Bake obj_on_obj = bake_dcc_files(obj_low, obj), obj_on_fbx = bake_dcc_files(obj_low, kFbx);
  // Enough in the map that a misplaced high-poly shows (AMisplacedHighPolyBakesAnotherMap).
  EXPECT_GE(mean_tilt(obj_on_obj), 0.5);
  EXPECT_LE(mean_difference(obj_on_fbx, obj_on_obj, "smooth OBJ low, FBX high vs OBJ high:"), 0.05);
  const std::string fbx_low = smooth_copy(kFbx, dir + "/fbx_smooth.obj");
  const Bake fbx_on_obj = bake_dcc_files(fbx_low, obj), fbx_on_fbx = bake_dcc_files(fbx_low, kFbx);
  EXPECT_GE(mean_tilt(fbx_on_fbx), 0.5);
  EXPECT_LE(mean_difference(fbx_on_fbx, fbx_on_obj, "smooth FBX low, FBX high vs OBJ high:"), 0.05);
}

// As the low-poly the files differ in one way that is not the reader's: the spider's three
// materials each use the whole UV square (its UV islands overlap about 9 deep), where the bake
// keeps the lowest-numbered triangle, and the two files number the triangles differently. With the
// FBX's triangles in the OBJ's order the FBX as the low-poly bakes the OBJ's map. (Blender's export
// also changed the normals of 84 of the 1368 triangles, most of zero area; none of them is the one
// a texel keeps.)
TEST(DccPair, SpiderFbxAndObjBakeTheSameMapAsLowPoly) {
  const std::string dir = test::scratch_dir();
  const Mesh obj = load_mesh(obj_with_normals(dir)), fbx = load_mesh(kFbx);
  const Mesh high = load_mesh(smooth_copy(kObj, dir + "/obj_smooth.obj"));
  const Mesh fbx_in_obj_order = in_order_of(fbx, obj);
  ASSERT_EQ(fbx_in_obj_order.triangle_count(), obj.triangle_count()) << "a triangle of the OBJ is not in the FBX";
  BakeOptions o;
  o.width = o.height = kSize;
  const std::vector<std::uint8_t> every = diff::uv_layout_mask(obj, kSize, kSize);
  const Bake obj_low{bake_normal_map(obj, high, nullptr, o).map, every};
  const Bake fbx_low{bake_normal_map(fbx, high, nullptr, o).map, every};
  const Bake fbx_ordered{bake_normal_map(fbx_in_obj_order, high, nullptr, o).map, every};
  EXPECT_GE(mean_tilt(obj_low), 0.5);
  mean_difference(fbx_low, obj_low, "FBX low as numbered vs OBJ low:");  // for the record: 1.1 deg
  EXPECT_LE(mean_difference(fbx_ordered, obj_low, "FBX low in OBJ order vs OBJ low:"), 0.05);
}

// The comparison sees a misplaced high-poly: the OBJ 1% larger, 100 times larger (centimetres
// taken for metres), or turned 90 degrees about X (Z up read as Y up) bakes a map far from the
// FBX's, at least 4 times the 0.05 degrees allowed.
TEST(DccPair, AMisplacedHighPolyBakesAnotherMap) {
  const std::string dir = test::scratch_dir();
  const Mesh low = load_mesh(smooth_copy(kObj, dir + "/obj_smooth.obj"));
  BakeOptions o;
  o.width = o.height = kSize;
  const Bake reference{bake_normal_map(low, load_mesh(kFbx), nullptr, o).map, diff::uv_layout_mask(low, kSize, kSize)};
  const Mesh obj = load_mesh(obj_with_normals(dir));
  Mesh larger = obj, hundred = obj, turned = obj;
  for (glm::vec3& p : larger.positions) p *= 1.01f;
  for (glm::vec3& p : hundred.positions) p *= 100.0f;
  for (glm::vec3& p : turned.positions) p = glm::vec3(p.x, -p.z, p.y);
  for (glm::vec3& n : turned.normals) n = glm::vec3(n.x, -n.z, n.y);
  for (const auto& [mesh, what] : {std::pair<const Mesh*, const char*>{&larger, "OBJ high 1% larger vs FBX high:"},
                                   {&hundred, "OBJ high 100 times larger vs FBX high:"},
                                   {&turned, "OBJ high turned about X vs FBX high:"}}) {
    const Bake misplaced{bake_normal_map(low, *mesh, nullptr, o).map, reference.mask};
    EXPECT_GT(mean_difference(misplaced, reference, what), 0.2) << what;
  }
}

}  // namespace
}  // namespace nmbake
