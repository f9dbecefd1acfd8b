// Internals shared by the mesh readers (mesh_io*.cpp). Not part of the library's interface.
//
// Each reader turns the whole file, already in memory, into a ParsedMesh; load_mesh() then applies
// the checks and repairs every format shares (no faces, partial normals or UVs, zero normals).
// Element numbers in messages follow the format's own indexing so a user can find them in the
// file: OBJ counts vertices and faces from 1 and names lines, PLY, OFF and STL count from 0.
#pragma once

#include <algorithm>
#include <array>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "core/errors.h"
#include "core/mesh.h"

namespace nmbake::mesh_io_detail {

// A reader's result. Every corner gets a slot in normal_index and uv_index (0 for a face that has
// none), so that per-corner arrays stay aligned; load_mesh() clears them when they are unusable.
// A reader that knows up front the file has no UVs (normals) turns the slots off. Colours come one
// per position (OBJ, PLY: load_mesh() makes color_index from position_index) or, with
// corner_colors, per corner like normals (Assimp); mesh.colors empty: none.
struct ParsedMesh {
  Mesh mesh;
  // The positions as the file has them, in double, from readers whose values may carry more than
  // float (OBJ, PLY, OFF); empty for STL. mesh.positions holds them rounded to float.
  std::vector<glm::dvec3> exact_positions;
  bool corner_uvs = true;
  bool corner_normals = true;
  bool corner_colors = false;               // color_index gets the corners' colour slot
  std::size_t vertices_without_colors = 0;  // beside vertices with colours: colours are dropped
  std::string format;                       // see MeshLoadInfo::format
  bool fast_path = false;                   // the PLY reader's fast path read it (mesh_io_ply_types.h)
  std::size_t file_faces = 0;
  std::size_t faces = 0;  // faces that became triangles
  std::size_t polygons_triangulated = 0;
  std::size_t faces_with_uvs = 0;
  std::size_t faces_with_normals = 0;
  std::string first_face_without_uvs;  // "line 40: face 3" or "face 0", for the require_uvs message
  std::size_t degenerate_faces_dropped = 0;
  double unit_scale = 1.0;  // see MeshLoadInfo::unit_scale
  // The object triangles are added to (Mesh::objects); by name, for a name met again.
  std::uint32_t object = 0;
  bool per_triangle_objects = false;  // mesh.triangle_object is being filled
  std::unordered_map<std::string, std::uint32_t> object_by_name;
  // The material triangles are added to (Mesh::materials), as for objects.
  std::uint32_t material = 0;
  bool per_triangle_materials = false;  // mesh.triangle_material is being filled
  std::unordered_map<std::string, std::uint32_t> material_by_name;
};

// Triangles added from now on belong to the object `name` (met again: the same object). A name
// given before any triangle names the first object; objects that end up without triangles are
// dropped when the mesh is finished (settle_objects).
inline void start_object(ParsedMesh& out, const std::string& name) {
  Mesh& m = out.mesh;
  if (m.objects.empty()) {
    if (m.source_face.empty()) {
      m.objects.push_back({name, {}});
      out.object_by_name.emplace(name, 0);
      return;
    }
    m.objects.push_back({});  // the triangles before the first name: named after the file
  }
  const auto [it, added] = out.object_by_name.try_emplace(name, std::uint32_t(m.objects.size()));
  if (added) m.objects.push_back({name, {}});
  if (!out.per_triangle_objects && it->second != 0) {
    out.per_triangle_objects = true;
    m.triangle_object.assign(m.source_face.size(), 0);
  }
  out.object = it->second;
}

// Triangles added from now on have the material `name` (met again: the same material). Material 0
// is "", the material of the triangles before the first name; load_mesh() drops the materials no
// triangle uses and numbers the others in the order of first use (settle_materials).
inline void start_material(ParsedMesh& out, const std::string& name) {
  Mesh& m = out.mesh;
  if (m.materials.empty()) {
    m.materials.push_back({});
    out.material_by_name.emplace(std::string(), 0);
  }
  const auto [it, added] = out.material_by_name.try_emplace(name, std::uint32_t(m.materials.size()));
  if (added) m.materials.push_back(name);
  if (!out.per_triangle_materials && it->second != 0) {
    out.per_triangle_materials = true;
    m.triangle_material.assign(m.source_face.size(), 0);
  }
  out.material = it->second;
}

// A colour value as Mesh::colors holds it: `value` over `max` (the integer type's largest value,
// 1 for floats), clamped to [0, 1]. The caller has refused non-finite values.
inline float unit_color(double value, double max = 1.0) { return static_cast<float>(std::clamp(value / max, 0.0, 1.0)); }

// Throws InputError("<path>: <problem>").
[[noreturn]] inline void fail(const std::string& path, const std::string& problem) { throw InputError(path + ": " + problem); }

ParsedMesh parse_obj(const std::string& path, std::string_view text);
// fast: binary triangle meshes take the PLY reader's fast path (mesh_io_ply_types.h) where they
// can; false only to compare the two.
ParsedMesh parse_ply(const std::string& path, std::string_view bytes, bool fast = true);
ParsedMesh parse_off(const std::string& path, std::string_view text);
ParsedMesh parse_stl(const std::string& path, std::string_view bytes);
// Through Assimp (mesh_io_assimp.cpp): by `path` when `read_path` (a .gltf finds its .bin), else
// from `bytes`, with `ext` (lower case, no dot) naming the format.
ParsedMesh parse_assimp(const std::string& path, const std::string& ext, std::string_view bytes, bool read_path, unsigned uv_set);
// Whether Assimp reads files with this extension (lower case, no dot).
bool assimp_reads(const std::string& ext);

// True when the size matches a binary STL's facet count (84 + 50 bytes per facet).
bool is_binary_stl(std::string_view bytes);

// (position, uv, normal, colour) indices of one corner; the colour slot is read only with
// ParsedMesh::corner_colors.
using Corner = std::array<std::uint32_t, 4>;

// Polygons with more corners than this are not fanned (below).
constexpr std::size_t kMaxFanCorners = 64;

// Appends a polygon's `n` corners as triangles of file face `face`: the fan (0,i,i+1) as Blender and
// most tools cut it, up to kMaxFanCorners; beyond, corners are cut off in passes (every second
// corner of what is left, each with its two neighbours), so triangles halve in number and double in
// size from pass to pass. A fan of n corners is n thin triangles spanning the polygon, whose boxes
// all overlap, so every ray would meet all of them; the passes give boxes that overlap about
// log n deep. Both cover a convex polygon exactly.
inline void add_polygon(ParsedMesh& out, const Corner* corners, std::size_t n, std::uint32_t face) {
  Mesh& m = out.mesh;
  auto triangle = [&](std::size_t a, std::size_t b, std::size_t c) {
    for (std::size_t k : {a, b, c}) {
      m.position_index.push_back(corners[k][0]);
      if (out.corner_uvs) m.uv_index.push_back(corners[k][1]);
      if (out.corner_normals) m.normal_index.push_back(corners[k][2]);
      if (out.corner_colors) m.color_index.push_back(corners[k][3]);
    }
    m.source_face.push_back(face);
    if (out.per_triangle_objects) m.triangle_object.push_back(out.object);
    if (out.per_triangle_materials) m.triangle_material.push_back(out.material);
  };
  if (n <= kMaxFanCorners) {
    for (std::size_t i = 1; i + 1 < n; ++i) triangle(0, i, i + 1);
  } else {
    std::vector<std::size_t> left(n), next;
    for (std::size_t i = 0; i < n; ++i) left[i] = i;
    while (left.size() >= 3) {
      next.clear();
      std::size_t i = 0;
      for (; i + 2 < left.size(); i += 2) {
        triangle(left[i], left[i + 1], left[i + 2]);
        next.push_back(left[i]);
      }
      next.insert(next.end(), left.begin() + std::ptrdiff_t(i), left.end());
      left.swap(next);
    }
  }
  ++out.faces;
  if (n > 3) ++out.polygons_triangulated;
}

// Text scanning -------------------------------------------------------------------------------

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
inline bool is_space(char c) { return is_blank(c) || c == '\n'; }

// The next whitespace-separated token of `line` from `pos` (empty at the end); advances pos.
inline std::string_view next_token(std::string_view line, std::size_t& pos) {
  while (pos < line.size() && is_space(line[pos])) ++pos;
  std::size_t start = pos;
  while (pos < line.size() && !is_space(line[pos])) ++pos;
  return line.substr(start, pos - start);
}

// A token quoted for a message, shortened so a binary blob cannot flood the terminal.
inline std::string quote(std::string_view token) {
  std::string s(token.substr(0, 32));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  return "'" + s + (token.size() > 32 ? "...'" : "'");
}

// Parses the whole token as a float or double (a leading '+' is accepted, as C's strtod does).
// Values beyond the type's range come back as +-inf so the caller's finiteness check reports them;
// values below it become 0 or a denormal. Returns false when the token is not entirely a number.
template <typename Real>
bool parse_real(std::string_view token, Real& out) {
  const char* first = token.data();
  const char* last = first + token.size();
  if (last - first > 1 && *first == '+' && first[1] != '-' && first[1] != '+') ++first;
  auto result = std::from_chars(first, last, out);
  if (first == last || result.ptr != last) return false;
  if (result.ec == std::errc::result_out_of_range) {
    // from_chars leaves `out` untouched here; strtod tells overflow (inf) from underflow (0). The
    // whole token is copied, however long (a fixed buffer would cut "7.000...0001e400" to 7).
    const std::string whole(first, last);
    out = static_cast<Real>(std::strtod(whole.c_str(), nullptr));
    return true;
  }
  return result.ec == std::errc();
}

// Parses the whole token as a decimal integer, '+' allowed. False on junk or more than 18 digits.
// Hand-written because face indices are the most frequent tokens of an OBJ file.
inline bool parse_int(std::string_view token, long long& out) {
  std::size_t i = 0;
  bool negative = false;
  if (i < token.size() && (token[i] == '-' || token[i] == '+')) negative = token[i++] == '-';
  if (i == token.size() || token.size() - i > 18) return false;
  long long value = 0;
  for (; i < token.size(); ++i) {
    unsigned digit = static_cast<unsigned char>(token[i]) - unsigned('0');
    if (digit > 9) return false;
    value = value * 10 + digit;
  }
  out = negative ? -value : value;
  return true;
}

}  // namespace nmbake::mesh_io_detail
