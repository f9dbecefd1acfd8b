// OFF reader (ASCII), in one pass over the text in memory, no iostreams.
//
// The magic says what each vertex line carries: [ST][C][N]OFF is x y z, a normal (N), a colour of
// 1 to 4 values (C) and a texture coordinate (ST), which after a colour is taken as the last two
// values, whatever the colour's length. The vertex and face counts follow the magic on its line or
// on the next (the edge count is ignored); '#' starts a comment anywhere. A face line is its corner
// count and the corners' vertex numbers (from 0); whatever follows them (a face colour) is ignored.
// Polygons are fanned (add_polygon). Every corner's normal and texture coordinate are its vertex's.
// 4OFF, nOFF and binary OFF are refused.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "io/mesh_io_detail.h"

namespace nmbake::mesh_io_detail {
namespace {

// The shortest vertex line ("0 0 0\n") and face line ("3 0 0 0\n"): no more elements than the
// bytes could hold are reserved, whatever the counts say.
constexpr std::size_t kMinVertexBytes = 6;
constexpr std::size_t kMinFaceBytes = 8;

// Splits the text into lines without comments, remembering each line's number for messages.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text) : text_(text) {}

  // The next line with content, '#' comments removed; false at the end.
  bool next(std::string_view& line) {
    while (pos_ < text_.size()) {
      std::size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_number_;
      const std::size_t hash = line.find('#');
      if (hash != std::string_view::npos) line = line.substr(0, hash);
      std::size_t p = 0;
      if (!next_token(line, p).empty()) return true;
    }
    return false;
  }
  std::size_t line_number() const { return line_number_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_number_ = 0;
};

bool is_off_magic(std::string_view token) {
  if (token.size() < 3 || token.substr(token.size() - 3) != "OFF") return false;
  for (char c : token.substr(0, token.size() - 3))
    if (std::strchr("STCN4n", c) == nullptr) return false;
  return true;
}

// The float nearest the number `token` reads `value` (the same number in double). Rounding the
// double to float gives it, except where the double fell exactly halfway between two floats:
// there the tie may break the wrong way, so the token is read again as float.
float nearest_float(std::string_view token, double value) {
  float f = static_cast<float>(value);
  if (double(f) != value) {
    const float other = std::nextafter(f, value > double(f) ? HUGE_VALF : -HUGE_VALF);
    if ((double(f) + double(other)) * 0.5 == value) parse_real(token, f);
  }
  return f;
}

class OffParser {
 public:
  OffParser(const std::string& path, std::string_view text, ParsedMesh& out) : path_(path), lines_(text), out_(out) {}

  void parse(std::size_t text_size);

 private:
  std::string at_line() const { return "line " + std::to_string(lines_.line_number()) + ": "; }
  void read_header();
  void read_vertex(std::string_view line, std::size_t v);
  void read_face(std::string_view line, std::uint32_t f);
  template <typename Real>
  void read_numbers(std::string_view line, std::size_t& pos, int count, std::size_t v, const char* what, Real* values,
                    std::string_view* tokens = nullptr);

