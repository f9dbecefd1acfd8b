// Wavefront OBJ reader: v, vt, vn and f lines, objects by o (or, in a file without o, by g) and
// materials by usemtl; every other statement (s, mtllib, l, p, free-form curves, ...) is ignored.
// One pass over the text in memory, no iostreams.
//
// Accepted: v, v/vt, v//vn, v/vt/vn corners; negative (relative) indices; tabs and repeated
// spaces; CRLF; a last line without newline; '\' line continuation; '#' comments; extra values
// after x y z: w (4 numbers), or the vertex colour extension "x y z r g b" (6 numbers, as MeshLab,
// ZBrush and Meshroom write it) and "x y z r g b a" (7), colours taken as they are (0..1). Other
// extra values are ignored. Positive indices may refer forward, as most exporters' readers allow;
// they are checked against the totals at the end.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "io/mesh_io_detail.h"

namespace nmbake::mesh_io_detail {
namespace {

enum Attribute { kPosition = 0, kUv = 1, kNormal = 2 };

const char* const kAttributeNames[3] = {"vertex", "texture coordinate", "normal"};

std::size_t attribute_count(const Mesh& m, Attribute attribute) {
  switch (attribute) {
    case kPosition: return m.positions.size();
    case kUv: return m.uvs.size();
    case kNormal: return m.normals.size();
  }
  return 0;
}

// The rest of the line from `pos`, trimmed and cut to 256 bytes: an o, g or usemtl name.
std::string statement_name(std::string_view line, std::size_t pos) {
  std::string_view name = line.substr(std::min(pos, line.size()));
  while (!name.empty() && is_space(name.front())) name.remove_prefix(1);
  while (!name.empty() && is_space(name.back())) name.remove_suffix(1);
  return std::string(name.substr(0, 256));
}

class ObjParser {
 public:
  ObjParser(const std::string& path, ParsedMesh& out) : path_(path), out_(out) {}

  void parse_line(std::string_view line, std::size_t line_number);
  void check_forward_references() const;
  // Colours for every vertex, or none; a vertex without one among some with counts in
  // ParsedMesh::vertices_without_colors (load_mesh drops them all then).
  void finish_colors();

 private:
  [[noreturn]] void fail_line(const std::string& problem) const { fail(path_, "line " + std::to_string(line_) + ": " + problem); }
  template <typename Real>
  Real read_value(std::string_view line, std::size_t& pos, Attribute element, bool required, bool& present) const;
  void parse_vertex(std::string_view line, std::size_t pos);
  void parse_uv(std::string_view line, std::size_t pos);
  void parse_normal(std::string_view line, std::size_t pos);
  void parse_face(std::string_view line, std::size_t pos);
  std::uint32_t resolve_index(std::string_view text, Attribute attribute);

  const std::string& path_;
  ParsedMesh& out_;
  std::size_t line_ = 0;
  std::uint32_t face_number_ = 0;  // 0-based count of f statements so far
  std::vector<Corner> corners_;
  bool named_by_o_ = false;  // an `o` was met: `g` no longer names objects
  std::size_t vertices_with_colors_ = 0;

