// STL reader, binary and ASCII, in one pass over the bytes in memory, no iostreams.
//
// A file whose size is 84 + 50 bytes per facet of its header's count is binary (is_binary_stl);
// any other must be ASCII and start with "solid". ASCII is read by keyword, in any case, whatever
// the line breaks: "solid", "endsolid" and "facet" take the rest of their line (a name, the facet
// normal), "outer" takes "loop", "vertex" three numbers, "endloop" and "endfacet" nothing. "outer
// loop" and "endloop" may be missing, several solids may follow one another, '#' starts a comment;
// any other token is an error. Facet normals are ignored (normals are computed from the triangles
// later).
//
// STL stores each facet's three corners by value: corners with equal coordinates become one vertex
// (-0 equals 0, and so does any value within FLT_MIN of 0, as OpenMesh's reader welded them),
// numbered in order of first appearance, with the first corner's coordinates. A facet two of whose
// corners are one vertex is dropped and counted (degenerate_faces_dropped); the vertices it met
// first stay, unused. Triangles keep their facet's number in the file (source_face).
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "io/mesh_io_detail.h"

namespace nmbake::mesh_io_detail {
namespace {

constexpr std::size_t kBinaryHeader = 84;  // 80 bytes of text, the facet count (uint32)
constexpr std::size_t kBinaryFacet = 50;   // normal, 3 corners (12 floats), 2 attribute bytes

std::uint32_t binary_stl_count(std::string_view bytes) {
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);  // little-endian, as is every platform we build for
  return count;
}

// "truncated: binary STL header says N facets (B bytes) but the file has S bytes"
std::string binary_size_problem(std::string_view bytes) {
  const std::uint64_t count = binary_stl_count(bytes);
  return "truncated: binary STL header says " + std::to_string(count) + " facets (" +
         std::to_string(kBinaryHeader + kBinaryFacet * count) + " bytes) but the file has " + std::to_string(bytes.size()) +
         " bytes";
}

// Corners -> vertices by exact coordinates: an open-addressing table of vertex numbers into the
// mesh's positions, grown to keep it at most half full.
class Welder {
 public:
  Welder(const std::string& path, std::vector<glm::vec3>& positions) : path_(path), positions_(positions) {
    slots_.assign(1024, kEmpty);
  }

  std::uint32_t vertex(const glm::vec3& p) {
    const glm::vec3 key = weld_key(p);
    std::size_t slot = hash(key) & (slots_.size() - 1);
    for (;; slot = (slot + 1) & (slots_.size() - 1)) {
      const std::uint32_t v = slots_[slot];
      if (v == kEmpty) break;
      if (weld_key(positions_[v]) == key) return v;  // NaN never gets here
    }
    if (positions_.size() >= kEmpty) fail(path_, "more than 2^32-2 distinct vertices");
    const auto v = static_cast<std::uint32_t>(positions_.size());
    positions_.push_back(p);
    slots_[slot] = v;
    if (2 * positions_.size() > slots_.size()) grow();
    return v;
  }

 private:
  static constexpr std::uint32_t kEmpty = UINT32_MAX;

  // The coordinates a vertex is welded by: those within FLT_MIN of 0 (denormals) become +0.
  static glm::vec3 weld_key(glm::vec3 p) {
    for (int k = 0; k < 3; ++k)
      if (std::fabs(p[k]) <= FLT_MIN) p[k] = 0.0f;
    return p;
  }
  static std::uint32_t bits(float x) {
    std::uint32_t b = 0;
    std::memcpy(&b, &x, 4);
    return b;
  }
  static std::size_t hash(const glm::vec3& p) {
    std::uint64_t h = (std::uint64_t(bits(p.x)) << 32 | bits(p.y)) ^ (std::uint64_t(bits(p.z)) * 0x9E3779B97F4A7C15ull);
    h ^= h >> 33;  // the finalizer of MurmurHash3: every input bit reaches the low bits
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 33;
    h *= 0xC4CEB9FE1A85EC53ull;
    h ^= h >> 33;
    return static_cast<std::size_t>(h);
  }
  void grow() {
    slots_.assign(2 * slots_.size(), kEmpty);
    const std::size_t mask = slots_.size() - 1;
    for (std::uint32_t v = 0; v < positions_.size(); ++v) {
      std::size_t slot = hash(weld_key(positions_[v])) & mask;
      while (slots_[slot] != kEmpty) slot = (slot + 1) & mask;
      slots_[slot] = v;
    }
  }