  const std::string& path_;
  LineCursor lines_;
  ParsedMesh& out_;
  bool has_normals_ = false, has_colours_ = false, has_texcoords_ = false;
  std::size_t vertex_count_ = 0, face_count_ = 0;
  std::vector<Corner> corners_;
};

// Reads `count` finite numbers of vertex `v` from `line` at `pos` into `values` (and their tokens).
template <typename Real>
void OffParser::read_numbers(std::string_view line, std::size_t& pos, int count, std::size_t v, const char* what, Real* values,
                             std::string_view* tokens) {
  auto where = [&] { return at_line() + "vertex " + std::to_string(v); };
  for (int i = 0; i < count; ++i) {
    std::string_view token = next_token(line, pos);
    if (token.empty()) fail(path_, where() + " has fewer than " + std::to_string(count) + " " + what);
    if (!parse_real(token, values[i])) fail(path_, where() + " has a malformed number " + quote(token));
    if (!std::isfinite(values[i]) || !std::isfinite(static_cast<float>(values[i])))
      fail(path_, where() + " has a non-finite " + what);
    if (tokens) tokens[i] = token;
  }
}

void OffParser::read_header() {
  std::string_view line;
  if (!lines_.next(line)) fail(path_, "no faces");
  std::size_t p = 0;
  const std::string_view magic = next_token(line, p);
  if (!is_off_magic(magic)) fail(path_, "not an OFF file (it does not start with 'OFF')");
  if (magic.find_first_of("4n") != std::string_view::npos) fail(path_, quote(magic) + " (4D or n-D OFF) is not supported");
  const std::string_view word = next_token(line, p);
  if (word == "BINARY") fail(path_, "binary OFF is not supported; save it as ASCII OFF or as PLY");
  has_texcoords_ = magic.substr(0, 2) == "ST";
  has_colours_ = magic.find('C') != std::string_view::npos;
  has_normals_ = magic.find('N') != std::string_view::npos;

  // The counts follow on the magic's line or on the next one.
  std::string_view counts_line = line.substr(p - word.size());
  if (word.empty() && !lines_.next(counts_line)) fail(path_, "file ends before the vertex and face counts");
  std::size_t cp = 0;
  long long counts[2] = {0, 0};
  for (long long& c : counts) {
    const std::string_view token = next_token(counts_line, cp);
    if (!parse_int(token, c)) fail(path_, at_line() + "malformed vertex or face count " + quote(token));
    if (c < 0) fail(path_, at_line() + "negative count " + std::to_string(c));
  }
  if (counts[0] > UINT32_MAX || counts[1] > INT32_MAX) fail(path_, "too many vertices or faces");
  vertex_count_ = static_cast<std::size_t>(counts[0]);
  face_count_ = static_cast<std::size_t>(counts[1]);
}

void OffParser::read_vertex(std::string_view line, std::size_t v) {
  std::size_t pos = 0;
  double x[3];
  std::string_view tokens[3];
  read_numbers(line, pos, 3, v, "coordinate", x, tokens);
  out_.exact_positions.emplace_back(x[0], x[1], x[2]);
  out_.mesh.positions.emplace_back(nearest_float(tokens[0], x[0]), nearest_float(tokens[1], x[1]),
                                   nearest_float(tokens[2], x[2]));
  if (has_normals_) {
    float n[3];
    read_numbers(line, pos, 3, v, "normal", n);
    out_.mesh.normals.emplace_back(n[0], n[1], n[2]);
  }
  if (has_texcoords_) {
    // After a colour (1 to 4 values) the texture coordinate is the last two values.
    if (has_colours_) {
      std::size_t ends[3] = {pos, pos, pos};  // where the last three tokens end
      std::size_t found = 0;
      for (std::size_t r = pos; !next_token(line, r).empty(); ++found) {
        ends[0] = ends[1];
        ends[1] = ends[2];
        ends[2] = r;
      }
      if (found > 2) pos = ends[0];
    }
    float t[2];
    read_numbers(line, pos, 2, v, "texture coordinate", t);
    out_.mesh.uvs.emplace_back(t[0], t[1]);
  }
}

void OffParser::read_face(std::string_view line, std::uint32_t f) {
  auto face = [&] { return at_line() + "face " + std::to_string(f); };
  std::size_t pos = 0;
  std::string_view token = next_token(line, pos);
  long long corners = 0;
  if (!parse_int(token, corners)) fail(path_, face() + " has a malformed corner count " + quote(token));
  if (corners < 3) fail(path_, face() + " has only " + std::to_string(corners) + " corners");
  corners_.clear();  // grown one token at a time: a corner count of 4e9 allocates nothing
  for (long long c = 0; c < corners; ++c) {
    token = next_token(line, pos);
    long long index = 0;
    if (token.empty()) fail(path_, face() + " lists fewer than its " + std::to_string(corners) + " corners");
    if (!parse_int(token, index)) fail(path_, face() + " has a malformed vertex index " + quote(token));
    if (index < 0 || std::size_t(index) >= vertex_count_)
      fail(path_, face() + " refers to vertex " + std::to_string(index) + " but the file has " + std::to_string(vertex_count_));
    const auto i = static_cast<std::uint32_t>(index);
    corners_.push_back({i, i, i});
  }
  ++out_.file_faces;
  add_polygon(out_, corners_.data(), corners_.size(), f);
}

void OffParser::parse(std::size_t text_size) {
  read_header();
  out_.corner_normals = has_normals_;
  out_.corner_uvs = has_texcoords_;
  const std::size_t vertices = std::min(vertex_count_, text_size / kMinVertexBytes);
  out_.mesh.positions.reserve(vertices);
  out_.exact_positions.reserve(vertices);
  if (has_normals_) out_.mesh.normals.reserve(vertices);
  if (has_texcoords_) out_.mesh.uvs.reserve(vertices);
  out_.mesh.source_face.reserve(std::min(face_count_, text_size / kMinFaceBytes));

  std::string_view line;
  for (std::size_t v = 0; v < vertex_count_; ++v) {
    if (!lines_.next(line))
      fail(path_, "truncated: file ends in vertex " + std::to_string(v) + " of " + std::to_string(vertex_count_));
    read_vertex(line, v);
  }
  for (std::size_t f = 0; f < face_count_; ++f) {
    if (!lines_.next(line))
      fail(path_, "truncated: file ends in face " + std::to_string(f) + " of " + std::to_string(face_count_));
    read_face(line, static_cast<std::uint32_t>(f));
  }
  // Every face has the normals and texture coordinates the magic announces, or none.
  out_.faces_with_normals = has_normals_ ? out_.faces : 0;
  out_.faces_with_uvs = has_texcoords_ ? out_.faces : 0;
  if (!has_texcoords_) out_.first_face_without_uvs = "face 0";
}

}  // namespace

ParsedMesh parse_off(const std::string& path, std::string_view text) {
  ParsedMesh out;
  out.format = "off";
  OffParser(path, text, out).parse(text.size());
  return out;
}

}  // namespace nmbake::mesh_io_detail
