// Stanford PLY reader: ascii, binary_little_endian and binary_big_endian, every scalar type under
// both its old (char, uchar, ...) and its sized (int8, uint8, ...) name. Reads x y z, nx ny nz, a
// UV pair (s/t, u/v, texture_u/texture_v or texture_s/texture_t) and a colour (red green blue
// [alpha], or diffuse_red ... [diffuse_alpha], of any type: ply_types.h color_scale) from
// "vertex", the index list
// (vertex_indices or vertex_index) and an optional per-corner "texcoord" list from "face"; every
// other property and element, lists included, is skipped.
//
// The header's counts are checked against the bytes that follow it before anything is allocated,
// so a hostile count cannot make us reserve gigabytes or loop for minutes.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/mesh_io_detail.h"
#include "io/mesh_io_ply_types.h"

namespace nmbake::mesh_io_detail {
namespace {

using namespace ply;

bool is_integer_type(Scalar t) { return t != Scalar::float32 && t != Scalar::float64; }

bool parse_scalar_name(std::string_view name, Scalar& t) {
  struct Name {
    const char* text;
    Scalar type;
  };
  static const Name names[] = {
      {"char", Scalar::int8},     {"int8", Scalar::int8},       {"uchar", Scalar::uint8},    {"uint8", Scalar::uint8},
      {"short", Scalar::int16},   {"int16", Scalar::int16},     {"ushort", Scalar::uint16},  {"uint16", Scalar::uint16},
      {"int", Scalar::int32},     {"int32", Scalar::int32},     {"uint", Scalar::uint32},    {"uint32", Scalar::uint32},
      {"float", Scalar::float32}, {"float32", Scalar::float32}, {"double", Scalar::float64}, {"float64", Scalar::float64}};
  for (const Name& n : names)
    if (name == n.text) {
      t = n.type;
      return true;
    }
  return false;
}

// Header ------------------------------------------------------------------------------------------

Header parse_header(const std::string& path, std::string_view bytes) {
  if (bytes.size() < 4 || bytes.substr(0, 3) != "ply" || !is_space(bytes[3]))
    fail(path, "not a PLY file (it does not start with 'ply')");
  Header header;
  bool have_format = false;
  std::size_t pos = 0, line_number = 0;
  for (;;) {
    if (pos >= bytes.size()) fail(path, "header has no end_header line");
    std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) fail(path, "header has no end_header line");
    std::string_view line = bytes.substr(pos, end - pos);
    pos = end + 1;
    ++line_number;
    auto header_fail = [&](const std::string& problem) {
      fail(path, "header line " + std::to_string(line_number) + ": " + problem);
    };
    std::size_t p = 0;
    std::string_view keyword = next_token(line, p);
    if (line_number == 1 || keyword.empty() || keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") break;
    if (keyword == "format") {
      std::string_view name = next_token(line, p);
      if (name == "ascii") {
        header.encoding = Encoding::ascii;
      } else if (name == "binary_little_endian") {
        header.encoding = Encoding::binary_little_endian;
      } else if (name == "binary_big_endian") {
        header.encoding = Encoding::binary_big_endian;
      } else {
        header_fail("unknown format " + quote(name));
      }
      have_format = true;
    } else if (keyword == "element") {
      Element element;
      element.name = std::string(next_token(line, p));
      std::string_view count_text = next_token(line, p);
      long long count = 0;
      if (element.name.empty() || !parse_int(count_text, count)) header_fail("element line needs a name and a count");
      if (count < 0) fail(path, "element " + element.name + " has a negative count " + std::to_string(count));
      element.count = static_cast<std::uint64_t>(count);
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) header_fail("property before any element");
      Property property;
      std::string_view type = next_token(line, p);
      if (type == "list") {
        property.is_list = true;
        std::string_view count_type = next_token(line, p);
        if (!parse_scalar_name(count_type, property.count_type)) header_fail("unknown list count type " + quote(count_type));
        if (!is_integer_type(property.count_type)) header_fail("list count type must be an integer type");
        type = next_token(line, p);
      }
      if (!parse_scalar_name(type, property.type)) header_fail("unknown property type " + quote(type));
      property.name = std::string(next_token(line, p));
      if (property.name.empty()) header_fail("property has no name");
      header.elements.back().properties.push_back(std::move(property));
    }
    // Other lines are ignored like comments: old Blender exporters wrote a bare "Created by ..."
    // line, and a misspelt element or property line still fails later on sizes or indices.
  }
  if (!have_format) fail(path, "header has no format line");
  header.data_offset = pos;
  return header;
}

// Fewest bytes one instance of `element` can take; lists count as empty unless `list_items` says
// otherwise (face index lists need 3 to be valid).
std::uint64_t min_instance_bytes(const Element& element, Encoding encoding, unsigned list_items) {
  std::uint64_t bytes = 0;
  for (const Property& p : element.properties) {
    unsigned items = p.is_list ? list_items : 1;
    if (encoding == Encoding::ascii) bytes += 2 * (items + (p.is_list ? 1u : 0u));  // a digit and a separator per value
    else bytes += (p.is_list ? scalar_size(p.count_type) : 0) + std::uint64_t(items) * scalar_size(p.type);
  }
  return bytes;
}

void check_counts_fit(const std::string& path, const Header& header, std::size_t data_bytes) {
  // The last ascii value may lack its separator.
  std::uint64_t remaining = data_bytes + (header.encoding == Encoding::ascii ? 1 : 0);
  for (const Element& e : header.elements) {
    std::uint64_t each = min_instance_bytes(e, header.encoding, 0);
    if (each == 0) continue;
    if (e.count > remaining / each)
      fail(path, "header declares " + std::to_string(e.count) + " " + e.name + " elements but only " +
                     std::to_string(data_bytes) + " bytes of data follow it (truncated file or bad count)");
    remaining -= e.count * each;
  }
}

Role vertex_role(const std::string& name, const Element& vertex) {
  auto has = [&](const char* other) {
    for (const Property& p : vertex.properties)
      if (p.name == other) return true;
    return false;
  };
  if (name == "x") return kX;
  if (name == "y") return kY;
  if (name == "z") return kZ;
  if (name == "nx") return kNx;
  if (name == "ny") return kNy;
  if (name == "nz") return kNz;
  // The first complete colour in this order wins; alpha only beside it.
  static const char* const colors[][4] = {{"red", "green", "blue", "alpha"},
                                          {"diffuse_red", "diffuse_green", "diffuse_blue", "diffuse_alpha"}};
  for (const auto& color : colors) {
    if (!has(color[0]) || !has(color[1]) || !has(color[2])) continue;
    for (int k = 0; k < 4; ++k)
      if (name == color[k]) return Role(kRed + k);
    break;
  }
  // The first complete UV pair in this order wins.
  static const char* const pairs[][2] = {{"s", "t"}, {"u", "v"}, {"texture_u", "texture_v"}, {"texture_s", "texture_t"}};
  for (const auto& pair : pairs) {
    if (!has(pair[0]) || !has(pair[1])) continue;
    if (name == pair[0]) return kU;
    if (name == pair[1]) return kV;
    return kNone;
  }
  return kNone;
}

// Scalar reading ------------------------------------------------------------------------------------

// A value for a message: integers without a fraction, anything else (NaN included) as is.
std::string number_text(double v) {
  if (std::fabs(v) < 1e15 && v == std::floor(v)) return std::to_string(static_cast<long long>(v));
  return std::to_string(v);
}

// Both encodings behind one interface: values come out as doubles (exact for every PLY integer).
class DataReader {
 public:
  DataReader(const std::string& path, const Header& header, std::string_view bytes)
      : path_(path),
        encoding_(header.encoding),
        data_(bytes.substr(header.data_offset)),
        swap_(header.encoding != Encoding::ascii && (header.encoding == Encoding::binary_little_endian) != kHostLittleEndian) {}

