// Tests of load_mesh(): the defect meshes in data/defects (each fails with a message naming the
// file and the problem, or loads with a defined repair), PLY in every encoding and scalar type
// (written here, big-endian included), and the real meshes under ../shared/data when present.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "io/mesh_io.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::data_path;
using test::shared_data_path;

#define SKIP_WITHOUT_SHARED_DATA()               \
  if (!test::exists(shared_data_path("meshes"))) \
  GTEST_SKIP() << "../shared/data is absent (" << shared_data_path("meshes") << "); skipping"

std::string file_name(const std::string& path) { return path.substr(path.find_last_of('/') + 1); }

// The InputError message of loading `path`, or "" (plus a test failure) when it loads.
std::string load_error(const std::string& path, const LoadOptions& options = {}) {
  try {
    Mesh m = load_mesh(path, options);
    ADD_FAILURE() << path << " loaded (" << m.triangle_count() << " triangles) but should fail";
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expect_error(const std::string& path, std::initializer_list<const char*> words, const LoadOptions& options = {}) {
  std::string message = load_error(path, options);
  EXPECT_NE(message.find(file_name(path)), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
  for (const char* word : words)
    EXPECT_NE(message.find(word), std::string::npos) << "'" << word << "' not in: " << message;
}

void write_file(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

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
  for (const char* word : d.words)
    EXPECT_NE(message.find(word), std::string::npos) << "'" << word << "' not in: " << message;
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
    {"unknown_extension.fbx", {"unknown file type '.fbx'", ".obj .ply .off .stl"}},
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

TEST(MeshIo, StlDegenerateFacetIsCounted) {
  MeshLoadInfo info;
  Mesh m = load_mesh(data_path("defects/degenerate_facet.stl"), {}, &info);
  EXPECT_EQ(m.triangle_count(), 1u);
  EXPECT_EQ(info.file_faces, 2u);
  EXPECT_EQ(info.degenerate_faces_dropped, 1u);
}

// PLY in every encoding and type -------------------------------------------------------------------

// A PLY written by the test itself, value by value, so every encoding and type can be checked.
struct PlyProperty {
  std::string type;  // "float", "uint8", ...
  std::string name;
  std::string count_type;  // non-empty for a list
};
struct PlyElement {
  std::string name;
  std::vector<PlyProperty> properties;
  std::vector<std::vector<std::vector<double>>> rows;  // row -> property -> values (1 for a scalar)
};

void put_binary(std::string& out, const std::string& type, double v, bool big_endian) {
  auto put = [&](auto value) {
    unsigned char raw[sizeof(value)];
    std::memcpy(raw, &value, sizeof(value));
    for (std::size_t i = 0; i < sizeof(value); ++i)
      out.push_back(static_cast<char>(raw[big_endian ? sizeof(value) - 1 - i : i]));
  };
  if (type == "char" || type == "int8") return put(static_cast<std::int8_t>(v));
  if (type == "uchar" || type == "uint8") return put(static_cast<std::uint8_t>(v));
  if (type == "short" || type == "int16") return put(static_cast<std::int16_t>(v));
  if (type == "ushort" || type == "uint16") return put(static_cast<std::uint16_t>(v));
  if (type == "int" || type == "int32") return put(static_cast<std::int32_t>(v));
  if (type == "uint" || type == "uint32") return put(static_cast<std::uint32_t>(v));
  if (type == "float" || type == "float32") return put(static_cast<float>(v));
  if (type == "double" || type == "float64") return put(v);
  ADD_FAILURE() << "bad type " << type;
}

std::string make_ply(const std::string& format, const std::vector<PlyElement>& elements) {
  std::string out = "ply\nformat " + format + " 1.0\ncomment written by test_mesh_io\n";
  for (const PlyElement& e : elements) {
    out += "element " + e.name + " " + std::to_string(e.rows.size()) + "\n";
    for (const PlyProperty& p : e.properties)
      out += p.count_type.empty() ? "property " + p.type + " " + p.name + "\n"
                                  : "property list " + p.count_type + " " + p.type + " " + p.name + "\n";
  }
  out += "end_header\n";
  const bool ascii = format == "ascii", big = format == "binary_big_endian";
  for (const PlyElement& e : elements)
    for (const auto& row : e.rows) {
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& p = e.properties[k];
        if (!p.count_type.empty()) {
          if (ascii) {
            out += std::to_string(row[k].size()) + " ";
          } else {
            put_binary(out, p.count_type, double(row[k].size()), big);
          }
        }
        for (double v : row[k]) {
          if (ascii) {
            char buffer[32];
            std::snprintf(buffer, sizeof buffer, "%.9g ", v);
            out += buffer;
          } else {
            put_binary(out, p.type, v, big);
          }
        }
      }
      if (ascii) out += "\n";
    }
  return out;
}

// A quad and a triangle over 5 vertices with normals and UVs, with an unused element and unused
// scalar and list properties around the used ones.
std::vector<PlyElement> sample_ply(const std::string& coord_type, const std::string& count_type,
                                   const std::string& index_type, const char* u = "s", const char* v = "t") {
  PlyElement extra{"material", {{"uchar", "id", ""}, {"float", "weights", "uchar"}}, {}};
  extra.rows = {{{7}, {0.5, 0.25}}, {{8}, {}}};
  PlyElement vertex{"vertex",
                    {{coord_type, "x", ""},
                     {"uchar", "red", ""},
                     {coord_type, "y", ""},
                     {"int", "ring", "uchar"},
                     {coord_type, "z", ""},
                     {"float", "nx", ""},
                     {"float", "ny", ""},
                     {"float", "nz", ""},
                     {"float", u, ""},
                     {"float", v, ""}},
                    {}};
  const double p[5][3] = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {1, 3, -1}};
  for (int i = 0; i < 5; ++i)
    vertex.rows.push_back(
        {{p[i][0]}, {200}, {p[i][1]}, {1, 2, 3}, {p[i][2]}, {0}, {0}, {1}, {p[i][0] / 4}, {p[i][1] / 4}});
  PlyElement face{
      "face", {{"uchar", "flags", ""}, {index_type, "vertex_indices", count_type}, {"float", "quality", "uchar"}}, {}};
  face.rows = {{{1}, {0, 1, 2, 3}, {0.5}}, {{2}, {3, 2, 4}, {}}};
  PlyElement edge{"edge", {{"int", "vertex1", ""}, {"int", "vertex2", ""}}, {{{0}, {1}}}};
  return {extra, vertex, face, edge};
}

void expect_sample_mesh(const Mesh& m, const std::string& what) {
  ASSERT_EQ(m.positions.size(), 5u) << what;
  EXPECT_EQ(m.positions[4], glm::vec3(1, 3, -1)) << what;
  EXPECT_EQ(m.position_index, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3, 3, 2, 4})) << what;
  EXPECT_EQ(m.source_face, (std::vector<std::uint32_t>{0, 0, 1})) << what;
  ASSERT_TRUE(m.has_normals()) << what;
  EXPECT_EQ(m.corner_normal(2, 2), glm::vec3(0, 0, 1)) << what;
  ASSERT_TRUE(m.has_uvs()) << what;
  EXPECT_EQ(m.corner_uv(2, 2), glm::vec2(0.25f, 0.75f)) << what;
}

