// Materials and vertex colours from the mesh loaders (issue 35, material-id and vertex-color maps):
// OBJ usemtl and "v x y z r g b", PLY vertex red green blue [alpha] in every encoding (and the fast
// path), glTF and DAE written by Assimp's exporter, merge_meshes, and the bad and partial cases.
#include <assimp/Exporter.hpp>
#include <assimp/material.h>
#include <assimp/scene.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/normals.h"
#include "io/mesh_io_detail.h"
#include "mesh_io_test_helpers.h"

namespace nmbake {
namespace {

using namespace mesh_io_test;

using Rgba = std::array<double, 4>;

// The material names of the triangles, in order ("" for material "" or none).
std::vector<std::string> triangle_materials(const Mesh& m) {
  std::vector<std::string> names;
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    names.push_back(m.material_count() ? m.materials[m.material_of(t)] : std::string("(none)"));
  return names;
}

void expect_color(const glm::vec4& got, const Rgba& want, double tolerance, const std::string& what) {
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(got[k], want[std::size_t(k)], tolerance) << what << " channel " << k;
}

// OBJ ------------------------------------------------------------------------------------------------

TEST(MeshIoMaterials, ObjUsemtlNamesMaterialsInFirstUseOrder) {
  const std::string dir = test::scratch_dir();
  // A triangle before any usemtl (material ""), quads and a pentagon fanned into triangles, a name
  // met again, a name no face uses.
  write_file(dir + "/two.obj",
             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nv 1.5 1.5 0\n"
             "f 1 2 3\n"
             "usemtl red\n"
             "f 1 2 3 4\n"
             "usemtl  blue  \n"
             "f 2 5 6 7 3\n"
             "usemtl red\n"
             "f 1 3 4\n"
             "usemtl unused\n");
  MeshLoadInfo info;
  const Mesh m = load_mesh(dir + "/two.obj", {}, &info);
  ASSERT_EQ(m.triangle_count(), 7u);
  EXPECT_EQ(info.polygons_triangulated, 2u);
  EXPECT_EQ(m.materials, (std::vector<std::string>{"", "red", "blue"}));
  EXPECT_EQ(m.material_count(), 3u);
  EXPECT_EQ(triangle_materials(m), (std::vector<std::string>{"", "red", "red", "blue", "blue", "blue", "red"}));
  EXPECT_EQ(m.source_face, (std::vector<std::uint32_t>{0, 1, 1, 2, 2, 2, 3}));

  // First use, not first mention: "a" is named first but used after "b".
  write_file(dir + "/order.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nusemtl b\nf 1 2 3\nusemtl a\nf 1 2 3\n");
  const Mesh o = load_mesh(dir + "/order.obj");
  EXPECT_EQ(o.materials, (std::vector<std::string>{"b", "a"}));
  EXPECT_EQ(o.triangle_material, (std::vector<std::uint32_t>{0, 1}));
}

TEST(MeshIoMaterials, ObjWithOneOrNoMaterial) {
  const std::string dir = test::scratch_dir();
  write_file(dir + "/one.obj", "mtllib x.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl skin\nf 1 2 3\nf 3 2 1\n");
  write_file(dir + "/none.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 3 2 1\n");
  write_file(dir + "/bare.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl\nf 1 2 3\nusemtl late\n");
  const Mesh one = load_mesh(dir + "/one.obj"), none = load_mesh(dir + "/none.obj"), bare = load_mesh(dir + "/bare.obj");
  EXPECT_EQ(one.materials, (std::vector<std::string>{"skin"}));
  EXPECT_TRUE(one.triangle_material.empty());
  EXPECT_EQ(one.material_of(1), 0u);
  EXPECT_EQ(none.material_count(), 0u);
  EXPECT_TRUE(none.triangle_material.empty());
  EXPECT_EQ(none.material_of(1), 0u);
  // A bare `usemtl` is no material; "late" has no face: the file has none in the end.
  EXPECT_EQ(bare.material_count(), 0u);
  EXPECT_TRUE(bare.triangle_material.empty());
}

TEST(MeshIoMaterials, ObjVertexColoursXyzrgb) {
  const std::string dir = test::scratch_dir();
  write_file(dir + "/rgb.obj",
             "v 0 0 0 1 0 0\n"
             "v 1 0 0 0 0.5 0 # green\n"
             "v 1 1 0 0 0 1\n"
             "v 0 1 0 1.5 -0.25 0.25\n"  // clamped
             "f 1 2 3 4\n");
  write_file(dir + "/rgba.obj", "v 0 0 0 1 0 0 0.5\nv 1 0 0 0 1 0 1\nv 0 1 0 0 0 1 0\nf 1 2 3\n");
  write_file(dir + "/w.obj", "v 0 0 0 1\nv 1 0 0 1\nv 0 1 0 1\nf 1 2 3\n");
  MeshLoadInfo info;
  const Mesh rgb = load_mesh(dir + "/rgb.obj", {}, &info);
  ASSERT_TRUE(rgb.has_colors());
  EXPECT_FALSE(info.colors_dropped);
  EXPECT_EQ(rgb.color_index, rgb.position_index);
  const Rgba want[4] = {{1, 0, 0, 1}, {0, 0.5, 0, 1}, {0, 0, 1, 1}, {1, 0, 0.25, 1}};
  for (std::size_t t = 0; t < rgb.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c)
      expect_color(rgb.corner_color(t, c), want[rgb.position_index[3 * t + std::size_t(c)]], 1e-7, "rgb.obj");
  const Mesh rgba = load_mesh(dir + "/rgba.obj");
  ASSERT_TRUE(rgba.has_colors());
  expect_color(rgba.corner_color(0, 0), {1, 0, 0, 0.5}, 1e-7, "rgba.obj");
  expect_color(rgba.corner_color(0, 2), {0, 0, 1, 0}, 1e-7, "rgba.obj");
  // x y z w: no colour.
  const Mesh w = load_mesh(dir + "/w.obj", {}, &info);
  EXPECT_FALSE(w.has_colors());
  EXPECT_TRUE(w.colors.empty());
  EXPECT_FALSE(info.colors_dropped);
}

TEST(MeshIoMaterials, ObjPartialColoursAreDropped) {
  const std::string dir = test::scratch_dir();
  // Vertex 1 has none, vertices 2 and 3 do, vertex 4 (after them) has none.
  write_file(dir + "/partial_colors.obj", "v 0 0 0\nv 1 0 0 1 0 0\nv 1 1 0 0 1 0\nv 0 1 0\nf 1 2 3 4\n");
  MeshLoadInfo info;
  const Mesh m = load_mesh(dir + "/partial_colors.obj", {}, &info);
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_FALSE(m.has_colors());
  EXPECT_TRUE(m.colors.empty());
  EXPECT_TRUE(info.colors_dropped);
  EXPECT_EQ(info.vertices_without_colors, 2u);
}

TEST(MeshIoMaterials, NonFiniteColourIsAnErrorNamingFileAndVertex) {
  const std::string dir = test::scratch_dir();
  write_file(dir + "/nan_color.obj", "v 0 0 0 1 1 1\nv 1 0 0 nan 0 0\nv 0 1 0 1 1 1\nf 1 2 3\n");
  expect_error(dir + "/nan_color.obj", {"line 2", "vertex 2", "non-finite colour"});
  write_file(dir + "/inf_color.obj", "v 0 0 0 1 1 1\nv 1 0 0 0 0 0\nv 0 1 0 1 inf 1 1\nf 1 2 3\n");
  expect_error(dir + "/inf_color.obj", {"line 3", "vertex 3", "non-finite colour"});
}

// PLY ------------------------------------------------------------------------------------------------

void put_value(std::string& out, const std::string& type, double v, bool big_endian) {
  auto put = [&](auto value) {
    unsigned char raw[sizeof(value)];
    std::memcpy(raw, &value, sizeof(value));
    for (std::size_t i = 0; i < sizeof(value); ++i) out.push_back(static_cast<char>(raw[big_endian ? sizeof(value) - 1 - i : i]));
  };
  if (type == "uchar") return put(static_cast<std::uint8_t>(v));
  if (type == "ushort") return put(static_cast<std::uint16_t>(v));
  if (type == "int") return put(static_cast<std::int32_t>(v));
  if (type == "float") return put(static_cast<float>(v));
  if (type == "double") return put(v);
  ADD_FAILURE() << "bad type " << type;
}

// The unit quad (4 vertices, 2 triangles: faces of three int indices, as the fast path reads them)
// with `colors` per vertex as stored (0..255 for uchar), of PLY type `type`; alpha when `alpha`.
std::string quad_ply(const std::string& format, const std::string& type, const std::vector<Rgba>& colors, bool alpha) {
  const double xy[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const int faces[2][3] = {{0, 1, 2}, {0, 2, 3}};
  std::string out = "ply\nformat " + format + " 1.0\nelement vertex 4\n";
  out += "property float x\nproperty float y\nproperty float z\n";
  for (const char* channel : {"red", "green", "blue", "alpha"})
    if (alpha || std::string(channel) != "alpha") out += "property " + type + " " + channel + "\n";
  out += "element face 2\nproperty list uchar int vertex_indices\nend_header\n";
  const bool ascii = format == "ascii", big = format == "binary_big_endian";
  auto value = [&](const std::string& t, double v) {
    if (!ascii) return put_value(out, t, v, big);
    char text[40];
    std::snprintf(text, sizeof text, "%.9g ", v);
    out += text;
  };
  for (int v = 0; v < 4; ++v) {
    value("float", xy[v][0]);
    value("float", xy[v][1]);
    value("float", 0.0);
    for (int k = 0; k < (alpha ? 4 : 3); ++k) value(type, colors[std::size_t(v)][std::size_t(k)]);
    if (ascii) out += "\n";
  }
  for (const auto& f : faces) {
    value("uchar", 3);
    for (int k = 0; k < 3; ++k) value("int", f[k]);
    if (ascii) out += "\n";
  }
  return out;
}

TEST(MeshIoMaterials, PlyVertexColoursEveryEncodingAndType) {
  struct Case {
    const char* type;
    double max;  // what the type's 1.0 is stored as
    bool alpha;
  };
  const std::vector<Rgba> unit = {{1, 0, 0, 1}, {0, 0.2, 0, 0.6}, {0, 0, 1, 0}, {0.4, 0.4, 0.4, 1}};
  for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"})
    for (const Case& c : {Case{"uchar", 255, false}, Case{"uchar", 255, true}, Case{"ushort", 65535, true},
                          Case{"float", 1, false}, Case{"float", 1, true}, Case{"double", 1, true}}) {
      const std::string what = std::string(format) + " " + c.type + (c.alpha ? " rgba" : " rgb");
      SCOPED_TRACE(what);
      std::vector<Rgba> stored = unit;
      for (Rgba& rgba : stored)
        for (double& v : rgba) v = std::round(v * c.max * 1e6) / 1e6;  // 0.2 * 255 = 51 exactly
      MeshLoadInfo info;
      const Mesh m = load_mesh_from_memory("quad.ply", quad_ply(format, c.type, stored, c.alpha), {}, &info);
      ASSERT_EQ(m.triangle_count(), 2u);
      ASSERT_TRUE(m.has_colors());
      EXPECT_EQ(m.color_index, m.position_index);
      ASSERT_EQ(m.colors.size(), 4u);
      for (std::size_t v = 0; v < 4; ++v) {
        Rgba want = unit[v];
        if (!c.alpha) want[3] = 1.0;
        expect_color(m.colors[v], want, 1e-6, what);
      }
    }
}

TEST(MeshIoMaterials, PlyFastPathReadsTheSameColours) {
  const std::vector<Rgba> stored = {{255, 0, 0, 255}, {0, 51, 0, 153}, {0, 0, 255, 0}, {102, 102, 102, 255}};
  for (bool alpha : {false, true}) {
    const std::string bytes = quad_ply("binary_little_endian", "uchar", stored, alpha);
    const auto quick = mesh_io_detail::parse_ply("quad.ply", bytes, true);
    const auto general = mesh_io_detail::parse_ply("quad.ply", bytes, false);
    EXPECT_TRUE(quick.fast_path);
    EXPECT_FALSE(general.fast_path);
    ASSERT_EQ(quick.mesh.colors.size(), 4u);
    ASSERT_EQ(general.mesh.colors.size(), 4u);
    for (std::size_t v = 0; v < 4; ++v) {
      EXPECT_EQ(quick.mesh.colors[v], general.mesh.colors[v]) << "vertex " << v;
      EXPECT_FLOAT_EQ(quick.mesh.colors[v].a, alpha ? float(stored[v][3] / 255.0) : 1.0f);
    }
    EXPECT_FLOAT_EQ(quick.mesh.colors[1].g, 0.2f);
  }
}

TEST(MeshIoMaterials, PlyNonFiniteColourIsAnErrorNamingTheVertex) {
  const std::string dir = test::scratch_dir();
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const std::vector<Rgba> bad = {{1, 0, 0, 1}, {0, 1, 0, 1}, {0, nan, 1, 1}, {1, 1, 1, inf}};
  for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    SCOPED_TRACE(format);
    const std::string path = dir + "/nan_color_" + format + ".ply";
    write_file(path, quad_ply(format, "float", bad, true));
    expect_error(path, {"vertex 2", "non-finite colour"});
  }
}

TEST(MeshIoMaterials, PlyWithoutAColourChannelHasNoColours) {
  // red and green only: no colour (as nx ny without nz is no normal).
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar alpha\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n0 0 0 1 2 3\n1 0 0 1 2 3\n0 1 0 1 2 3\n3 0 1 2\n";
  MeshLoadInfo info;
  const Mesh m = load_mesh_from_memory("rg.ply", ply, {}, &info);
  EXPECT_EQ(m.triangle_count(), 1u);
  EXPECT_FALSE(m.has_colors());
  EXPECT_FALSE(info.colors_dropped);
}

// OFF and STL have no colours or materials.
TEST(MeshIoMaterials, OffAndStlHaveNone) {
  const Mesh off = load_mesh_from_memory("t.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  const Mesh stl = load_mesh_from_memory(
      "t.stl",
      "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n");
  for (const Mesh* m : {&off, &stl}) {
    EXPECT_EQ(m->triangle_count(), 1u);
    EXPECT_FALSE(m->has_colors());
    EXPECT_EQ(m->material_count(), 0u);
  }
}

// glTF and DAE through Assimp -------------------------------------------------------------------------

// A scene of three quads side by side, each its own mesh (meshes 0 and 2 of material "red_mat",
// mesh 1 of "blue_mat"), vertex colours on every mesh (or not on mesh 1 with `partial`), written
// by Assimp's exporter as `format` at `path`.
void export_colored_scene(const std::string& format, const std::string& path, bool partial = false, float bad_value = 0.25f) {
  auto scene = std::make_unique<aiScene>();
  scene->mNumMaterials = 2;
  scene->mMaterials = new aiMaterial*[2];
  for (unsigned k = 0; k < 2; ++k) {
    scene->mMaterials[k] = new aiMaterial;
    const aiString name(k == 0 ? "red_mat" : "blue_mat");
    scene->mMaterials[k]->AddProperty(&name, AI_MATKEY_NAME);
  }
  scene->mNumMeshes = 3;
  scene->mMeshes = new aiMesh*[3];
  for (unsigned i = 0; i < 3; ++i) {
    auto* mesh = new aiMesh;
    mesh->mName = aiString("quad" + std::to_string(i));
    mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    mesh->mMaterialIndex = i == 1 ? 1 : 0;
    mesh->mNumVertices = 4;
    mesh->mVertices = new aiVector3D[4];
    mesh->mNormals = new aiVector3D[4];
    const float x0 = 2.0f * float(i);
    const float xy[4][2] = {{x0, 0}, {x0 + 1, 0}, {x0 + 1, 1}, {x0, 1}};
    for (unsigned v = 0; v < 4; ++v) {
      mesh->mVertices[v] = aiVector3D(xy[v][0], xy[v][1], 0);
      mesh->mNormals[v] = aiVector3D(0, 0, 1);
    }
    if (!(partial && i == 1)) {
      mesh->mColors[0] = new aiColor4D[4];
      // Vertex v of mesh i: (i/4, v/4, bad_value or 0.25 on vertex 3 of mesh 2, 1 - v/8).
      for (unsigned v = 0; v < 4; ++v)
        mesh->mColors[0][v] = aiColor4D(float(i) / 4, float(v) / 4, i == 2 && v == 3 ? bad_value : 0.25f, 1.0f - float(v) / 8);
    }
    mesh->mNumFaces = 2;
    mesh->mFaces = new aiFace[2];
    const unsigned faces[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (unsigned f = 0; f < 2; ++f) {
      mesh->mFaces[f].mNumIndices = 3;
      mesh->mFaces[f].mIndices = new unsigned[3]{faces[f][0], faces[f][1], faces[f][2]};
    }
    scene->mMeshes[i] = mesh;
  }
  scene->mRootNode = new aiNode("root");
  scene->mRootNode->mNumMeshes = 3;
  scene->mRootNode->mMeshes = new unsigned[3]{0, 1, 2};
  Assimp::Exporter exporter;
  ASSERT_EQ(exporter.Export(scene.get(), format, path), AI_SUCCESS) << exporter.GetErrorString();
}

// The colour export_colored_scene gives the corner at x, y (mesh i = floor(x / 2)).
Rgba scene_color(const glm::vec3& p) {
  const int i = int(std::floor(p.x / 2.0f + 0.01f));
  const float x = p.x - 2.0f * float(i);
  const int v = x < 0.5f ? (p.y < 0.5f ? 0 : 3) : (p.y < 0.5f ? 1 : 2);
  return {double(i) / 4, double(v) / 4, 0.25, 1.0 - double(v) / 8};
}

TEST(MeshIoMaterials, GltfAndDaeMaterialsAndColours) {
  const std::string dir = test::scratch_dir();
  struct Case {
    const char* format;  // Assimp's export id
    const char* file;
    double tolerance;  // DAE writes its floats as text
    bool alpha;        // Assimp's COLLADA exporter writes RGB only: alpha reads back 1
  };
  for (const Case& c : {Case{"glb2", "scene.glb", 1e-6, true}, Case{"gltf2", "scene.gltf", 1e-6, true},
                        Case{"collada", "scene.dae", 1e-5, false}}) {
    SCOPED_TRACE(c.file);
    export_colored_scene(c.format, dir + "/" + c.file);
    MeshLoadInfo info;
    const Mesh m = load_mesh(dir + "/" + c.file, {}, &info);
    ASSERT_EQ(m.triangle_count(), 6u);
    // Meshes of one material share it by name.
    EXPECT_EQ(m.material_count(), 2u);
    ASSERT_TRUE(m.has_colors());
    EXPECT_FALSE(info.colors_dropped);
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      glm::vec3 centre(0.0f);
      for (int k = 0; k < 3; ++k) centre += m.corner_position(t, k) / 3.0f;
      const std::string material = centre.x > 2.0f && centre.x < 3.0f ? "blue_mat" : "red_mat";
      ASSERT_LT(m.material_of(t), m.materials.size());
      EXPECT_EQ(m.materials[m.material_of(t)], material) << "triangle " << t << " at x " << centre.x;
      for (int k = 0; k < 3; ++k) {
        Rgba want = scene_color(m.corner_position(t, k));
        if (!c.alpha) want[3] = 1.0;
        expect_color(m.corner_color(t, k), want, c.tolerance, "triangle " + std::to_string(t));
      }
    }
  }
}

TEST(MeshIoMaterials, GltfPartialColoursAreDroppedAndNonFiniteRefused) {
  const std::string dir = test::scratch_dir();
  export_colored_scene("glb2", dir + "/partial.glb", true);
  MeshLoadInfo info;
  const Mesh m = load_mesh(dir + "/partial.glb", {}, &info);
  EXPECT_EQ(m.triangle_count(), 6u);
  EXPECT_FALSE(m.has_colors());
  EXPECT_TRUE(info.colors_dropped);
  EXPECT_EQ(info.vertices_without_colors, 4u);
  EXPECT_EQ(m.material_count(), 2u);

  export_colored_scene("glb2", dir + "/nan_color.glb", false, std::numeric_limits<float>::quiet_NaN());
  expect_error(dir + "/nan_color.glb", {"vertex 3", "non-finite colour"});
}

// glTF primitives: one of an unnamed material, one of a named one, one without a material (Assimp
// gives it an unnamed material of its own, after the file's).
TEST(MeshIoMaterials, GltfUnnamedMaterialsAndPrimitivesWithoutOne) {
  const std::string buffer = "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA";
  const std::string head =
      R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
      R"("buffers":[{"byteLength":36,"uri":")" +
      buffer +
      R"("}],"bufferViews":[{"buffer":0,"byteLength":36}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}],)";
  const std::string three =
      head + R"("materials":[{},{"name":"named"}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"material":0},)"
             R"({"attributes":{"POSITION":0},"material":1},{"attributes":{"POSITION":0}}]}]})";
  const Mesh m = load_mesh_from_memory("three.gltf", three);
  ASSERT_EQ(m.triangle_count(), 3u);
  EXPECT_EQ(triangle_materials(m), (std::vector<std::string>{"material 0", "named", ""}));
  // A file without materials has none, though Assimp gives its primitives one.
  const std::string none = head + R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}]})";
  const Mesh n = load_mesh_from_memory("none.gltf", none);
  EXPECT_EQ(n.triangle_count(), 1u);
  EXPECT_EQ(n.material_count(), 0u);
}