  void start(const Element& element, std::uint64_t index) {
    element_ = &element;
    index_ = index;
  }
  double read(Scalar t) {
    if (encoding_ == Encoding::ascii) return read_ascii();
    unsigned size = scalar_size(t);
    if (data_.size() - pos_ < size) truncated();
    double value = load_scalar(data_.data() + pos_, t, swap_);
    pos_ += size;
    return value;
  }
  void skip(Scalar t, std::uint64_t n) {
    if (encoding_ == Encoding::ascii) {
      for (std::uint64_t i = 0; i < n; ++i)
        if (next_token(data_, pos_).empty()) truncated();
      return;
    }
    std::uint64_t size = n * scalar_size(t);  // n was checked against the file size by the caller
    if (data_.size() - pos_ < size) truncated();
    pos_ += static_cast<std::size_t>(size);
  }
  // A list's length, refusing negative, fractional and impossible ones.
  std::uint64_t read_list_count(const Property& p) {
    double count = read(p.count_type);
    if (count < 0 || count != std::floor(count))
      fail_here("has a list '" + p.name + "' with an invalid length " + number_text(count));
    // Every item takes at least one byte: a longer list (an ascii 1e30 or inf included) cannot be
    // in the file, and checking before the cast keeps it defined.
    if (count > double(data_.size() - pos_)) truncated();
    std::uint64_t n = static_cast<std::uint64_t>(count);
    std::uint64_t item_bytes = encoding_ == Encoding::ascii ? 1 : scalar_size(p.type);
    if (n * item_bytes > data_.size() - pos_) truncated();
    return n;
  }
  [[noreturn]] void fail_here(const std::string& problem) const {
    fail(path_, element_->name + " " + std::to_string(index_) + " " + problem);
  }

