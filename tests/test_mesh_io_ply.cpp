// Tests of load_mesh() on PLY in every encoding and scalar type, written here value by value
// (big-endian included), and on an OBJ sculpt rewritten as PLY.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "io/mesh_io_detail.h"
#include "mesh_io_test_helpers.h"

namespace nmbake {
namespace {

using test::shared_data_path;
using namespace mesh_io_test;

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
    for (std::size_t i = 0; i < sizeof(value); ++i) out.push_back(static_cast<char>(raw[big_endian ? sizeof(value) - 1 - i : i]));
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
std::vector<PlyElement> sample_ply(const std::string& coord_type, const std::string& count_type, const std::string& index_type,
                                   const char* u = "s", const char* v = "t") {
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
    vertex.rows.push_back({{p[i][0]}, {200}, {p[i][1]}, {1, 2, 3}, {p[i][2]}, {0}, {0}, {1}, {p[i][0] / 4}, {p[i][1] / 4}});
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
  const char* coord_types[] = {"float", "float32", "double", "float64", "char", "int8", "short", "int16", "int", "int32"};
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

}  // namespace
}  // namespace nmbake

namespace nmbake {
namespace {

// A binary triangle mesh of n x n quads (two triangles each), large enough for several of the fast
// path's chunks, with the properties asked for.
std::string grid_ply(int n, const std::string& format, const std::string& coord, const std::string& count,
                     const std::string& index, bool normals, bool uvs, bool extra) {
  PlyElement before{"material", {{"uchar", "id", ""}}, {}};  // no rows: takes no bytes
  PlyElement vertex{"vertex", {{coord, "x", ""}, {coord, "y", ""}, {coord, "z", ""}}, {}};
  if (extra) vertex.properties.insert(vertex.properties.begin() + 1, {"uchar", "red", ""});
  if (normals) vertex.properties.insert(vertex.properties.end(), {{"float", "nx", ""}, {"float", "ny", ""}, {"float", "nz", ""}});
  if (uvs) vertex.properties.insert(vertex.properties.end(), {{"float", "s", ""}, {"float", "t", ""}});
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) {
      std::vector<std::vector<double>> row = {{x * 0.37 - 3.1}, {y * 0.29 + 1.7}, {std::sin(x * 0.1) * std::cos(y * 0.13)}};
      if (extra) row.insert(row.begin() + 1, {double((x * 7 + y) % 256)});
      if (normals) row.insert(row.end(), {{0.1}, {-0.2}, {0.97}});
      if (uvs) row.insert(row.end(), {{x / double(n)}, {y / double(n)}});
      vertex.rows.push_back(row);
    }
  PlyElement face{"face", {{index, "vertex_indices", count}}, {}};
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double a = y * (n + 1) + x, b = a + 1, c = a + n + 1, d = c + 1;
      face.rows.push_back({{a, b, d}});
      face.rows.push_back({{a, d, c}});
    }
  return make_ply(format, {before, vertex, face});
}

void expect_same_mesh(const mesh_io_detail::ParsedMesh& a, const mesh_io_detail::ParsedMesh& b, const std::string& what) {
  const Mesh &m = a.mesh, &n = b.mesh;
  EXPECT_EQ(std::memcmp(m.positions.data(), n.positions.data(), m.positions.size() * sizeof(glm::vec3)), 0) << what;
  ASSERT_EQ(m.positions.size(), n.positions.size()) << what;
  EXPECT_TRUE(a.exact_positions == b.exact_positions) << what;
  EXPECT_TRUE(m.normals == n.normals) << what;
  EXPECT_TRUE(m.uvs == n.uvs) << what;
  EXPECT_TRUE(m.position_index == n.position_index) << what;
  EXPECT_TRUE(m.uv_index == n.uv_index) << what;
  EXPECT_TRUE(m.normal_index == n.normal_index) << what;
  EXPECT_TRUE(m.source_face == n.source_face) << what;
  EXPECT_EQ(a.corner_uvs, b.corner_uvs) << what;
  EXPECT_EQ(a.corner_normals, b.corner_normals) << what;
  EXPECT_EQ(a.format, b.format) << what;
  EXPECT_EQ(a.file_faces, b.file_faces) << what;
  EXPECT_EQ(a.faces, b.faces) << what;
  EXPECT_EQ(a.faces_with_uvs, b.faces_with_uvs) << what;
  EXPECT_EQ(a.faces_with_normals, b.faces_with_normals) << what;
  EXPECT_EQ(a.first_face_without_uvs, b.first_face_without_uvs) << what;
}

}  // namespace