TEST(MeshIo, PlyEveryEncodingAndScalarType) {
  const std::string dir = test::scratch_dir();
  const char* formats[] = {"ascii", "binary_little_endian", "binary_big_endian"};
  const char* coord_types[] = {"float", "float32", "double", "float64", "char",
                               "int8",  "short",   "int16",  "int",     "int32"};
  const char* count_types[] = {"uchar", "uint8", "char", "ushort", "short", "int", "uint", "uint32"};
  const char* index_types[] = {"int", "int32", "uint", "uint32", "uchar", "uint8", "short", "ushort", "uint16", "char"};
  int n = 0;
  for (const char* format : formats) {
    for (const char* coord : coord_types) {
      std::string path = dir + "/coords_" + std::to_string(n++) + ".ply";
      write_file(path, make_ply(format, sample_ply(coord, "uchar", "int")));
      MeshLoadInfo info;
      expect_sample_mesh(load_mesh(path, {true}, &info), std::string(format) + " coords " + coord);
      EXPECT_EQ(info.format, std::string(format) == "ascii" ? "ply-ascii" : "ply-binary");
    }
    for (const char* count : count_types)
      for (const char* index : index_types) {
        std::string path = dir + "/faces_" + std::to_string(n++) + ".ply";
        write_file(path, make_ply(format, sample_ply("float", count, index)));
        expect_sample_mesh(load_mesh(path), std::string(format) + " list " + count + " " + index);
      }
  }
}

TEST(MeshIo, PlyBigEndianMatchesLittleEndianBitForBit) {
  const std::string dir = test::scratch_dir();
  std::vector<PlyElement> elements = sample_ply("float", "uchar", "int");
  elements[1].rows[4][0] = {0.1};  // a value with a full mantissa
  write_file(dir + "/le.ply", make_ply("binary_little_endian", elements));
  write_file(dir + "/be.ply", make_ply("binary_big_endian", elements));
  Mesh le = load_mesh(dir + "/le.ply"), be = load_mesh(dir + "/be.ply");
  ASSERT_EQ(le.positions.size(), be.positions.size());
  EXPECT_EQ(std::memcmp(le.positions.data(), be.positions.data(), le.positions.size() * sizeof(glm::vec3)), 0);
  EXPECT_EQ(be.positions[4].x, 0.1f);
  EXPECT_EQ(le.position_index, be.position_index);
}

TEST(MeshIo, PlyUvPropertyNames) {
  const std::string dir = test::scratch_dir();
  const char* names[][2] = {{"s", "t"}, {"u", "v"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}};
  for (const auto& uv : names) {
    std::string path = dir + "/" + uv[0] + ".ply";
    write_file(path, make_ply("binary_little_endian", sample_ply("float", "uchar", "int", uv[0], uv[1])));
    expect_sample_mesh(load_mesh(path, {true}), std::string("uv names ") + uv[0] + "/" + uv[1]);
  }
}