 private:
  // Out of line, like truncated(), so that read() stays small enough to inline into the loops.
  [[gnu::noinline]] double read_ascii() {
    std::string_view token = next_token(data_, pos_);
    if (token.empty()) truncated();
    double value = 0;
    if (!parse_real(token, value)) fail_here("has a malformed value " + quote(token));
    return value;
  }
  [[noreturn, gnu::noinline]] void truncated() const {
    fail(path_,
         "truncated: file ends in " + element_->name + " " + std::to_string(index_) + " of " + std::to_string(element_->count));
  }
  const std::string& path_;
  Encoding encoding_;
  std::string_view data_;
  bool swap_;
  std::size_t pos_ = 0;
  const Element* element_ = nullptr;
  std::uint64_t index_ = 0;
};

// Data -----------------------------------------------------------------------------------------------

Layout assign_roles(const std::string& path, Header& header) {
  Layout layout;
  for (Element& e : header.elements) {
    if (e.name == "vertex" && !layout.vertex) {
      bool x = false, y = false, z = false, nx = false, ny = false, nz = false, u = false, red = false;
      for (Property& p : e.properties) {
        if (p.is_list) continue;
        p.role = vertex_role(p.name, e);
        x |= p.role == kX, y |= p.role == kY, z |= p.role == kZ;
        nx |= p.role == kNx, ny |= p.role == kNy, nz |= p.role == kNz, u |= p.role == kU, red |= p.role == kRed;
      }
      if (!x || !y || !z) fail(path, "vertex element lacks an x, y or z property");
      layout.normals = nx && ny && nz;
      if (!layout.normals)
        for (Property& p : e.properties)
          if (p.role == kNx || p.role == kNy || p.role == kNz) p.role = kNone;
      layout.vertex_uvs = u;
      layout.colors = red;  // vertex_role gives colour roles only to a complete red, green, blue
      layout.vertex = &e;
    } else if (e.name == "face" && !layout.face) {
      for (Property& p : e.properties) {
        if (!p.is_list) continue;
        if ((p.name == "vertex_indices" || p.name == "vertex_index") && !layout.face) {
          p.role = kIndices;
          layout.face = &e;
        } else if (p.name == "texcoord") {
          p.role = kTexcoords;
          layout.face_texcoords = true;
        }
      }
      if (!layout.face) fail(path, "face element has no vertex_indices list");
    }
  }
  if (layout.face && !layout.vertex) fail(path, "has faces but no vertex element");
  if (layout.face_texcoords) layout.vertex_uvs = false;
  return layout;
}

void read_vertex(DataReader& reader, const Element& e, const Layout& layout, std::uint64_t i, ParsedMesh& out) {
  Mesh& m = out.mesh;
  glm::dvec3 exact(0);  // in double: a mesh far from the origin is re-centred before rounding to float
  glm::vec3 n(0);
  glm::vec2 uv(0);
  glm::vec4 color(1);
  bool finite_color = true;
  for (const Property& prop : e.properties) {
    if (prop.is_list) {
      reader.skip(prop.type, reader.read_list_count(prop));
      continue;
    }
    if (prop.role == kNone) {
      reader.skip(prop.type, 1);
      continue;
    }
    const double exact_value = reader.read(prop.type);
    const float value = static_cast<float>(exact_value);
    switch (prop.role) {
      case kX: exact.x = exact_value; break;
      case kY: exact.y = exact_value; break;
      case kZ: exact.z = exact_value; break;
      case kNx: n.x = value; break;
      case kNy: n.y = value; break;
      case kNz: n.z = value; break;
      case kU: uv.x = value; break;
      case kV: uv.y = value; break;
      case kRed:
      case kGreen:
      case kBlue:
      case kAlpha:
        finite_color = finite_color && std::isfinite(exact_value);
        color[prop.role - kRed] = unit_color(exact_value, color_scale(prop.type));
        break;
      default: break;
    }
  }
  const glm::vec3 p(exact);
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) reader.fail_here("has a non-finite coordinate");
  if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z)) reader.fail_here("has a non-finite normal");
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) reader.fail_here("has a non-finite texture coordinate");
  if (!finite_color) reader.fail_here("has a non-finite colour");
  m.positions[i] = p;
  out.exact_positions[i] = exact;
  if (layout.normals) m.normals[i] = n;
  if (layout.vertex_uvs) m.uvs[i] = uv;
  if (layout.colors) m.colors[i] = color;
}

