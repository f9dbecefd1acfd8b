// Tests of load_mesh() on the real meshes under ../shared/data (skipped when it is absent): the
// sculpts, and the edge cases of the Assimp and CGAL sample meshes.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "mesh_io_test_helpers.h"

namespace nmbake {
namespace {

using test::shared_data_path;
using namespace mesh_io_test;

// Real meshes --------------------------------------------------------------------------------------

TEST(MeshIo, SculptCountsMatchGenerationJson) {
  SKIP_WITHOUT_SHARED_DATA();
  for (const char* name : {"torus_demo", "torus_s3", "suz_L3", "suz_L4"}) {
    std::string dir = shared_data_path(std::string("sculpts/") + name);
    std::ifstream json_file(dir + "/generation.json");
    ASSERT_TRUE(json_file) << dir;
    nlohmann::json generation = nlohmann::json::parse(json_file);

    MeshLoadInfo info;
    Mesh high = load_mesh(dir + "/high.ply", {}, &info);
    EXPECT_EQ(info.format, "ply-binary");
    EXPECT_EQ(high.positions.size(), generation["high"]["verts"].get<std::size_t>()) << name;
    EXPECT_EQ(high.triangle_count(), generation["high"]["tris"].get<std::size_t>()) << name;
    EXPECT_TRUE(high.has_normals()) << name;
    EXPECT_FALSE(high.has_uvs()) << name;
    EXPECT_EQ(info.zero_normals, 0u);

    Mesh low = load_mesh(dir + "/low.obj", {true}, &info);
    EXPECT_EQ(low.positions.size(), generation["low"]["verts"].get<std::size_t>()) << name;
    EXPECT_EQ(low.triangle_count(), generation["low"]["tris"].get<std::size_t>()) << name;
    EXPECT_TRUE(low.has_normals()) << name;
    EXPECT_TRUE(low.has_uvs()) << name;
    EXPECT_EQ(info.polygons_triangulated, 0u);
  }
  Mesh torus = load_mesh(shared_data_path("sculpts/torus_s3/high.ply"));
  EXPECT_EQ(torus.positions.size(), 196608u);
  EXPECT_EQ(torus.triangle_count(), 393216u);
}

struct SharedCase {
  const char* file;
  std::size_t triangles;  // 0: must fail with `error`
  const char* error = "";
};

TEST(MeshIo, AssimpEdgeCases) {
  SKIP_WITHOUT_SHARED_DATA();
  const SharedCase cases[] = {
      {"OBJ/box_UTF16BE.obj", 0, "looks like UTF-16 text"},
      // "3.1+e2" is not a number; reading it as 3.1 would silently move the vertex.
      {"OBJ/number_formats.obj", 0, "line 11: vertex 8 has a malformed number '3.1+e2'"},
      {"OBJ/box_without_lineending.obj", 12},
      {"OBJ/concave_polygon.obj", 64},  // one 66-gon, fanned
      {"OBJ/multiple_spaces.obj", 1},
      {"OBJ/testmixed.obj", 12},  // l and p statements ignored
      {"OBJ/cube_usemtl.obj", 12},
      {"OBJ/regr01.obj", 2710},
      {"OBJ/spider.obj", 1368},
      {"OBJ/WusonOBJ.obj", 3732},
      {"PLY/cube.ply", 12},
      {"PLY/cube_binary.ply", 12},
      {"PLY/cube_uv.ply", 12},
      {"PLY/Wuson.ply", 3732},  // has a stray "Created by Blender3D" header line
      {"OFF/Wuson.off", 3732},
      {"STL/Spider_ascii.stl", 1312},
      {"STL/Spider_binary.stl", 1312},
      {"STL/sphereWithHole.stl", 285},
  };
  for (const SharedCase& c : cases) {
    std::string path = shared_data_path(std::string("meshes/assimp/") + c.file);
    if (c.triangles == 0) {
      expect_error(path, {c.error});
      continue;
    }
    try {
      EXPECT_EQ(load_mesh(path).triangle_count(), c.triangles) << c.file;
    } catch (const Error& e) {
      ADD_FAILURE() << c.file << ": " << e.what();
    }
  }
}

TEST(MeshIo, AssimpRepairsAreReported) {
  SKIP_WITHOUT_SHARED_DATA();
  const std::string dir = shared_data_path("meshes/assimp/");
  MeshLoadInfo info;
  Mesh m = load_mesh(dir + "OBJ/spider.obj", {}, &info);  // one "vn 0 0 0"
  EXPECT_EQ(info.zero_normals, 1u);
  EXPECT_FALSE(m.has_normals());
  m = load_mesh(dir + "OBJ/regr01.obj", {}, &info);  // UVs on some faces only
  EXPECT_TRUE(info.uvs_dropped);
  expect_error(dir + "OBJ/regr01.obj", {"has no UVs"}, {true});
  m = load_mesh(dir + "PLY/cube_uv.ply", {true}, &info);
  EXPECT_EQ(m.positions.size(), 24u);
  EXPECT_TRUE(m.has_normals());
  EXPECT_EQ(info.polygons_triangulated, 6u);
  m = load_mesh(dir + "STL/Spider_binary.stl", {}, &info);
  EXPECT_EQ(info.file_faces, 1368u);
  EXPECT_EQ(info.degenerate_faces_dropped, 56u);
  EXPECT_EQ(m.positions.size(), 722u);  // welded by value (STL has no shared vertices)
}

TEST(MeshIo, WusonInThreeFormatsAgrees) {
  SKIP_WITHOUT_SHARED_DATA();
  const std::string dir = shared_data_path("meshes/assimp/");
  Mesh obj = load_mesh(dir + "OBJ/WusonOBJ.obj", {true});
  Mesh ply = load_mesh(dir + "PLY/Wuson.ply", {true});
  Mesh off = load_mesh(dir + "OFF/Wuson.off");
  EXPECT_EQ(obj.triangle_count(), ply.triangle_count());
  EXPECT_EQ(obj.triangle_count(), off.triangle_count());
  EXPECT_TRUE(obj.has_normals() && ply.has_normals());
  // The same surface: equal bounding boxes.
  auto bounds = [](const Mesh& m) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    return std::make_pair(lo, hi);
  };
  for (const Mesh* other : {&ply, &off}) {
    EXPECT_NEAR(glm::length(bounds(obj).first - bounds(*other).first), 0.0f, 1e-5f);
    EXPECT_NEAR(glm::length(bounds(obj).second - bounds(*other).second), 0.0f, 1e-5f);
  }
}

TEST(MeshIo, CgalOffMeshesLoadWithTheirHeaderCounts) {
  SKIP_WITHOUT_SHARED_DATA();
  for (const char* name : {"ChineseDragon-10kv", "armadillo", "bear", "bunny00", "camel", "cow", "elephant", "fandisk",
                           "lion-head", "man", "mushroom", "refined_elephant"}) {
    std::string path = shared_data_path(std::string("meshes/cgal/") + name + ".off");
    std::ifstream in(path);
    std::string magic;
    std::size_t vertices = 0, faces = 0;
    in >> magic >> vertices >> faces;
    MeshLoadInfo info;
    Mesh m = load_mesh(path, {}, &info);
    EXPECT_EQ(m.positions.size(), vertices) << name;
    EXPECT_EQ(info.file_faces, faces) << name;
    EXPECT_EQ(m.triangle_count(), faces) << name;  // all triangles
  }
}

}  // namespace
}  // namespace nmbake
