// Tests of load_mesh() on the defect meshes in data/defects: each fails with a message naming the
// file and the problem, or loads with a defined repair; and the quirks of each format it accepts.
// PLY in every encoding: test_mesh_io_ply.cpp; real meshes: test_mesh_io_real_meshes.cpp.
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "mesh_io_test_helpers.h"

namespace nmbake {
namespace {

using test::data_path;
using namespace mesh_io_test;

// Defects that must be refused --------------------------------------------------------------------

struct Defect {
  const char* file;
  std::vector<const char*> words;
  bool require_uvs = false;
};

class DefectTest : public ::testing::TestWithParam<Defect> {};

TEST_P(DefectTest, FailsWithMessageNamingFileAndProblem) {
  const Defect& d = GetParam();
  LoadOptions options;
  options.require_uvs = d.require_uvs;
  std::string message = load_error(data_path(std::string("defects/") + d.file), options);
  EXPECT_NE(message.find(d.file), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  for (const char* word : d.words) EXPECT_NE(message.find(word), std::string::npos) << "'" << word << "' not in: " << message;
}

const Defect kDefects[] = {
    {"zero_bytes.obj", {"file is empty"}},
    {"empty.obj", {"file is empty"}},
    {"no_faces.obj", {"no faces"}},
    {"nan_vertex.obj", {"line 2", "vertex 2", "non-finite"}},
    {"inf_vertex.obj", {"line 3", "vertex 3", "non-finite"}},
    {"nan_uv.obj", {"line 5", "texture coordinate 2", "non-finite"}},
    {"nan_normal.obj", {"line 5", "normal 2", "non-finite"}},
    {"no_uvs.obj", {"line 5", "face 1 has no UVs"}, true},
    {"mixed_uvs.obj", {"line 9", "face 2 has no UVs"}, true},
    {"corner_mixed_uvs.obj", {"line 6", "face 1", "some corners"}},
    {"index_out_of_range.obj", {"line 5", "refers to vertex 9 but the file has 3"}},
    {"uv_index_out_of_range.obj", {"line 5", "texture coordinate 4 but the file has 1"}},
    {"zero_index.obj", {"line 4", "vertex 0"}},
    {"relative_index_out_of_range.obj", {"line 4", "vertex -4", "only 3"}},
    {"non_numeric.obj", {"line 2", "vertex 2", "malformed number 'abc'"}},
    {"malformed_number.obj", {"line 3", "malformed number '3.1+e2'"}},
    {"non_numeric_index.obj", {"line 4", "malformed vertex index 'x'"}},
    {"two_corner_face.obj", {"line 5", "face 2 has only 2 corners"}},
    {"too_few_coordinates.obj", {"line 2", "vertex 2", "too few"}},
    {"binary_garbage.obj", {"zero byte", "not an OBJ"}},
    {"utf16.obj", {"looks like UTF-16 text; save it as UTF-8"}},
    {"unknown_extension.xyz", {"unknown file type '.xyz'", ".obj .ply .off .stl", ".gltf .glb .fbx .dae .3ds"}},
    {"not_a_mesh.fbx", {"is not a .fbx file"}},
    {"inf_vertex.ply", {"vertex 1 has a non-finite coordinate"}},
    {"nan_normal.ply", {"vertex 2 has a non-finite normal"}},
    {"negative_count.ply", {"face", "negative count -5"}},
    {"huge_count.ply", {"4000000000 vertex", "bytes of data"}},
    {"huge_count_binary.ply", {"2147483648 face", "bytes of data"}},
    {"index_out_of_range.ply", {"face 1 refers to vertex 7 but the file has 3"}},
    {"negative_index.ply", {"face 0 refers to vertex -1"}},
    {"two_corner_face.ply", {"face 1 has only 2 corners"}},
    {"non_numeric.ply", {"vertex 1", "malformed value 'zero'"}},
    {"no_end_header.ply", {"end_header"}},
    {"bad_magic.ply", {"not a PLY file"}},
    {"unknown_type.ply", {"header line 4", "unknown property type 'int64'"}},
    {"no_vertex_indices.ply", {"vertex_indices"}},
    {"truncated_ascii.ply", {"truncated: file ends in face 1 of 2"}},
    {"truncated_binary.ply", {"truncated: file ends in face 1 of 2"}},
    {"truncated_vertices.ply", {"3 vertex", "20 bytes"}},
    {"index_out_of_range.off", {"face 0 refers to vertex 3 but the file has 3"}},
    {"huge_count.off", {"truncated", "vertex 4 of 1000000000"}},
    {"negative_count.off", {"negative count -1"}},
    {"huge_corner_count.off", {"face 0", "4000000000 corners"}},
    {"two_corner_face.off", {"face 1 has only 2 corners"}},
    {"nan_vertex.off", {"vertex 1 has a non-finite coordinate"}},
    {"binary.off", {"binary OFF is not supported"}},
    {"nan_vertex.stl", {"facet 0 has a non-finite coordinate"}},
    {"nan_vertex_binary.stl", {"facet 0 has a non-finite coordinate"}},
    {"four_vertex_facet.stl", {"facet 0 has 4 vertices"}},
    {"truncated_ascii.stl", {"truncated", "facet 1"}},
    {"truncated_binary.stl", {"truncated", "5 facets", "134 bytes"}},
    // Issue 5, hostile input: one of each defect in every format that can carry it.
    {"zero_bytes.ply", {"file is empty"}},
    {"zero_bytes.off", {"file is empty"}},
    {"zero_bytes.stl", {"file is empty"}},
    {"nan_vertex_binary.ply", {"vertex 1 has a non-finite coordinate"}},
    {"inf_vertex_binary.ply", {"vertex 2 has a non-finite coordinate"}},
    {"inf_vertex.off", {"line 4", "vertex 1 has a non-finite coordinate"}},
    {"inf_vertex_binary.stl", {"facet 0 has a non-finite coordinate"}},
    {"non_numeric_count.ply", {"header line 3", "needs a name and a count"}},
    {"overflow_count.ply", {"header line 3", "needs a name and a count"}},
    {"truncated_header.ply", {"no end_header"}},
    {"huge_list_count_binary.ply", {"truncated: file ends in face 0 of 1"}},
    {"negative_list_count.ply", {"face 0", "invalid length -3"}},
    {"float_index.ply", {"face 0 refers to vertex 1.5"}},
    {"non_numeric.off", {"line 4", "vertex 1 has a malformed number 'x'"}},
    {"non_numeric_count.off", {"line 2", "malformed vertex or face count 'four'"}},
    {"non_numeric.stl", {"line 5", "facet 0", "malformed vertex coordinate 'zero'"}},
    {"huge_facet_count.stl", {"truncated", "4294967295 facets", "134 bytes"}},
    {"huge_index.obj", {"line 5", "malformed vertex index '99999999999999999999'"}},
    {"huge_index_in_range_type.obj", {"line 5", "refers to vertex 4294967297 but the file has 3"}},
    // Found by the fuzzer (tests/fuzz/corpus/crash_ply_list_count_3e38): an ascii list length
    // beyond 2^64 was cast to an integer (undefined behaviour) before the size check.
    {"huge_list_count_ascii.ply", {"truncated: file ends in face 0 of 1"}},
    // Issue 21: a number longer than 63 characters was cut to its first 63 and read as 7.
    {"long_number.obj", {"line 1", "vertex 1", "non-finite"}},
    {"short_texcoords.off", {"line 5", "vertex 2 has fewer than 2 texture coordinate"}},
    // Issue 34, item 8: checked before Assimp reads them (deeper ones crashed it, the GLB's claim
    // was allocated, the cycles made it recurse for ever).
    {"glb_chunk_claims_4gb.glb", {"malformed: GLB chunk 0 claims 4026531840 bytes, 31 are left"}},
    {"gltf_nodes_1001_deep.gltf", {"malformed: node 1000 is nested more than 1000 deep"}},
    {"json_1001_deep.gltf", {"malformed: nested more than 1000 deep (at byte 1035)"}},
    {"dae_nodes_1001_deep.dae", {"malformed: nested more than 1000 deep (at byte 6073)"}},
    {"dae_instance_cycle.dae", {"malformed: node 'a' is its own ancestor (a cycle)"}},
    {"fbx_model_cycle.fbx", {"malformed: node '1000' is its own ancestor (a cycle)"}},
    {"fbx_records_1001_deep.fbx", {"malformed: FBX records nested more than 1000 deep (at byte 14027)"}},
};

std::string defect_test_name(const ::testing::TestParamInfo<Defect>& info) {
  std::string name = info.param.file;
  for (char& c : name)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Defects, DefectTest, ::testing::ValuesIn(kDefects), defect_test_name);

TEST(MeshIo, DefectsReadmeListsEveryFile) {
  std::ifstream readme(data_path("defects/README.md"));
  ASSERT_TRUE(readme) << "data/defects/README.md is missing";
  std::string text((std::istreambuf_iterator<char>(readme)), std::istreambuf_iterator<char>());
  for (const Defect& d : kDefects) EXPECT_NE(text.find(std::string("`") + d.file + "`"), std::string::npos) << d.file;
}

TEST(MeshIo, DirectoryAndMissingFile) {
  expect_error(data_path("defects"), {"defects: is a directory"});
  expect_error(data_path("defects/does_not_exist.obj"), {"cannot open", "No such file or directory"});
}

// Defects that load with a defined repair -------------------------------------------------------

TEST(MeshIo, RepeatedVertexIsKeptAsZeroAreaTriangle) {
  for (const char* file : {"defects/repeated_vertex.obj", "defects/repeated_vertex.off"}) {
    Mesh m = load_mesh(data_path(file));
    ASSERT_EQ(m.triangle_count(), 2u) << file;
    EXPECT_EQ(m.position_index[3], m.position_index[4]) << file;
  }
}

TEST(MeshIo, PartialNormalsAndUvsAreDropped) {
  MeshLoadInfo info;
  Mesh m = load_mesh(data_path("defects/mixed_normals.obj"), {}, &info);
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_FALSE(m.has_normals());
  EXPECT_TRUE(m.normals.empty());
  EXPECT_TRUE(info.normals_dropped);
  EXPECT_EQ(info.faces_without_normals, 1u);

  m = load_mesh(data_path("defects/mixed_uvs.obj"), {}, &info);
  EXPECT_FALSE(m.has_uvs());
  EXPECT_TRUE(info.uvs_dropped);
  EXPECT_EQ(info.faces_without_uvs, 1u);

  m = load_mesh(data_path("defects/no_uvs.obj"), {}, &info);  // no UVs at all: nothing dropped
  EXPECT_FALSE(m.has_uvs());
  EXPECT_FALSE(info.uvs_dropped);
  EXPECT_TRUE(m.has_normals());
}

TEST(MeshIo, ZeroNormalDropsAllNormals) {
  MeshLoadInfo info;
  Mesh m = load_mesh(data_path("defects/zero_normal.obj"), {}, &info);
  EXPECT_FALSE(m.has_normals());
  EXPECT_EQ(info.zero_normals, 1u);
  EXPECT_TRUE(info.normals_dropped);
}

TEST(MeshIo, NormalsAreRenormalized) {
  MeshLoadInfo info;
  Mesh m = load_mesh(data_path("defects/unnormalized_normals.obj"), {}, &info);
  ASSERT_TRUE(m.has_normals());
  EXPECT_EQ(info.normals_renormalized, 2u);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(glm::length(m.corner_normal(0, c)), 1.0f, 1e-6f);
  EXPECT_NEAR(m.corner_normal(0, 1).y, std::sqrt(0.5f), 1e-6f);
}

// Found by the fuzzer (tests/fuzz/corpus/crash_ply_huge_normal): a normal whose squared length
// overflows float came out as (0,0,0). Lengths are now taken in double.
TEST(MeshIo, HugeNormalsAreRenormalizedNotZeroed) {
  MeshLoadInfo info;
  Mesh m = load_mesh(data_path("defects/huge_normals.ply"), {}, &info);
  ASSERT_TRUE(m.has_normals());
  EXPECT_EQ(info.normals_renormalized, 3u);
  EXPECT_EQ(info.zero_normals, 0u);
  const float h = std::sqrt(0.5f), t = std::sqrt(1.0f / 3.0f);
  const glm::vec3 expected[3] = {{h, 0, h}, {0, 1, 0}, {-t, -t, -t}};
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.corner_normal(0, c)[k], expected[c][k], 1e-6f) << "corner " << c;
}

TEST(MeshIo, ObjRelativeIndices) {
  Mesh m = load_mesh(data_path("defects/relative_indices.obj"), {true});
  ASSERT_EQ(m.triangle_count(), 1u);
  EXPECT_EQ(m.position_index, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(m.uv_index, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(m.normal_index, (std::vector<std::uint32_t>{0, 0, 0}));
}

TEST(MeshIo, ObjCrlfTabsContinuationAndIgnoredStatements) {
  MeshLoadInfo info;
  std::string path = data_path("defects/crlf_tabs_continuation.obj");
  Mesh m = load_mesh(path, {}, &info);
  EXPECT_EQ(m.source, path);
  EXPECT_EQ(info.format, "obj");
  ASSERT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.positions[3], glm::vec3(1, 1, 0));  // the r g b after x y z is ignored
  // "f 1 2 \ 4 3" is one quad fanned (0,1,2), (0,2,3); then "f 1 2 3".
  EXPECT_EQ(m.position_index, (std::vector<std::uint32_t>{0, 1, 3, 0, 3, 2, 0, 1, 2}));
  EXPECT_EQ(m.source_face, (std::vector<std::uint32_t>{0, 0, 1}));
  EXPECT_EQ(info.file_faces, 2u);
  EXPECT_EQ(info.polygons_triangulated, 1u);
}

TEST(MeshIo, PolygonIsFannedFromItsFirstCorner) {
  std::string path = test::scratch_dir() + "/pentagon.obj";
  write_file(path, "v 0 0 0\nv 1 0 0\nv 1.5 1 0\nv 0.5 2 0\nv -0.5 1 0\nf 1 2 3 4 5\n");
  Mesh m = load_mesh(path);
  EXPECT_EQ(m.position_index, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 3, 4}));
  EXPECT_EQ(m.source_face, (std::vector<std::uint32_t>{0, 0, 0}));
}

TEST(MeshIo, PlySkipsUnusedElementsAndProperties) {
  MeshLoadInfo info;
  Mesh m = load_mesh(data_path("defects/extra_elements.ply"), {true}, &info);
  EXPECT_EQ(info.format, "ply-ascii");
  ASSERT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.positions[2], glm::vec3(1, 1, 0));
  EXPECT_EQ(m.positions[3], glm::vec3(0, 1, 0));
  EXPECT_EQ(m.uvs[3], glm::vec2(0, 1));
  EXPECT_EQ(m.position_index, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST(MeshIo, OffCommentsAndCountsOnTheHeaderLine) {
  MeshLoadInfo info;
  Mesh m = load_mesh(data_path("defects/comments_and_counts_on_header.off"), {}, &info);
  EXPECT_EQ(info.format, "off");
  ASSERT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.positions[2], glm::vec3(1, 1, 0));
  EXPECT_EQ(m.position_index, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 2, 3}));
}