class FaceReader {
 public:
  FaceReader(ParsedMesh& out, const Layout& layout, std::size_t vertex_count)
      : out_(out), layout_(layout), vertex_count_(vertex_count) {}

  void read(DataReader& reader, const Element& e, std::uint64_t i) {
    corners_.clear();
    texcoords_.clear();
    for (const Property& prop : e.properties) {
      if (!prop.is_list) {
        reader.skip(prop.type, 1);
        continue;
      }
      std::uint64_t n = reader.read_list_count(prop);
      if (prop.role == kIndices) {
        read_indices(reader, prop, n);
      } else if (prop.role == kTexcoords) {
        for (std::uint64_t k = 0; k < n; ++k) texcoords_.push_back(static_cast<float>(reader.read(prop.type)));
      } else {
        reader.skip(prop.type, n);
      }
    }
    add(reader, static_cast<std::uint32_t>(i));
  }

 private:
  void read_indices(DataReader& reader, const Property& prop, std::uint64_t n) {
    for (std::uint64_t k = 0; k < n; ++k) {
      double v = reader.read(prop.type);
      if (v < 0 || v >= double(vertex_count_) || v != std::floor(v))
        reader.fail_here("refers to vertex " + number_text(v) + " but the file has " + std::to_string(vertex_count_));
      auto index = static_cast<std::uint32_t>(v);
      corners_.push_back({index, index, index, index});
    }
  }