TEST(MeshIo, PlyPerCornerTexcoordList) {
  PlyElement vertex{"vertex", {{"float", "x", ""}, {"float", "y", ""}, {"float", "z", ""}}, {}};
  vertex.rows = {{{0}, {0}, {0}}, {{1}, {0}, {0}}, {{0}, {1}, {0}}};
  PlyElement face{"face", {{"int", "vertex_indices", "uchar"}, {"float", "texcoord", "uchar"}}, {}};
  face.rows = {{{0, 1, 2}, {0.1, 0.2, 0.3, 0.4, 0.5, 0.6}}};
  std::string path = test::scratch_dir() + "/texcoord.ply";
  write_file(path, make_ply("binary_little_endian", {vertex, face}));
  Mesh m = load_mesh(path, {true});
  ASSERT_TRUE(m.has_uvs());
  EXPECT_EQ(m.corner_uv(0, 2), glm::vec2(0.5f, 0.6f));
}

TEST(MeshIo, PlyNoUvsWithRequireUvs) {
  std::string path = test::scratch_dir() + "/plain.ply";
  std::vector<PlyElement> elements = sample_ply("float", "uchar", "int", "a", "b");
  write_file(path, make_ply("ascii", elements));
  expect_error(path, {"face 0 has no UVs"}, {true});
  EXPECT_FALSE(load_mesh(path).has_uvs());
}

TEST(MeshIo, PlyTruncatedInEveryElement) {
  const std::string dir = test::scratch_dir();
  std::string full = make_ply("binary_big_endian", sample_ply("double", "uchar", "int"));
  // Cutting anywhere inside the data must give a clean error; only a cut in the trailing edge
  // element (two ints), which is never read, may load.
  std::size_t header_end = full.find("end_header\n") + 11;
  for (std::size_t cut = header_end; cut < full.size(); ++cut) {
    std::string path = dir + "/cut.ply";
    write_file(path, full.substr(0, cut));
    try {
      load_mesh(path);
      EXPECT_GE(cut, full.size() - 8) << "loaded although cut at " << cut << " of " << full.size();
    } catch (const InputError& e) {
      std::string message = e.what();
      EXPECT_TRUE(message.find("truncated") != std::string::npos || message.find("bytes of data") != std::string::npos)
          << "cut at " << cut << ": " << message;
    }
  }
}

// OBJ and PLY of the same mesh agree ------------------------------------------------------------

std::vector<PlyElement> mesh_as_ply(const Mesh& m) {
  // Unshared corners, as OBJ's separate index streams cannot be written as PLY vertices otherwise.
  PlyElement vertex{"vertex",
                    {{"float", "x", ""},
                     {"float", "y", ""},
                     {"float", "z", ""},
                     {"float", "nx", ""},
                     {"float", "ny", ""},
                     {"float", "nz", ""},
                     {"float", "s", ""},
                     {"float", "t", ""}},
                    {}};
  PlyElement face{"face", {{"uint", "vertex_indices", "uchar"}}, {}};
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    std::vector<double> corners;
    for (int c = 0; c < 3; ++c) {
      glm::vec3 p = m.corner_position(t, c), n = m.corner_normal(t, c);
      glm::vec2 uv = m.corner_uv(t, c);
      vertex.rows.push_back({{p.x}, {p.y}, {p.z}, {n.x}, {n.y}, {n.z}, {uv.x}, {uv.y}});
      corners.push_back(double(3 * t + c));
    }
    face.rows.push_back({corners});
  }
  return {vertex, face};
}

TEST(MeshIo, SculptObjAndPlyAgree) {
  SKIP_WITHOUT_SHARED_DATA();
  Mesh obj = load_mesh(shared_data_path("sculpts/suz_L3/low.obj"), {true});
  std::string path = test::scratch_dir() + "/low.ply";
  write_file(path, make_ply("binary_big_endian", mesh_as_ply(obj)));
  Mesh ply = load_mesh(path, {true});
  ASSERT_EQ(ply.triangle_count(), obj.triangle_count());
  for (std::size_t t = 0; t < obj.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      ASSERT_EQ(ply.corner_position(t, c), obj.corner_position(t, c)) << "triangle " << t;
      ASSERT_EQ(ply.corner_uv(t, c), obj.corner_uv(t, c)) << "triangle " << t;
      ASSERT_NEAR(glm::length(ply.corner_normal(t, c) - obj.corner_normal(t, c)), 0.0f, 1e-6f) << "triangle " << t;
    }
}

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

TEST(MeshIo, LoadTimes) {
  SKIP_WITHOUT_SHARED_DATA();
  for (const char* file : {"sculpts/torus_s3/high.ply", "sculpts/suz_L4/low.obj"}) {
    double best = 1e9;
    std::size_t triangles = 0;
    for (int run = 0; run < 3; ++run) {
      auto start = std::chrono::steady_clock::now();
      Mesh m = load_mesh(shared_data_path(file));
      best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      triangles = m.triangle_count();
    }
    std::printf("[ timing   ] %s: %zu triangles in %.1f ms (best of 3)\n", file, triangles, best * 1e3);
  }
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
  EXPECT_EQ(m.positions.size(), 722u);  // welded by OpenMesh
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
