// The asset formats read through Assimp (issue 20, item 1): real files of the Assimp test set
// (data/assimp) load with their hard edges and seams, node transforms and FBX units are applied,
// and one scene saved as OBJ/PLY, GLB, FBX in centimetres and DAE bakes the same map.
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "io/mesh_io.h"
#include "nmdiff.h"
#include "pipeline/bake.h"
#include "test_support.h"

namespace nmbake {
namespace {

// Distinct normals the corners of the mesh use.
std::size_t distinct_normals(const Mesh& m) {
  std::vector<glm::vec3> seen;
  for (std::uint32_t i : m.normal_index)
    if (std::find(seen.begin(), seen.end(), m.normals[i]) == seen.end()) seen.push_back(m.normals[i]);
  return seen.size();
}

TEST(AssimpFormats, RealFilesLoadWithHardEdges) {
  struct Case {
    const char* file;
    const char* format;
    std::size_t triangles;
    bool uvs;
    std::size_t normals;  // distinct normals: a cube's 6 faces; 3DS's come from its smoothing groups
  };
  for (const Case& c : {Case{"BoxTextured.glb", "gltf", 12, true, 6}, Case{"BoxTextured.gltf", "gltf", 12, true, 6},
                        Case{"box.fbx", "fbx", 12, false, 6}, Case{"cube_with_2UVs.DAE", "dae", 12, true, 6},
                        Case{"cube_with_diffuse_texture.3DS", "3ds", 12, true, 10}}) {
    SCOPED_TRACE(c.file);
    MeshLoadInfo info;
    const Mesh m = load_mesh(test::data_path(std::string("assimp/") + c.file), {}, &info);
    EXPECT_EQ(info.format, c.format);
    EXPECT_EQ(m.triangle_count(), c.triangles);
    EXPECT_EQ(m.has_uvs(), c.uvs);
    // A cube: 8 corners welded, its normals kept per corner (hard edges; smooth ones would be 8).
    EXPECT_EQ(m.positions.size(), 8u);
    ASSERT_TRUE(m.has_normals());
    EXPECT_EQ(distinct_normals(m), c.normals);
    EXPECT_EQ(info.unit_scale, 1.0);
  }
}

TEST(AssimpFormats, MalformedFilesAreOneLineErrors) {
  const std::string dir = test::scratch_dir();
  const std::string bad = dir + "/bad.glb", empty = dir + "/empty.fbx", junk = dir + "/junk.dae";
  test::write_file(bad, std::string("glTF\x02\0\0\0\x10\0\0\0junkjunk", 20));
  test::write_file(empty, "");
  test::write_file(junk, "<?xml version=\"1.0\"?><COLLADA><library_geometries><geometry>");
  for (const std::string& path : {bad, empty, junk}) {
    try {
      load_mesh(path);
      ADD_FAILURE() << path << " loaded";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ": ", 0), 0u) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  test::write_file(dir + "/mesh.xyz123", "v 0 0 0\n");
  try {
    load_mesh(dir + "/mesh.xyz123");
    ADD_FAILURE() << "an unknown extension loaded";
  } catch (const InputError& e) {
    EXPECT_TRUE(test::contains(e.what(), "unknown file type '.xyz123'")) << e.what();
  }
}

// --uv-set picks a UV set of a file that has several (cube_with_2UVs.DAE); own formats have one.
TEST(AssimpFormats, UvSetPicksTheSet) {
  LoadOptions first, second, third;
  second.uv_set = 1;
  third.uv_set = 2;
  const std::string dae = test::data_path("assimp/cube_with_2UVs.DAE");
  const Mesh a = load_mesh(dae, first), b = load_mesh(dae, second);
  ASSERT_TRUE(a.has_uvs());
  ASSERT_TRUE(b.has_uvs());
  EXPECT_EQ(a.position_index, b.position_index);
  EXPECT_TRUE(a.uvs != b.uvs) << "set 1 read the same UVs as set 0";
  third.require_uvs = true;
  try {
    load_mesh(dae, third);
    ADD_FAILURE() << "UV set 2 of a file with two loaded";
  } catch (const InputError& e) {
    EXPECT_TRUE(test::contains(e.what(), "(UV set 2) has no UVs")) << e.what();
  }
  try {
    load_mesh(test::data_path("sample/torus_low.obj"), second);
    ADD_FAILURE() << "UV set 1 of an OBJ loaded";
  } catch (const InputError& e) {
    EXPECT_TRUE(test::contains(e.what(), ".obj files have one UV set")) << e.what();
  }
  const test::CliRun r = test::run_nmbake(dae + " " + dae + " -o m.png --size 32 --uv-set 1 --report r.json --allow-overlap");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.report["options"]["uv_set"], 1);
  EXPECT_EQ(test::run_nmbake(dae + " " + dae + " -o m.png --size 32 --uv-set 8").code, 1);
}

// `in` re-saved by Assimp's exporter as `format` (an Assimp export id) at `out`, its coordinates
// scaled by `scale` (an FBX in centimetres: 100, with the file's unit the exporter writes, 1 cm;
// the vertices themselves, as the FBX exporter leaves out the root node's transform).
// With `move`, the scene is also turned and moved by it, as a node's transform.
void export_scene(const std::string& in, const std::string& format, const std::string& out, double scale = 1.0,
                  const aiMatrix4x4* move = nullptr) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(in, aiProcess_ValidateDataStructure);
  ASSERT_NE(scene, nullptr) << importer.GetErrorString();
  for (unsigned i = 0; i < scene->mNumMeshes; ++i)
    for (unsigned v = 0; v < scene->mMeshes[i]->mNumVertices; ++v) scene->mMeshes[i]->mVertices[v] *= float(scale);
  if (move) {  // the old root, moved, under a new one (the exporters leave out the root's own transform)
    aiNode* top = new aiNode("moved");
    top->mChildren = new aiNode* [1] { scene->mRootNode };
    top->mNumChildren = 1;
    scene->mRootNode->mParent = top;
    scene->mRootNode->mTransformation = *move * scene->mRootNode->mTransformation;
    const_cast<aiScene*>(scene)->mRootNode = top;
  }
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(scene, format, out), AI_SUCCESS) << exporter.GetErrorString();
}

