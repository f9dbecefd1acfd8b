// Numbers in text meshes (OBJ, PLY ascii, OFF, STL ascii) read exactly as strtod / strtof read them
// (issue 34, item 11: "7.000...0001e-1" with a 70-digit mantissa must be 0.7, not 7 or anything
// near): long mantissas, runs of zeros, exponents up to the ends of the range, denormals, halfway
// cases; what is not wholly a number (hex, a 'd' exponent) is refused naming the line.
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "io/mesh_io_detail.h"

namespace nmbake {
namespace {

using mesh_io_detail::ParsedMesh;

// A random decimal of one of many shapes whose value strtod reads as a finite double.
std::string random_decimal(std::mt19937_64& rng) {
  auto pick = [&](std::uint64_t n) { return std::size_t(rng() % n); };
  auto digits = [&](std::size_t n) {
    std::string s;
    for (std::size_t i = 0; i < n; ++i) s += char('0' + pick(10));
    return s;
  };
  std::string s = pick(2) ? "-" : (pick(8) == 0 ? "+" : "");
  if (pick(4) == 0) s += std::string(pick(30), '0');  // leading zeros
  const std::size_t whole = pick(5) == 0 ? pick(60) : pick(6);
  s += whole ? digits(whole) : "0";
  if (pick(4)) {
    s += '.';
    if (pick(3) == 0) s += std::string(pick(80), '0');
    s += digits(pick(5) == 0 ? pick(120) : pick(18));
    if (pick(3) == 0) s += std::string(pick(90), '0') + (pick(2) ? "1" : "");  // the issue's shape
  }
  if (pick(3)) {
    const int range = pick(4) == 0 ? 330 : 40, exponent = int(pick(2 * range)) - range;
    s += (pick(2) ? "e" : "E") + std::string(exponent >= 0 && pick(6) == 0 ? "+" : "") + std::to_string(exponent);
  }
  return s;
}

std::vector<std::string> random_decimals(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<std::string> out;
  while (out.size() < n) {
    std::string s = random_decimal(rng);
    char* end = nullptr;
    const bool finite = std::isfinite(std::strtod(s.c_str(), &end)) && std::isfinite(std::strtof(s.c_str(), nullptr));
    if (finite && end == s.c_str() + s.size()) out.push_back(s);
  }
  // Halfway between two floats and two doubles, and a hair above and below: the last digits decide.
  out.push_back("0.70000001788139343261718750");                                    // a float tie
  out.push_back("0.70000001788139343261718750000000000000000000001");               // just above it
  out.push_back("0.70000001788139343261718749999999999999999999999");               // just below it
  out.push_back("1.00000000000000011102230246251565404236316680908203125");         // a double tie
  out.push_back("1.000000000000000111022302462515654042363166809082031250000001");  // above
  out.push_back("7." + std::string(68, '0') + "1e-1");
  out.push_back("4.9406564584124654e-324");  // the smallest denormal double
  out.push_back("2.4703282292062328e-324");  // half of it: rounds to even (0)
  out.push_back("1.40129846e-45");           // the smallest denormal float
  out.push_back("1.7976931348623157e308");
  return out;
}

// Three numbers a line: `prefix` (v, vn ...) before each, every third one gets the next line.
std::string lines(const std::vector<std::string>& numbers, const std::string& prefix) {
  std::string text;
  for (std::size_t i = 0; i + 2 < numbers.size(); i += 3)
    text += prefix + numbers[i] + " " + numbers[i + 1] + " " + numbers[i + 2] + "\n";
  return text;
}

void expect_exact(const std::vector<glm::dvec3>& read, const std::vector<std::string>& numbers, const char* format) {
  ASSERT_EQ(read.size(), numbers.size() / 3) << format;
  for (std::size_t i = 0; i < read.size() * 3; ++i) {
    const double want = std::strtod(numbers[i].c_str(), nullptr), got = read[i / 3][int(i % 3)];
    ASSERT_EQ(std::memcmp(&want, &got, sizeof want), 0) << format << ": " << numbers[i] << " read as " << got;
  }
}

void expect_exact(const std::vector<glm::vec3>& read, const std::vector<std::string>& numbers, const char* format) {
  ASSERT_EQ(read.size(), numbers.size() / 3) << format;
  for (std::size_t i = 0; i < read.size() * 3; ++i) {
    const float want = std::strtof(numbers[i].c_str(), nullptr), got = read[i / 3][int(i % 3)];
    ASSERT_EQ(std::memcmp(&want, &got, sizeof want), 0) << format << ": " << numbers[i] << " read as " << got;
  }
}

TEST(MeshNumbers, ObjReadsEveryDecimalAsStrtod) {
  const std::vector<std::string> numbers = random_decimals(30000, 34);
  const ParsedMesh m = mesh_io_detail::parse_obj("n.obj", lines(numbers, "v ") + lines(numbers, "vn ") + "f 1 2 3\n");
  expect_exact(m.exact_positions, numbers, "OBJ v");
  expect_exact(m.mesh.normals, numbers, "OBJ vn");  // float: as strtof, not strtod rounded again
}

TEST(MeshNumbers, PlyOffAndStlReadEveryDecimalAsStrtod) {
  const std::vector<std::string> numbers = random_decimals(3000, 35);
  const std::size_t n = numbers.size() / 3;
  const std::string ply = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(n) +
                          "\nproperty double x\nproperty double y\nproperty double z\nelement face 1\n"
                          "property list uchar int vertex_indices\nend_header\n" +
                          lines(numbers, "") + "3 0 1 2\n";
  expect_exact(mesh_io_detail::parse_ply("n.ply", ply).exact_positions, numbers, "PLY");
  const std::string off = "OFF\n" + std::to_string(n) + " 1 0\n" + lines(numbers, "") + "3 0 1 2\n";
  expect_exact(mesh_io_detail::parse_off("n.off", off).exact_positions, numbers, "OFF");
  // STL keeps positions in float only. Each number is one corner's x; y and z make every facet a
  // right triangle (never dropped as degenerate), kept within float's range.
  std::vector<std::string> xs;
  for (const std::string& x : numbers)
    if (std::fabs(std::strtod(x.c_str(), nullptr)) < 1e30) xs.push_back(x);
  xs.resize(xs.size() / 3 * 3);
  std::string stl = "solid n\n";
  for (std::size_t i = 0; i < xs.size(); i += 3)
    stl += "facet normal 0 0 1\nouter loop\nvertex " + xs[i] + " 0 0\nvertex " + xs[i + 1] + " 1 0\nvertex " + xs[i + 2] +
           " 0 1\nendloop\nendfacet\n";
  const ParsedMesh s = mesh_io_detail::parse_stl("n.stl", stl + "endsolid n\n");
  ASSERT_EQ(s.mesh.position_index.size(), xs.size());
  for (std::size_t c = 0; c < xs.size(); ++c) {
    float want = std::strtof(xs[c].c_str(), nullptr);
    if (std::fabs(want) <= FLT_MIN) want = 0.0f;  // the STL reader welds denormals to 0, -0 to +0
    const float got = s.mesh.positions[s.mesh.position_index[c]].x;
    ASSERT_EQ(want, got) << "STL: " << xs[c] << " read as " << got;
  }
}

// The case of the issue, and numbers that are not wholly decimal: refused with the line.
TEST(MeshNumbers, IssueCaseAndRefusals) {
  const std::string seventy = "7." + std::string(68, '0') + "1e-1";
  const ParsedMesh m = mesh_io_detail::parse_obj("n.obj", "v " + seventy + " -" + seventy + " 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_EQ(m.exact_positions[0].x, 0.7);
  EXPECT_EQ(m.exact_positions[0].y, -0.7);
  for (const char* bad : {"0x1p-1", "7.0d-1", "7.0e", "1e-+5", "0.7.1", "7e-1f"}) {
    try {
      mesh_io_detail::parse_obj("n.obj", "v 0 0 0\nv " + std::string(bad) + " 0 0\n");
      ADD_FAILURE() << bad << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("n.obj: line 2: vertex 2 has a malformed number"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace nmbake