// merge_meshes ------------------------------------------------------------------------------------------

TEST(MeshIoMaterials, MergeUnitesMaterialsByNameAndKeepsColoursOfAll) {
  const std::string dir = test::scratch_dir();
  write_file(dir + "/a.obj", "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 0 1 0 1 0 0\nusemtl red\nf 1 2 3\nusemtl blue\nf 3 2 1\n");
  write_file(dir + "/b.obj",
             "v 0 0 1 0 1 0\nv 1 0 1 0 1 0\nv 0 1 1 0 1 0\nv 1 1 1 0 1 0\nusemtl green\nf 1 2 3\nusemtl blue\nf 2 4 3\n");
  write_file(dir + "/plain.obj", "v 0 0 2\nv 1 0 2\nv 0 1 2\nf 1 2 3\n");
  const Mesh a = load_mesh(dir + "/a.obj"), b = load_mesh(dir + "/b.obj"), plain = load_mesh(dir + "/plain.obj");

  const Mesh ab = merge_meshes({a, b});
  ASSERT_EQ(ab.triangle_count(), 4u);
  EXPECT_EQ(ab.materials, (std::vector<std::string>{"red", "blue", "green"}));
  EXPECT_EQ(triangle_materials(ab), (std::vector<std::string>{"red", "blue", "green", "blue"}));
  ASSERT_TRUE(ab.has_colors());
  EXPECT_EQ(ab.colors.size(), 7u);
  for (std::size_t t = 0; t < 4; ++t)
    for (int c = 0; c < 3; ++c) expect_color(ab.corner_color(t, c), t < 2 ? Rgba{1, 0, 0, 1} : Rgba{0, 1, 0, 1}, 0, "merged");

  // A part without colours drops them; a part without materials has "".
  const Mesh abp = merge_meshes({a, b, plain});
  EXPECT_FALSE(abp.has_colors());
  EXPECT_TRUE(abp.colors.empty());
  EXPECT_EQ(abp.materials, (std::vector<std::string>{"red", "blue", "green", ""}));
  EXPECT_EQ(triangle_materials(abp), (std::vector<std::string>{"red", "blue", "green", "blue", ""}));

  // No part names a material: none.
  const Mesh plains = merge_meshes({plain, plain});
  EXPECT_EQ(plains.material_count(), 0u);
  EXPECT_TRUE(plains.triangle_material.empty());
  // One material across the parts: triangle_material stays empty.
  write_file(dir + "/c.obj", "v 0 0 3\nv 1 0 3\nv 0 1 3\nusemtl red\nf 1 2 3\n");
  const Mesh c = load_mesh(dir + "/c.obj");
  const Mesh cc = merge_meshes({c, c});
  EXPECT_EQ(cc.materials, (std::vector<std::string>{"red"}));
  EXPECT_TRUE(cc.triangle_material.empty());
}