Image bake_assimp_files(const std::string& low_path, const std::string& high_path, double* unit_scale = nullptr) {
  MeshLoadInfo info;
  const test::MeshPair pair = test::load_pair(low_path, high_path, &info);
  if (unit_scale) *unit_scale = info.unit_scale;
  BakeOptions o;
  o.width = o.height = 256;
  return bake_normal_map(pair.low, pair.high, nullptr, o).map;
}

double mean_difference(const Image& a, const Image& b) {
  const double mean = diff::compare_normal_maps(a, b).mean_deg;
  std::printf("mean difference %.5f deg\n", mean);
  return mean;
}

TEST(AssimpFormats, OneSceneInEveryFormatBakesTheSameMap) {
  const std::string dir = test::scratch_dir();
  const std::string low = test::data_path("sample/torus_low.obj"), high = test::data_path("sample/torus_high.ply");
  export_scene(low, "glb2", dir + "/low.glb");
  export_scene(high, "glb2", dir + "/high.glb");
  // ASCII FBX: Assimp 5.2's binary FBX export cannot be read back by its own reader ("FBX-Tokenize
  // block offset is out of range"); the binary reader is tested on box.fbx above.
  export_scene(low, "fbxa", dir + "/low.fbx", 100.0);  // centimetres
  export_scene(high, "fbxa", dir + "/high.fbx", 100.0);
  export_scene(low, "collada", dir + "/low.dae");
  export_scene(high, "collada", dir + "/high.dae");
  const Image reference = bake_assimp_files(low, high);
  double scale = 0.0;
  const Image glb = bake_assimp_files(dir + "/low.glb", dir + "/high.glb", &scale);
  EXPECT_EQ(scale, 1.0);
  const Image fbx = bake_assimp_files(dir + "/low.fbx", dir + "/high.fbx", &scale);
  EXPECT_DOUBLE_EQ(scale, 0.01);
  const Image dae = bake_assimp_files(dir + "/low.dae", dir + "/high.dae");
  // Centimetres and metres line up: an FBX low-poly with a glTF high-poly, and the other way.
  const Image fbx_glb = bake_assimp_files(dir + "/low.fbx", dir + "/high.glb");
  const Image glb_fbx = bake_assimp_files(dir + "/low.glb", dir + "/high.fbx");
  const Image obj_fbx = bake_assimp_files(low, dir + "/high.fbx");
  EXPECT_LE(mean_difference(glb, reference), 0.05);
  EXPECT_LE(mean_difference(fbx, glb), 0.05);
  EXPECT_LE(mean_difference(dae, reference), 0.05);
  EXPECT_LE(mean_difference(fbx_glb, glb), 0.05);
  EXPECT_LE(mean_difference(glb_fbx, glb), 0.05);
  EXPECT_LE(mean_difference(obj_fbx, reference), 0.05);
}