  const std::string& path_;
  std::vector<glm::vec3>& positions_;
  std::vector<std::uint32_t> slots_;
};

// Adds facet `facet` with the given corners, or counts it dropped when two weld together.
void add_facet(ParsedMesh& out, Welder& welder, const glm::vec3 (&corners)[3], std::uint32_t facet) {
  const Corner c[3] = {{welder.vertex(corners[0]), 0, 0}, {welder.vertex(corners[1]), 0, 0}, {welder.vertex(corners[2]), 0, 0}};
  ++out.file_faces;
  if (c[0][0] == c[1][0] || c[0][0] == c[2][0] || c[1][0] == c[2][0]) {
    ++out.degenerate_faces_dropped;
    return;
  }
  add_polygon(out, c, 3, facet);
}

void parse_binary(const std::string& path, std::string_view bytes, ParsedMesh& out, Welder& welder) {
  const std::uint32_t count = binary_stl_count(bytes);
  out.mesh.position_index.reserve(3 * std::size_t(count));  // the file's size vouches for the count
  out.mesh.source_face.reserve(count);
  out.mesh.positions.reserve(count / 2 + 3);  // a closed mesh has about half as many vertices as facets
  const char* facet_bytes = bytes.data() + kBinaryHeader;
  for (std::uint32_t f = 0; f < count; ++f, facet_bytes += kBinaryFacet) {
    float values[9];
    std::memcpy(values, facet_bytes + 12, sizeof values);  // after the facet normal
    for (float v : values)
      if (!std::isfinite(v)) fail(path, "facet " + std::to_string(f) + " has a non-finite coordinate");
    const glm::vec3 corners[3] = {
        {values[0], values[1], values[2]}, {values[3], values[4], values[5]}, {values[6], values[7], values[8]}};
    add_facet(out, welder, corners, f);
  }
}

bool is_keyword(std::string_view token, const char* keyword) {
  const std::size_t n = std::strlen(keyword);
  if (token.size() != n) return false;
  for (std::size_t i = 0; i < n; ++i)
    if ((token[i] | 0x20) != keyword[i]) return false;  // ASCII lower case; keywords are letters
  return true;
}

// The ASCII reader: one token at a time, line numbers counted only for a message.
class AsciiStl {
 public:
  AsciiStl(const std::string& path, std::string_view text, ParsedMesh& out, Welder& welder)
      : path_(path), text_(text), out_(out), welder_(welder) {}

  void parse();

 private:
  std::string_view next() {
    for (;;) {
      std::string_view token = next_token(text_, pos_);
      if (token.empty() || token[0] != '#') return token;
      skip_line();  // a '#' comment
    }
  }
  void skip_line() {
    const std::size_t end = text_.find('\n', pos_);
    pos_ = end == std::string_view::npos ? text_.size() : end + 1;
  }
  std::size_t line_at(std::size_t pos) const {
    return 1 + static_cast<std::size_t>(std::count(text_.begin(), text_.begin() + std::ptrdiff_t(pos), '\n'));
  }
  // "line L: facet F <problem>", L being the line of `token`.
  [[noreturn]] void fail_facet(std::string_view token, const std::string& problem) const {
    fail(path_, "line " + std::to_string(line_at(std::size_t(token.data() - text_.data()))) + ": facet " +
                    std::to_string(facet_) + " " + problem);
  }
  [[noreturn]] void fail_unexpected(std::string_view token) const;
  void read_vertex(std::string_view keyword);