// Hostile input -------------------------------------------------------------------------------------

// What load_mesh promises of the new arrays (mesh.h), on a mesh it returned.
void expect_consistent(const Mesh& m, const std::string& what) {
  const std::size_t tris = m.triangle_count();
  if (m.has_colors()) {
    ASSERT_EQ(m.color_index.size(), 3 * tris) << what;
    for (std::uint32_t i : m.color_index) ASSERT_LT(i, m.colors.size()) << what;
    for (const glm::vec4& c : m.colors)
      for (int k = 0; k < 4; ++k) ASSERT_TRUE(c[k] >= 0.0f && c[k] <= 1.0f) << what << ": colour value " << c[k];
  } else {
    EXPECT_TRUE(m.colors.empty()) << what;
  }
  if (!m.triangle_material.empty()) {
    ASSERT_EQ(m.triangle_material.size(), tris) << what;
    ASSERT_GE(m.material_count(), 2u) << what;
    for (std::uint32_t k : m.triangle_material) ASSERT_LT(k, m.material_count()) << what;
  }
  if (m.material_count() == 1) {
    EXPECT_FALSE(m.materials[0].empty()) << what;
  }
}

// Files with colours and materials with bytes overwritten, cut or repeated (fixed seed): each
// loads with consistent arrays or is refused with an InputError, never anything else.
TEST(MeshIoMaterials, MutatedFilesLoadConsistentOrAreRefused) {
  const std::vector<Rgba> stored = {{255, 0, 0, 255}, {0, 51, 0, 153}, {0, 0, 255, 0}, {102, 102, 102, 255}};
  const std::vector<Rgba> unit = {{1, 0, 0, 1}, {0, 0.2, 0, 0.6}, {0, 0, 1, 0}, {0.4, 0.4, 0.4, 1}};
  const std::pair<std::string, std::string> seeds[] = {
      {"m.obj",
       "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 1 1 0 0 0 1 0.5\nv 0 1 0 1 1 1\nusemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\n"
       "usemtl a\nf 4 3 2 1\n"},
      {"m.ply", quad_ply("ascii", "uchar", stored, true)},
      {"m.ply", quad_ply("binary_little_endian", "uchar", stored, false)},
      {"m.ply", quad_ply("binary_little_endian", "float", unit, true)},
      {"m.ply", quad_ply("binary_big_endian", "ushort", stored, true)},
  };
  std::uint64_t state = 12111;
  auto next = [&](std::uint64_t n) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return (state >> 33) % n;
  };
  const char junk[] = {'0', '9', '-', '.', 'e', ' ', '\n', 'n', 'a', 'f', '#', '\0', '\xff', '\x7f', '3', '1'};
  int loaded = 0, refused = 0;
  for (const auto& [name, seed] : seeds)
    for (int round = 0; round < 300; ++round) {
      std::string bytes = seed;
      for (std::uint64_t k = 1 + next(4); k-- > 0;) {
        const std::size_t at = next(bytes.size());
        switch (next(3)) {
          case 0: bytes[at] = junk[next(sizeof junk)]; break;
          case 1: bytes.resize(at); break;
          default: bytes.insert(at, bytes.substr(at, next(16))); break;
        }
        if (bytes.empty()) bytes = "v";
      }
      const std::string what = name + " round " + std::to_string(round);
      try {
        MeshLoadInfo info;
        const Mesh m = load_mesh_from_memory(name, bytes, {}, &info);
        expect_consistent(m, what);
        ++loaded;
      } catch (const InputError&) {
        ++refused;
      }
    }
  std::printf("%d loaded, %d refused\n", loaded, refused);
  EXPECT_GT(loaded, 50);
  EXPECT_GT(refused, 50);
}

}  // namespace
}  // namespace nmbake