  void add(DataReader& reader, std::uint32_t face) {
    const std::size_t n = corners_.size();
    if (n < 3) reader.fail_here("has only " + std::to_string(n) + (n == 1 ? " corner" : " corners"));
    bool has_uvs = layout_.vertex_uvs;
    if (layout_.face_texcoords) {
      // Per-corner UVs (MeshLab's "texcoord" list, u v per corner) replace per-vertex ones.
      has_uvs = texcoords_.size() == 2 * n;
      if (has_uvs) {
        auto& uvs = out_.mesh.uvs;
        for (std::size_t c = 0; c < n; ++c) {
          glm::vec2 uv(texcoords_[2 * c], texcoords_[2 * c + 1]);
          if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) reader.fail_here("has a non-finite texture coordinate");
          corners_[c][1] = static_cast<std::uint32_t>(uvs.size());
          uvs.push_back(uv);
        }
      }
    }
    ++out_.file_faces;
    if (has_uvs) ++out_.faces_with_uvs;
    else if (out_.first_face_without_uvs.empty()) out_.first_face_without_uvs = "face " + std::to_string(face);
    if (layout_.normals) ++out_.faces_with_normals;
    add_polygon(out_, corners_.data(), n, face);
  }

  ParsedMesh& out_;
  const Layout& layout_;
  std::size_t vertex_count_;
  std::vector<Corner> corners_;
  std::vector<float> texcoords_;
};

// Room for the triangles of `faces` faces without trusting a count the file may not back up.
void reserve_triangles(ParsedMesh& out, const Header& header, const Element& face, std::size_t data_bytes) {
  std::uint64_t min_face = min_instance_bytes(face, header.encoding, 3);
  std::uint64_t faces = std::min<std::uint64_t>(face.count, min_face ? data_bytes / min_face : 0);
  Mesh& m = out.mesh;
  m.position_index.reserve(3 * faces);
  if (out.corner_uvs) m.uv_index.reserve(3 * faces);
  if (out.corner_normals) m.normal_index.reserve(3 * faces);
  m.source_face.reserve(faces);
}

}  // namespace

ParsedMesh parse_ply(const std::string& path, std::string_view bytes, bool fast) {
  Header header = parse_header(path, bytes);
  const std::size_t data_bytes = bytes.size() - header.data_offset;
  check_counts_fit(path, header, data_bytes);
  Layout layout = assign_roles(path, header);

  ParsedMesh out;
  out.format = header.encoding == Encoding::ascii ? "ply-ascii" : "ply-binary";
  if (!layout.face || layout.face->count == 0) return out;  // load_mesh reports "no faces"

  // Vertex counts were checked against the file size, so these allocations are backed by data.
  const Element& vertex = *layout.vertex;
  if (vertex.count > UINT32_MAX) fail(path, "more than 2^32-1 vertices");
  if (fast) {
    ParsedMesh quick;
    quick.format = out.format;
    if (parse_fast(header, layout, bytes.substr(header.data_offset), quick)) return quick;
  }
  Mesh& m = out.mesh;
  m.positions.resize(vertex.count);
  out.exact_positions.resize(vertex.count);
  if (layout.normals) m.normals.resize(vertex.count);
  if (layout.vertex_uvs) m.uvs.resize(vertex.count);
  if (layout.colors) m.colors.resize(vertex.count);
  out.corner_uvs = layout.vertex_uvs || layout.face_texcoords;
  out.corner_normals = layout.normals;
  reserve_triangles(out, header, *layout.face, data_bytes);

  DataReader reader(path, header, bytes);
  FaceReader faces(out, layout, vertex.count);
  int needed = 2;  // elements left to read: the vertices and the faces
  for (const Element& e : header.elements) {
    const bool is_vertex = &e == layout.vertex, is_face = &e == layout.face;
    if (e.properties.empty()) continue;  // takes no bytes, however large its count
    for (std::uint64_t i = 0; i < e.count; ++i) {
      reader.start(e, i);
      if (is_vertex) {
        read_vertex(reader, e, layout, i, out);
      } else if (is_face) {
        faces.read(reader, e, i);
      } else {
        for (const Property& prop : e.properties) reader.skip(prop.type, prop.is_list ? reader.read_list_count(prop) : 1);
      }
    }
    if ((is_vertex || is_face) && --needed == 0) break;  // nothing after them matters
  }
  return out;
}

}  // namespace nmbake::mesh_io_detail