  const std::string& path_;
  std::string_view text_;
  ParsedMesh& out_;
  Welder& welder_;
  std::size_t pos_ = 0;
  std::uint32_t facet_ = 0;  // the facet being read, or the next one
  bool in_facet_ = false;
  std::size_t vertices_ = 0;  // of the facet being read
  glm::vec3 corners_[3];
};

void AsciiStl::fail_unexpected(std::string_view token) const {
  const std::string at =
      "line " + std::to_string(line_at(std::size_t(token.data() - text_.data()))) + ": unexpected " + quote(token);
  std::string problem = in_facet_ ? at + " in facet " + std::to_string(facet_) + " (expected 'vertex', 'endloop' or 'endfacet')"
                                  : at + " before facet " + std::to_string(facet_) + " (expected 'facet' or 'endsolid')";
  // A binary STL cut short (or padded) may begin with "solid": say what its header claims too.
  if (text_.size() >= kBinaryHeader && std::memchr(text_.data(), '\0', text_.size()) != nullptr)
    problem += "; not ASCII STL, and as binary STL: " + binary_size_problem(text_);
  fail(path_, problem);
}

void AsciiStl::read_vertex(std::string_view keyword) {
  if (!in_facet_) fail_facet(keyword, "has a vertex outside 'facet ... endfacet'");
  float p[3];
  for (float& value : p) {
    std::string_view token = next();
    if (token.empty()) fail(path_, "truncated: file ends in facet " + std::to_string(facet_));
    if (!parse_real(token, value)) fail_facet(token, "has a malformed vertex coordinate " + quote(token));
    if (!std::isfinite(value)) fail_facet(token, "has a non-finite coordinate");
  }
  if (vertices_ < 3) corners_[vertices_] = glm::vec3(p[0], p[1], p[2]);
  ++vertices_;
}

void AsciiStl::parse() {
  for (std::string_view token = next(); !token.empty(); token = next()) {
    if (is_keyword(token, "vertex")) {
      read_vertex(token);
    } else if (is_keyword(token, "endloop") && in_facet_) {
      continue;
    } else if (is_keyword(token, "endfacet") && in_facet_) {
      if (vertices_ != 3) fail_facet(token, "has " + std::to_string(vertices_) + " vertices; STL facets are triangles");
      add_facet(out_, welder_, corners_, facet_);
      if (facet_ == UINT32_MAX) fail(path_, "more than 2^32-1 facets");
      ++facet_;
      in_facet_ = false;
    } else if (is_keyword(token, "outer") && in_facet_) {
      const std::size_t after_outer = pos_;
      if (!is_keyword(next(), "loop")) pos_ = after_outer;
    } else if (is_keyword(token, "facet") && !in_facet_) {
      in_facet_ = true;
      vertices_ = 0;
      skip_line();  // "normal nx ny nz", ignored: some exporters write nan for a degenerate facet
    } else if ((is_keyword(token, "solid") || is_keyword(token, "endsolid")) && !in_facet_) {
      skip_line();  // the solid's name
    } else if (in_facet_ && (is_keyword(token, "facet") || is_keyword(token, "solid") || is_keyword(token, "endsolid"))) {
      fail_facet(token, "has no 'endfacet' before " + quote(token));
    } else {
      fail_unexpected(token);
    }
  }
  if (in_facet_) fail(path_, "truncated: file ends in facet " + std::to_string(facet_));
}

}  // namespace

bool is_binary_stl(std::string_view bytes) {
  return bytes.size() >= kBinaryHeader && bytes.size() == kBinaryHeader + kBinaryFacet * std::uint64_t(binary_stl_count(bytes));
}

ParsedMesh parse_stl(const std::string& path, std::string_view bytes) {
  ParsedMesh out;
  out.format = "stl";
  out.corner_uvs = out.corner_normals = false;  // STL has neither
  out.first_face_without_uvs = "face 0";
  Welder welder(path, out.mesh.positions);
  if (is_binary_stl(bytes)) {
    parse_binary(path, bytes, out, welder);
    return out;
  }
  std::string_view text = bytes;
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // a UTF-8 byte-order mark
  std::size_t p = 0;
  if (!is_keyword(next_token(text, p), "solid")) {
    if (bytes.size() < kBinaryHeader) fail(path, "truncated: too short for a binary STL header and not ASCII STL");
    fail(path, binary_size_problem(bytes));
  }
  AsciiStl(path, text, out, welder).parse();
  // Binary bytes after a header that begins with "solid" read as one long line: say what the
  // header claims.
  if (out.file_faces == 0 && bytes.size() >= kBinaryHeader && std::memchr(bytes.data(), '\0', bytes.size()))
    fail(path, binary_size_problem(bytes));
  return out;
}

}  // namespace nmbake::mesh_io_detail