  // The largest positive index seen per attribute and its line, checked once the totals are known.
  long long max_index_[3] = {0, 0, 0};
  std::size_t max_index_line_[3] = {0, 0, 0};
};

// One number of a v, vt or vn statement; `element` names it in messages.
template <typename Real>
Real ObjParser::read_value(std::string_view line, std::size_t& pos, Attribute element, bool required, bool& present) const {
  auto name = [&] {
    return std::string(kAttributeNames[element]) + " " + std::to_string(attribute_count(out_.mesh, element) + 1);
  };
  std::string_view token = next_token(line, pos);
  present = !token.empty() && token[0] != '#';
  if (!present) {
    if (required) fail_line(name() + " has too few values");
    return Real(0);
  }
  Real value = 0;
  if (!parse_real(token, value)) fail_line(name() + " has a malformed number " + quote(token));
  return value;
}

void ObjParser::parse_vertex(std::string_view line, std::size_t pos) {
  bool present = false;
  glm::dvec3 exact;  // in double: a mesh far from the origin is re-centred before rounding to float
  for (int i = 0; i < 3; ++i) exact[i] = read_value<double>(line, pos, kPosition, true, present);
  const glm::vec3 p(exact);
  auto& positions = out_.mesh.positions;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
    fail_line("vertex " + std::to_string(positions.size() + 1) + " has a non-finite coordinate");
  if (positions.size() >= UINT32_MAX) fail_line("more than 2^32-1 vertices");
  positions.push_back(p);
  out_.exact_positions.push_back(exact);

  // What follows x y z: w, r g b or r g b a; anything else is no colour (and ignored, as before).
  double extra[4];
  int extras = 0;
  for (std::string_view token = next_token(line, pos); !token.empty() && token[0] != '#'; token = next_token(line, pos))
    if (extras == 4 || !parse_real(token, extra[extras++])) return;
  if (extras != 3 && extras != 4) return;
  glm::vec4 color(1.0f);
  for (int i = 0; i < extras; ++i) {
    if (!std::isfinite(extra[i])) fail_line("vertex " + std::to_string(positions.size()) + " has a non-finite colour");
    color[i] = unit_color(extra[i]);
  }
  auto& colors = out_.mesh.colors;
  colors.resize(positions.size() - 1, glm::vec4(1.0f));  // vertices before without colours: placeholders
  colors.push_back(color);
  ++vertices_with_colors_;
}

void ObjParser::finish_colors() {
  if (vertices_with_colors_ == 0) return;
  out_.mesh.colors.resize(out_.mesh.positions.size(), glm::vec4(1.0f));
  out_.vertices_without_colors = out_.mesh.positions.size() - vertices_with_colors_;
}

void ObjParser::parse_uv(std::string_view line, std::size_t pos) {
  bool present = false;
  glm::vec2 uv;
  uv.x = read_value<float>(line, pos, kUv, true, present);
  uv.y = read_value<float>(line, pos, kUv, false, present);  // 1D textures omit v
  auto& uvs = out_.mesh.uvs;
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y))
    fail_line("texture coordinate " + std::to_string(uvs.size() + 1) + " has a non-finite value");
  if (uvs.size() >= UINT32_MAX) fail_line("more than 2^32-1 texture coordinates");
  uvs.push_back(uv);
}

void ObjParser::parse_normal(std::string_view line, std::size_t pos) {
  bool present = false;
  glm::vec3 n;
  for (int i = 0; i < 3; ++i) n[i] = read_value<float>(line, pos, kNormal, true, present);
  auto& normals = out_.mesh.normals;
  if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z))
    fail_line("normal " + std::to_string(normals.size() + 1) + " has a non-finite component");
  if (normals.size() >= UINT32_MAX) fail_line("more than 2^32-1 normals");
  normals.push_back(n);
}

// OBJ numbers from 1; negative numbers count back from the last one defined so far.
std::uint32_t ObjParser::resolve_index(std::string_view text, Attribute attribute) {
  long long value = 0;
  if (!parse_int(text, value))
    fail_line("face has a malformed " + std::string(kAttributeNames[attribute]) + " index " + quote(text));
  const char* name = kAttributeNames[attribute];
  if (value == 0) fail_line(std::string("face refers to ") + name + " 0 (OBJ numbers them from 1)");
  long long count = static_cast<long long>(attribute_count(out_.mesh, attribute));
  if (value < 0) {
    if (-value > count)
      fail_line(std::string("face refers to ") + name + " " + std::to_string(value) + " but only " + std::to_string(count) +
                " precede it");
    return static_cast<std::uint32_t>(count + value);
  }
  if (value > max_index_[attribute]) {
    max_index_[attribute] = value;
    max_index_line_[attribute] = line_;
  }
  if (value > UINT32_MAX)
    fail_line(std::string("face refers to ") + name + " " + std::to_string(value) + " but the file has " + std::to_string(count));
  return static_cast<std::uint32_t>(value - 1);
}