TEST(MeshIo, PlyFastPathReadsWhatTheGeneralReaderReads) {
  int fast = 0;
  for (const std::string coord : {"float", "double", "short"})
    for (const std::string count : {"uchar", "int"})
      for (const std::string index : {"int", "uint"})
        for (int props = 0; props < 4; ++props) {
          const bool normals = props & 1, uvs = props & 2, extra = props == 3;
          const std::string bytes = grid_ply(coord == "float" && index == "int" ? 190 : 20, "binary_little_endian", coord, count,
                                             index, normals, uvs, extra);
          const std::string what = coord + " " + count + " " + index + " props " + std::to_string(props);
          const auto quick = mesh_io_detail::parse_ply("grid.ply", bytes, true);
          const auto general = mesh_io_detail::parse_ply("grid.ply", bytes, false);
          EXPECT_TRUE(quick.fast_path) << what;
          EXPECT_FALSE(general.fast_path) << what;
          expect_same_mesh(quick, general, what);
          fast += quick.fast_path;
        }
  EXPECT_EQ(fast, 48);
  // The shared sculpt, as every bench scene is written.
  const std::string sculpt = shared_data_path("sculpts/suz_L4/high.ply");
  if (std::filesystem::exists(sculpt)) {
    const std::string bytes = test::read_file(sculpt);
    const auto quick = mesh_io_detail::parse_ply(sculpt, bytes, true);
    EXPECT_TRUE(quick.fast_path);
    expect_same_mesh(quick, mesh_io_detail::parse_ply(sculpt, bytes, false), sculpt);
  }
}

TEST(MeshIo, PlyFastPathLeavesEverythingElseToTheGeneralReader) {
  std::string base = grid_ply(30, "binary_little_endian", "float", "uchar", "int", true, true, false);
  const std::size_t data = base.find("end_header\n") + 11;
  const std::size_t vertex_bytes = 31 * 31 * 32, face0 = data + vertex_bytes;
  auto message = [](const std::string& bytes, bool fast) {
    try {
      mesh_io_detail::parse_ply("m.ply", bytes, fast);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // Files it does not take: read as before, the same mesh.
  std::vector<std::pair<std::string, std::string>> others = {
      {"big-endian", grid_ply(30, "binary_big_endian", "float", "uchar", "int", true, true, false)},
      {"ascii", grid_ply(5, "ascii", "float", "uchar", "int", false, false, false)},
      {"short indices", grid_ply(30, "binary_little_endian", "float", "uchar", "short", false, true, false)}};
  std::string quad = base;
  quad[face0] = 4;  // the first face claims 4 corners: the next face's count becomes its 4th index...
  others.push_back({"a face that is not a triangle", quad});
  for (const auto& [what, bytes] : others) {
    const std::string general = message(bytes, false);
    ASSERT_EQ(message(bytes, true), general) << what;
    if (general != "no error") continue;
    const auto quick = mesh_io_detail::parse_ply("m.ply", bytes, true);
    EXPECT_FALSE(quick.fast_path) << what;
    expect_same_mesh(quick, mesh_io_detail::parse_ply("m.ply", bytes, false), what);
  }
  // Files it refuses: the general reader's message, naming the element.
  std::string negative = base, far = base, nan = base;
  const std::int32_t minus_one = -1, too_far = 31 * 31;
  std::memcpy(&negative[face0 + 13 * 600 + 1], &minus_one, 4);
  std::memcpy(&far[face0 + 1 + 4], &too_far, 4);
  const float not_a_number = std::nanf("");
  std::memcpy(&nan[data + 32 * 700 + 4], &not_a_number, 4);
  for (const auto& [what, bytes] :
       std::vector<std::pair<std::string, std::string>>{{"negative index", negative},
                                                        {"index out of range", far},
                                                        {"NaN", nan},
                                                        {"truncated", base.substr(0, base.size() - 5)}}) {
    const std::string general = message(bytes, false);
    EXPECT_NE(general, "no error") << what;
    EXPECT_EQ(message(bytes, true), general) << what;
  }
}

// A file large enough to be read in parts on every core (mesh_io.cpp, FileBytes) loads as its bytes
// do from memory: the same mesh, and the normals' counts summed over the parallel chunks.
TEST(MeshIo, ALargeFileReadInPartsLoadsAsFromMemory) {
  const std::string bytes = grid_ply(450, "binary_little_endian", "float", "uchar", "int", true, true, false);
  ASSERT_GT(bytes.size(), std::size_t(8) << 20);
  const std::string path = test::scratch_dir() + "/grid.ply";
  test::write_file(path, bytes);
  MeshLoadInfo from_file, from_memory;
  const Mesh a = load_mesh(path, {}, &from_file);
  const Mesh b = load_mesh_from_memory(path, bytes, {}, &from_memory);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(glm::vec3)), 0);
  EXPECT_TRUE(a.normals == b.normals);
  EXPECT_TRUE(a.uvs == b.uvs);
  EXPECT_TRUE(a.position_index == b.position_index);
  EXPECT_EQ(from_file.normals_renormalized, a.positions.size());  // (0.1, -0.2, 0.97) is 0.995 long
  EXPECT_EQ(from_memory.normals_renormalized, from_file.normals_renormalized);
  EXPECT_EQ(from_file.largest_coordinate, from_memory.largest_coordinate);
}

}  // namespace nmbake
