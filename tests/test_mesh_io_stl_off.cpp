// Tests of load_mesh() on STL (ascii and binary) and OFF, read by our own readers (mesh_io_stl.cpp,
// mesh_io_off.cpp): the layouts real exporters write, welding and dropped facets, errors naming the
// facet, exact OFF coordinates, and an STOFF low-poly that bakes as the same mesh in OBJ.
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "mesh_io_test_helpers.h"
#include "pipeline/bake.h"

namespace nmbake {
namespace {

using namespace mesh_io_test;

// The unit quad as two facets, corners in this order.
const glm::vec3 kQuad[2][3] = {{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}};

std::string number(float v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", double(v));
  return text;
}

// ASCII STL of `facets`, with `eol` line ends, `facet` the facet's line and `outer` the loop's
// ("": no "outer loop" and "endloop").
std::string ascii_stl(const std::vector<std::array<glm::vec3, 3>>& facets, const std::string& eol = "\n",
                      const std::string& facet = "facet normal 0 0 1", const std::string& outer = "outer loop") {
  std::string s = "solid test" + eol;
  for (const auto& f : facets) {
    s += "  " + facet + eol;
    if (!outer.empty()) s += "    " + outer + eol;
    for (const glm::vec3& p : f) s += "      vertex " + number(p.x) + " " + number(p.y) + " " + number(p.z) + eol;
    if (!outer.empty()) s += "    endloop" + eol;
    s += "  endfacet" + eol;
  }
  return s + "endsolid test" + eol;
}

std::string binary_stl(const std::vector<std::array<glm::vec3, 3>>& facets) {
  std::string s(80, ' ');
  s.replace(0, 5, "solid");  // as some exporters write it: the size decides, not the first word
  const auto count = static_cast<std::uint32_t>(facets.size());
  s.append(reinterpret_cast<const char*>(&count), 4);
  for (const auto& f : facets) {
    const float values[12] = {0, 0, 1, f[0].x, f[0].y, f[0].z, f[1].x, f[1].y, f[1].z, f[2].x, f[2].y, f[2].z};
    s.append(reinterpret_cast<const char*>(values), sizeof values);
    s.append(2, '\0');
  }
  return s;
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::vector<std::array<glm::vec3, 3>> quad_facets() {
  return {{kQuad[0][0], kQuad[0][1], kQuad[0][2]}, {kQuad[1][0], kQuad[1][1], kQuad[1][2]}};
}

Mesh load_text(const std::string& name, const std::string& bytes, MeshLoadInfo* info = nullptr) {
  const std::string path = test::scratch_dir() + "/" + name;
  write_file(path, bytes);
  return load_mesh(path, {}, info);
}

void expect_quad(const Mesh& m, const std::string& what) {
  ASSERT_EQ(m.positions.size(), 4u) << what;
  EXPECT_EQ(m.positions[0], glm::vec3(0, 0, 0)) << what;
  EXPECT_EQ(m.positions[1], glm::vec3(1, 0, 0)) << what;
  EXPECT_EQ(m.positions[2], glm::vec3(1, 1, 0)) << what;
  EXPECT_EQ(m.positions[3], glm::vec3(0, 1, 0)) << what;
  EXPECT_EQ(m.position_index, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3})) << what;
  EXPECT_EQ(m.source_face, (std::vector<std::uint32_t>{0, 1})) << what;
  EXPECT_FALSE(m.has_normals()) << what;  // facet normals are not vertex normals
  EXPECT_FALSE(m.has_uvs()) << what;
}

// STL ---------------------------------------------------------------------------------------------

// Layouts OpenMesh's reader misread (it took the three lines after any line containing "outer" as
// the vertices, and nothing else): each must give the quad.
TEST(StlReader, AsciiLayoutsOfRealExportersGiveTheSameMesh) {
  const auto q = quad_facets();
  const std::pair<const char*, std::string> layouts[] = {
      {"plain", ascii_stl(q)},
      {"crlf", ascii_stl(q, "\r\n")},
      {"upper case", upper(ascii_stl(q))},
      {"no outer loop", ascii_stl(q, "\n", "facet normal 0 0 1", "")},
      {"no facet normal", ascii_stl(q, "\n", "facet")},
      {"nan facet normal", ascii_stl(q, "\n", "facet normal nan nan nan")},
      {"tabs", ascii_stl(q, "\n\t")},
      {"name with outer", "solid outer_shell\n" + ascii_stl(q).substr(11)},
      {"blank line in a loop",
       "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n\nvertex 1 0 0\nvertex 1 1 0\n"
       "endloop\nendfacet\nfacet\nouter loop\nvertex 0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\n"
       "endfacet\nendsolid a\n"},
      {"one line per facet",
       "solid a\nfacet normal 0 0 1\nouter loop vertex 0 0 0 vertex 1 0 0 vertex 1 1 0 endloop "
       "endfacet\nfacet\nvertex 0 0 0 vertex 1 1 0 vertex 0 1 0 endfacet endsolid"},
      {"two solids",
       "solid a\nfacet\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendfacet\nendsolid a\nsolid b\nfacet\n"
       "vertex 0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendfacet\nendsolid b\n"},
      {"comments",
       "solid a\n# made by hand\nfacet\nvertex 0 0 0 # first\nvertex 1 0 0\nvertex 1 1 0\nendfacet\n"
       "facet\nvertex 0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendfacet\n"},
      {"byte-order mark", "\xEF\xBB\xBF" + ascii_stl(q)},
  };
  for (const auto& [what, text] : layouts) {
    SCOPED_TRACE(what);
    MeshLoadInfo info;
    try {
      expect_quad(load_text("quad.stl", text, &info), what);
      EXPECT_EQ(info.format, "stl");
      EXPECT_EQ(info.file_faces, 2u);
      EXPECT_EQ(info.degenerate_faces_dropped, 0u);
    } catch (const InputError& e) {
      ADD_FAILURE() << e.what();
    }
  }
  expect_quad(load_text("quad.stl", binary_stl(q)), "binary");
}

// Corners weld by value (-0 and denormals are 0) in order of first appearance; a facet whose
// corners weld together is dropped and counted, and the triangles keep their facet's number.
TEST(StlReader, CornersWeldAndDegenerateFacetsAreCounted) {
  const glm::vec3 a(0, 0, 0), b(1, 0, 0), c(1, 1, 0), d(0, 1, 0);
  const glm::vec3 minus_zero(-0.0f, 0, 0), denormal(1e-40f, 0, -0.0f);
  const std::vector<std::array<glm::vec3, 3>> facets = {
      {a, b, c},
      {minus_zero, denormal, d},  // a three times: dropped, but d is met here first
      {denormal, c, d},
      {b, b, b},  // dropped
  };
  for (const bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    MeshLoadInfo info;
    const Mesh m = load_text("weld.stl", binary ? binary_stl(facets) : ascii_stl(facets), &info);
    ASSERT_EQ(m.positions.size(), 4u);
    EXPECT_EQ(std::signbit(m.positions[0].x), false);  // the first corner's coordinates
    EXPECT_EQ(m.positions[3], d);
    EXPECT_EQ(m.position_index, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
    EXPECT_EQ(m.source_face, (std::vector<std::uint32_t>{0, 2}));
    EXPECT_EQ(info.file_faces, 4u);
    EXPECT_EQ(info.degenerate_faces_dropped, 2u);
  }
}

// The sample's high-poly as ASCII and binary STL: the same triangles, corner for corner, welded
// back into as many vertices as it has distinct positions.
TEST(StlReader, SampleHighPolyRoundTripsInBothEncodings) {
  const Mesh high = load_mesh(test::data_path("sample/torus_high.ply"));
  std::vector<std::array<glm::vec3, 3>> facets(high.triangle_count());
  std::map<std::tuple<float, float, float>, int> distinct;
  for (std::size_t t = 0; t < facets.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      facets[t][c] = high.corner_position(t, c);
      distinct[{facets[t][c].x, facets[t][c].y, facets[t][c].z}] = 0;
    }
  const Mesh ascii = load_text("high_ascii.stl", ascii_stl(facets));
  const Mesh binary = load_text("high_binary.stl", binary_stl(facets));
  for (const Mesh* m : {&ascii, &binary}) {
    ASSERT_EQ(m->triangle_count(), high.triangle_count());
    EXPECT_EQ(m->positions.size(), distinct.size());
    for (std::size_t t = 0; t < facets.size(); ++t)
      for (int c = 0; c < 3; ++c) ASSERT_EQ(m->corner_position(t, c), facets[t][c]) << "triangle " << t;
  }
  EXPECT_EQ(ascii.positions, binary.positions);
  EXPECT_EQ(ascii.position_index, binary.position_index);
}

TEST(StlReader, ErrorsNameTheLineAndFacet) {
  const std::string dir = test::scratch_dir();
  const std::string head =
      "solid a\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\n";
  const std::pair<std::string, std::vector<const char*>> cases[] = {
      {head + "facet\nvertex 0 0 0\nvertex 1 0 0\nendfacet\n", {"line 12: facet 1 has 2 vertices; STL facets are triangles"}},
      {head + "facet\nvertex 0 0 0\ncolor 1 0 0\n", {"line 11: unexpected 'color' in facet 1"}},
      {head + "endsolid a\ngarbage\n", {"line 10: unexpected 'garbage' before facet 1"}},
      {head + "facet\nvertex 0 0 0\nvertex 1 0 1e39\n", {"line 11: facet 1 has a non-finite coordinate"}},
      {head + "facet\nvertex 0 0 0\nvertex 1 0\nvertex 1 1 0\n", {"line 12: facet 1 has a malformed vertex coordinate 'vertex'"}},
      {head + "facet\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nfacet\n", {"line 13: facet 1 has no 'endfacet' before 'facet'"}},
      {head + "facet\nvertex 0 0 0\nvertex 1 0", {"truncated: file ends in facet 1"}},
      {head + "vertex 0 0 0\n", {"line 9: facet 1 has a vertex outside 'facet ... endfacet'"}},
  };
  for (const auto& [text, words] : cases) {
    write_file(dir + "/bad.stl", text);
    SCOPED_TRACE(text);
    const std::string message = load_error(dir + "/bad.stl");
    EXPECT_EQ(message.rfind(dir + "/bad.stl: ", 0), 0u) << message;
    for (const char* word : words) EXPECT_NE(message.find(word), std::string::npos) << message;
  }

  // Binary: the facet with a NaN, a count that disagrees with the size (a binary STL cut short
  // whose header begins with "solid" is told as both).
  std::string binary = binary_stl(quad_facets());
  const float nan = std::nanf("");
  std::memcpy(&binary[84 + 50 + 12 + 4], &nan, 4);
  write_file(dir + "/nan.stl", binary);
  expect_error(dir + "/nan.stl", {"facet 1 has a non-finite coordinate"});
  write_file(dir + "/cut.stl", binary_stl(quad_facets()).substr(0, 84 + 50 + 20));
  expect_error(dir + "/cut.stl", {"truncated: binary STL header says 2 facets (184 bytes) but the file has 154 bytes"});
  write_file(dir + "/empty_binary.stl", binary_stl({}));
  expect_error(dir + "/empty_binary.stl", {"no faces"});
}

// OFF ---------------------------------------------------------------------------------------------

TEST(OffReader, HeaderVariants) {
  const std::string faces = "3 0 1 2\n3 0 2 3 255 0 0\n";
  struct Case {
    std::string text;
    bool normals, uvs;
  };
  const Case cases[] = {
      {"OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n" + faces, false, false},
      {"OFF 4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n" + faces, false, false},
      {"# comment\nOFF # magic\n\n4 2\n0 0 0\n1 0 0 # x\n1 1 0\n0 1 0\n" + faces, false, false},
      {"NOFF\r\n4 2 0\r\n0 0 0 0 0 1\r\n1 0 0 0 0 1\r\n1 1 0 0 0 1\r\n0 1 0 0 0 1\r\n3 0 1 2\r\n3 0 2 3\r\n", true, false},
      {"COFF\n4 2 0\n0 0 0 1 0 0\n1 0 0 1 0 0 1\n1 1 0 0.5\n0 1 0 255 255 255 255\n" + faces, false, false},
      {"CNOFF\n4 2 0\n0 0 0 0 0 1 1 0 0\n1 0 0 0 0 1 1 0 0\n1 1 0 0 0 1 1 0 0\n0 1 0 0 0 1 1 0 0\n" + faces, true, false},
      {"STOFF\n4 2 0\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n" + faces, false, true},
      {"STNOFF\n4 2 0\n0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n" + faces, true, true},
      {"STCOFF\n4 2 0\n0 0 0 9 9 9 0 0\n1 0 0 9 9 9 9 1 0\n1 1 0 9 1 1\n0 1 0 9 9 0 1\n" + faces, false, true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    const Mesh m = load_text("quad.off", c.text);
    ASSERT_EQ(m.positions.size(), 4u);
    EXPECT_EQ(m.position_index, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
    EXPECT_EQ(m.source_face, (std::vector<std::uint32_t>{0, 1}));
    EXPECT_EQ(m.positions[2], glm::vec3(1, 1, 0));
    ASSERT_EQ(m.has_normals(), c.normals);
    ASSERT_EQ(m.has_uvs(), c.uvs);
    for (std::size_t i = 0; i < m.position_index.size(); ++i) {
      const glm::vec3 p = m.positions[m.position_index[i]];
      if (c.uvs) {
        EXPECT_EQ(m.uvs[m.uv_index[i]], glm::vec2(p.x, p.y)) << "corner " << i;
      }
      if (c.normals) {
        EXPECT_EQ(m.normals[m.normal_index[i]], glm::vec3(0, 0, 1)) << "corner " << i;
      }
    }
  }
  const std::string dir = test::scratch_dir();
  for (const char* magic : {"4OFF", "nOFF"}) {
    write_file(dir + "/nd.off", std::string(magic) + "\n3 1 0\n0 0 0 0\n1 0 0 0\n0 1 0 0\n3 0 1 2\n");
    expect_error(dir + "/nd.off", {"is not supported"});
  }
  write_file(dir + "/big.off", "OFF\n4294967296 1 0\n");
  expect_error(dir + "/big.off", {"too many vertices or faces"});
}

// A number whose double lies exactly halfway between two floats: rounding that double to float
// would break the tie to even (1), the number itself is above it (the next float).
TEST(OffReader, CoordinatesAreTheNearestFloatAndExactInDouble) {
  const std::string x = "1.00000005960464477539062501";
  const Mesh m = load_text("tie.off", "OFF\n3 1 0\n" + x + " 0 0\n0 1 0\n0 0 1\n3 0 1 2\n");
  EXPECT_EQ(m.positions[0].x, std::nextafter(1.0f, 2.0f));

  // Far from the origin the mesh is re-centred in double: its 0.001 steps survive.
  const Mesh far = load_text("far.off", "OFF\n3 1 0\n1000000.001 0 0\n1000000.002 1 0\n1000000.003 0 1\n3 0 1 2\n");
  EXPECT_NE(far.origin, glm::dvec3(0.0));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(double(far.positions[i].x) + far.origin.x, 1000000.001 + 0.001 * i, 1e-9) << i;
}

// An STOFF (with normals) low-poly is the same mesh as the OBJ with the same vertices, and bakes
// the same map.
TEST(OffReader, TexturedLowPolyBakesAsTheSameMeshInObj) {
  LoadOptions uvs;
  uvs.require_uvs = true;
  const Mesh low = load_mesh(test::data_path("sample/torus_low.obj"), uvs);
  ASSERT_TRUE(low.has_normals());
  // One OFF vertex per distinct (position, uv, normal) corner.
  std::map<std::tuple<std::uint32_t, std::uint32_t, std::uint32_t>, std::uint32_t> vertex_of;
  std::vector<std::uint32_t> corners;
  std::string off_vertices, obj = "o low\n", obj_faces;
  for (std::size_t i = 0; i < low.position_index.size(); ++i) {
    const auto key = std::make_tuple(low.position_index[i], low.uv_index[i], low.normal_index[i]);
    auto [it, added] = vertex_of.try_emplace(key, std::uint32_t(vertex_of.size()));
    corners.push_back(it->second);
    if (!added) continue;
    const glm::vec3 p = low.positions[low.position_index[i]], n = low.normals[low.normal_index[i]];
    const glm::vec2 t = low.uvs[low.uv_index[i]];
    const std::string values[8] = {number(p.x), number(p.y), number(p.z), number(n.x),
                                   number(n.y), number(n.z), number(t.x), number(t.y)};
    for (const std::string& v : values) off_vertices += v + " ";
    off_vertices += "\n";
    obj += "v " + values[0] + " " + values[1] + " " + values[2] + "\nvt " + values[6] + " " + values[7] + "\nvn " + values[3] +
           " " + values[4] + " " + values[5] + "\n";
  }
  std::string off =
      "STNOFF\n" + std::to_string(vertex_of.size()) + " " + std::to_string(low.triangle_count()) + " 0\n" + off_vertices;
  for (std::size_t t = 0; t < low.triangle_count(); ++t) {
    off += "3 " + std::to_string(corners[3 * t]) + " " + std::to_string(corners[3 * t + 1]) + " " +
           std::to_string(corners[3 * t + 2]) + "\n";
    obj += "f";
    for (int c = 0; c < 3; ++c) {
      const std::string i = std::to_string(corners[3 * t + c] + 1);
      obj += " " + i + "/" + i + "/" + i;
    }
    obj += "\n";
  }
  const std::string dir = test::scratch_dir();
  write_file(dir + "/low.off", off);
  write_file(dir + "/low.obj", obj);
  const Mesh from_off = load_mesh(dir + "/low.off", uvs);
  const Mesh from_obj = load_mesh(dir + "/low.obj", uvs);
  EXPECT_EQ(from_off.positions, from_obj.positions);
  EXPECT_EQ(from_off.uvs, from_obj.uvs);
  EXPECT_EQ(from_off.normals, from_obj.normals);
  EXPECT_EQ(from_off.position_index, from_obj.position_index);
  EXPECT_EQ(from_off.uv_index, from_obj.uv_index);
  EXPECT_EQ(from_off.normal_index, from_obj.normal_index);

  const Mesh high = load_mesh(test::data_path("sample/torus_high.ply"));
  BakeOptions o;
  o.width = o.height = 64;
  const BakeResult off_bake = bake_normal_map(from_off, high, nullptr, o);
  const BakeResult obj_bake = bake_normal_map(from_obj, high, nullptr, o);
  std::size_t covered = 0;
  for (std::uint8_t c : off_bake.coverage) covered += c;
  EXPECT_GT(covered, off_bake.coverage.size() / 4);  // the torus's UV layout fills much of the map
  EXPECT_TRUE(off_bake.map.pixels == obj_bake.map.pixels);
}

}  // namespace
}  // namespace nmbake