// Each node's transform places its meshes: the pair turned and moved by a node transform bakes the
// map of the pair where it was.
TEST(AssimpFormats, NodeTransformsAreApplied) {
  const std::string dir = test::scratch_dir();
  const std::string low = test::data_path("sample/torus_low.obj"), high = test::data_path("sample/torus_high.ply");
  aiMatrix4x4 turn, shift;
  aiMatrix4x4::Rotation(0.7f, aiVector3D(0.3f, 1.0f, 0.2f).Normalize(), turn);
  aiMatrix4x4::Translation(aiVector3D(5.0f, -2.0f, 3.0f), shift);
  const aiMatrix4x4 move = shift * turn;
  export_scene(low, "glb2", dir + "/low.glb", 1.0, &move);
  export_scene(high, "glb2", dir + "/high.glb", 1.0, &move);
  const Mesh moved = load_mesh(dir + "/low.glb"), original = load_mesh(low);
  ASSERT_EQ(moved.positions.size(), original.positions.size());
  glm::dvec3 centre(0.0);
  for (const glm::vec3& p : moved.positions) centre += glm::dvec3(p);
  centre /= double(moved.positions.size());
  EXPECT_NEAR(centre.x, 5.0, 0.05);
  EXPECT_NEAR(centre.y, -2.0, 0.05);
  EXPECT_NEAR(centre.z, 3.0, 0.05);
  EXPECT_LE(mean_difference(bake_assimp_files(dir + "/low.glb", dir + "/high.glb"), bake_assimp_files(low, high)), 0.05);
}

// Triangles whose winding (counter-clockwise from the front) agrees with their corners' normals.
double share_wound_with_normals(const Mesh& m) {
  std::size_t agree = 0;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const glm::vec3 face =
        glm::cross(m.corner_position(t, 1) - m.corner_position(t, 0), m.corner_position(t, 2) - m.corner_position(t, 0));
    agree += glm::dot(face, m.corner_normal(t, 0) + m.corner_normal(t, 1) + m.corner_normal(t, 2)) > 0.0f;
  }
  return double(agree) / double(m.triangle_count());
}

// A mirroring node transform (negative determinant) turns the winding over; the reader reverses
// the corners so that triangles stay counter-clockwise from the side their normals face.
TEST(AssimpFormats, MirroringTransformsKeepTheWinding) {
  const std::string dir = test::scratch_dir();
  const std::string low = test::data_path("sample/torus_low.obj");
  aiMatrix4x4 mirror;
  aiMatrix4x4::Scaling(aiVector3D(-1.0f, 1.0f, 1.0f), mirror);
  export_scene(low, "glb2", dir + "/mirrored.glb", 1.0, &mirror);
  export_scene(low, "glb2", dir + "/plain.glb");
  const Mesh mirrored = load_mesh(dir + "/mirrored.glb"), plain = load_mesh(dir + "/plain.glb");
  EXPECT_GT(share_wound_with_normals(plain), 0.99);
  EXPECT_GT(share_wound_with_normals(mirrored), 0.99);
  EXPECT_LT(mirrored.positions[0].x * plain.positions[0].x, 0.0f) << "not mirrored";
}

}  // namespace
}  // namespace nmbake

namespace nmbake {
namespace {

// Bytes of another format under an Assimp extension are refused before Assimp reads them (its
// fallback to reading by signature took a broken PLY named .gltf into a reader that never ends).
TEST(AssimpFormats, ContentsMustFitTheExtension) {
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n";
  for (const char* name : {"a.gltf", "a.glb", "a.fbx", "a.dae"}) {
    try {
      load_mesh_from_memory(name, ply);
      ADD_FAILURE() << name << " loaded";
    } catch (const InputError& e) {
      EXPECT_TRUE(test::contains(e.what(), std::string(name) + ": is not a ." + (std::string(name).substr(2)) + " file"))
          << e.what();
    }
  }
  // Bytes that are not text in a COLLADA array: Assimp read them as numbers and allocated 12 GB over
  // 40 s; refused at once.
  const std::string junk = test::read_file(test::data_path("../tests/fuzz/corpus/oom_dae_fuzzed_3gb"));
  ASSERT_FALSE(junk.empty());
  try {
    load_mesh_from_memory("junk.dae", junk.substr(1));
    ADD_FAILURE() << "junk.dae loaded";
  } catch (const InputError& e) {
    EXPECT_TRUE(test::contains(e.what(), "junk.dae: malformed: <p> holds a byte that is not text")) << e.what();
  }
  // A glTF whose node hides its mesh by a scale of 0: finite normals (replaced by computed ones).
  const std::string hidden = test::read_file(test::data_path("../tests/fuzz/corpus/crash_gltf_node_scale_zero"));
  ASSERT_FALSE(hidden.empty());
  const Mesh m = load_mesh_from_memory("hidden.gltf", hidden.substr(1));
  for (const glm::vec3& n : m.normals) EXPECT_TRUE(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z));
}

}  // namespace
}  // namespace nmbake