void ObjParser::parse_face(std::string_view line, std::size_t pos) {
  corners_.clear();
  int with_uv = 0, with_normal = 0;
  for (;;) {
    std::string_view token = next_token(line, pos);
    if (token.empty() || token[0] == '#') break;
    // Split "v/vt/vn"; vt may be empty ("v//vn").
    std::string_view parts[3];
    int part_count = 0;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= token.size(); ++i) {
      if (i < token.size() && token[i] != '/') continue;
      if (part_count == 3) fail_line("face corner " + quote(token) + " has more than three parts");
      parts[part_count++] = token.substr(start, i - start);
      start = i + 1;
    }
    if (parts[0].empty()) fail_line("face corner " + quote(token) + " has no vertex index");
    Corner corner{0, 0, 0, 0};
    corner[kPosition] = resolve_index(parts[0], kPosition);
    if (part_count > 1 && !parts[1].empty()) {
      corner[kUv] = resolve_index(parts[1], kUv);
      ++with_uv;
    }
    if (part_count > 2 && !parts[2].empty()) {
      corner[kNormal] = resolve_index(parts[2], kNormal);
      ++with_normal;
    }
    corners_.push_back(corner);
  }

  const std::uint32_t face = face_number_++;
  auto face_name = [&] { return "face " + std::to_string(face + 1); };
  const int n = static_cast<int>(corners_.size());
  if (n < 3) fail_line(face_name() + " has only " + std::to_string(n) + (n == 1 ? " corner" : " corners"));
  if (with_uv != 0 && with_uv != n) fail_line(face_name() + " has texture coordinates on some corners only");
  if (with_normal != 0 && with_normal != n) fail_line(face_name() + " has normals on some corners only");

  ++out_.file_faces;
  if (with_uv) {
    ++out_.faces_with_uvs;
  } else if (out_.first_face_without_uvs.empty()) {
    out_.first_face_without_uvs = "line " + std::to_string(line_) + ": " + face_name();
  }
  if (with_normal) ++out_.faces_with_normals;
  add_polygon(out_, corners_.data(), corners_.size(), face);
}

void ObjParser::parse_line(std::string_view line, std::size_t line_number) {
  line_ = line_number;
  std::size_t pos = 0;
  std::string_view keyword = next_token(line, pos);
  if (keyword.empty() || keyword[0] == '#') return;
  if (keyword == "v") {
    parse_vertex(line, pos);
  } else if (keyword == "vt") {
    parse_uv(line, pos);
  } else if (keyword == "vn") {
    parse_normal(line, pos);
  } else if (keyword == "f" || keyword == "fo") {  // "fo" is the obsolete spelling of "f"
    parse_face(line, pos);
  } else if (keyword == "o" || (keyword == "g" && !named_by_o_)) {
    // Objects by `o`; in a file without `o` (Maya, 3ds Max), by group.
    named_by_o_ = named_by_o_ || keyword == "o";
    const std::string name = statement_name(line, pos);
    if (!name.empty()) start_object(out_, name);
  } else if (keyword == "usemtl") {
    start_material(out_, statement_name(line, pos));  // a bare `usemtl`: no material ("")
  }
}

void ObjParser::check_forward_references() const {
  for (int a = 0; a < 3; ++a) {
    long long count = static_cast<long long>(attribute_count(out_.mesh, Attribute(a)));
    if (max_index_[a] > count)
      fail(path_, "line " + std::to_string(max_index_line_[a]) + ": face refers to " + kAttributeNames[a] + " " +
                      std::to_string(max_index_[a]) + " but the file has " + std::to_string(count));
  }
}

// Strips the '\' of a continued line (and a CR before the newline); false when not continued.
bool strip_continuation(std::string_view& line) {
  std::string_view trimmed = line;
  if (!trimmed.empty() && trimmed.back() == '\r') trimmed.remove_suffix(1);
  if (trimmed.empty() || trimmed.back() != '\\') return false;
  trimmed.remove_suffix(1);
  line = trimmed;
  return true;
}

}  // namespace

ParsedMesh parse_obj(const std::string& path, std::string_view text) {
  if (const void* nul = std::memchr(text.data(), '\0', text.size()))
    fail(path, "contains a zero byte at offset " + std::to_string(static_cast<const char*>(nul) - text.data()) +
                   "; not an OBJ text file");

  ParsedMesh out;
  out.format = "obj";
  ObjParser parser(path, out);
  std::string joined;  // a logical line assembled from '\'-continued physical lines
  std::size_t pos = 0, line_number = 1;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    const std::size_t first_line = line_number++;
    if (strip_continuation(line)) {
      joined.assign(line);
      bool more = true;
      while (more && pos < text.size()) {
        end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view next = text.substr(pos, end - pos);
        pos = end + 1;
        ++line_number;
        more = strip_continuation(next);
        joined += ' ';
        joined += next;
      }
      line = joined;
    }
    parser.parse_line(line, first_line);
  }
  parser.check_forward_references();
  parser.finish_colors();
  return out;
}

}  // namespace nmbake::mesh_io_detail