// Found by the fuzzer (tests/fuzz/corpus/oom_off_face_trailing_tokens): OpenMesh's reader, which
// nmbake used then, left what follows a face's indices for the next face's corner count;
// 2552147483648 made it push 2^32 corners (1.6 GB). Face colours and other trailing tokens are ignored.
TEST(MeshIo, OffFaceColoursAndTrailingTokensAreIgnored) {
  MeshLoadInfo info;
  Mesh m = load_mesh(data_path("defects/face_colours.off"), {}, &info);
  EXPECT_EQ(info.file_faces, 3u);
  ASSERT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.positions[3], glm::vec3(0, 1, 0));
  EXPECT_EQ(m.position_index, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 0, 1, 2, 0, 2, 3}));
}

// NOFF normals and STOFF texture coordinates (OpenMesh's reader, used before, read neither).
TEST(MeshIo, OffNormalsAndTextureCoordinatesAreRead) {
  MeshLoadInfo info;
  Mesh m = load_mesh(data_path("defects/normals_colours_texcoords.off"), {true}, &info);
  ASSERT_TRUE(m.has_uvs());
  ASSERT_TRUE(m.has_normals());
  const glm::vec2 uvs[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (std::size_t t = 0; t < m.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = m.position_index[3 * t + c];
      EXPECT_EQ(m.corner_uv(t, c), uvs[v]) << "vertex " << v;
      EXPECT_EQ(m.corner_normal(t, c), glm::vec3(0, 0, 1)) << "vertex " << v;  // (0,0,2) renormalized
    }
  EXPECT_EQ(info.normals_renormalized, 1u);
}

TEST(MeshIo, LongNumbersAreParsedWhole) {
  Mesh m = load_mesh(data_path("defects/long_numbers_in_range.obj"));
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.positions[0].x, 1.0f);
  EXPECT_EQ(m.positions[1].x, 0.1f);
}

TEST(MeshIo, StlDegenerateFacetIsCounted) {
  MeshLoadInfo info;
  Mesh m = load_mesh(data_path("defects/degenerate_facet.stl"), {}, &info);
  EXPECT_EQ(m.triangle_count(), 1u);
  EXPECT_EQ(info.file_faces, 2u);
  EXPECT_EQ(info.degenerate_faces_dropped, 1u);
}

}  // namespace
}  // namespace nmbake
