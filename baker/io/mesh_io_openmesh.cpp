// OFF and STL through OpenMesh's readers, the only code in nmbake that includes OpenMesh.
//
// OpenMesh's readers trust their input: an OFF count or corner count is believed and looped over,
// a comment line or counts on the header line derail the OFF reader silently, and problems go to
// omerr() while the read still "succeeds". So every file is first checked here (a pre-scan that
// stores nothing), OpenMesh then reads it into a flat importer of ours (no halfedge structure, so no
// face is dropped or split for being non-manifold), anything OpenMesh writes to omerr() becomes an
// InputError, and the element counts it delivers are compared with the file's.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <OpenMesh/Core/IO/Options.hh>
#include <OpenMesh/Core/IO/importer/BaseImporter.hh>
#include <OpenMesh/Core/IO/reader/OFFReader.hh>
#include <OpenMesh/Core/IO/reader/STLReader.hh>
#include <OpenMesh/Core/System/omstream.hh>

#include "io/mesh_io_detail.h"

namespace nmbake::mesh_io_detail {
namespace {

using OpenMesh::EdgeHandle;
using OpenMesh::FaceHandle;
using OpenMesh::HalfedgeHandle;
using OpenMesh::Vec2f;
using OpenMesh::Vec3d;
using OpenMesh::Vec3f;
using OpenMesh::Vec3uc;
using OpenMesh::Vec4f;
using OpenMesh::Vec4uc;
using OpenMesh::VertexHandle;
using StatusInfo = OpenMesh::Attributes::StatusInfo;

// Collects what a reader delivers straight into a ParsedMesh. Problems are remembered (the first
// one is reported) rather than thrown through OpenMesh's code.
class FlatImporter : public OpenMesh::IO::BaseImporter {
 public:
  explicit FlatImporter(ParsedMesh& out) : out_(out) {}

  const std::string& problem() const { return problem_; }
  std::size_t normals_set() const { return normals_set_; }
  std::size_t uvs_set() const { return uvs_set_; }

  VertexHandle add_vertex(const Vec3f& p) override {
    auto& positions = out_.mesh.positions;
    if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
      note("vertex " + std::to_string(positions.size()) + " has a non-finite coordinate");
    positions.emplace_back(p[0], p[1], p[2]);
    return VertexHandle(static_cast<int>(positions.size() - 1));
  }
  VertexHandle add_vertex() override { return add_vertex(Vec3f(0, 0, 0)); }

  FaceHandle add_face(const VHandles& corners) override {
    const auto face = static_cast<std::uint32_t>(out_.file_faces++);
    const std::size_t vertex_count = out_.mesh.positions.size();
    if (corners.size() < 3) {
      note("face " + std::to_string(face) + " has only " + std::to_string(corners.size()) + " corners");
      return FaceHandle(static_cast<int>(face));
    }
    corners_.clear();
    for (VertexHandle v : corners) {
      if (v.idx() < 0 || std::size_t(v.idx()) >= vertex_count) {
        note("face " + std::to_string(face) + " refers to vertex " + std::to_string(v.idx()) + " but the file has " +
             std::to_string(vertex_count));
        return FaceHandle(static_cast<int>(face));
      }
      auto i = static_cast<std::uint32_t>(v.idx());
      corners_.push_back({i, i, i});
    }
    add_polygon(out_, corners_.data(), corners_.size(), face);
    return FaceHandle(static_cast<int>(face));
  }

  void set_normal(VertexHandle v, const Vec3f& n) override {
    auto& normals = out_.mesh.normals;
    if (normals.size() < out_.mesh.positions.size()) normals.resize(out_.mesh.positions.size());
    if (v.idx() < 0 || std::size_t(v.idx()) >= normals.size()) return;
    if (!std::isfinite(n[0]) || !std::isfinite(n[1]) || !std::isfinite(n[2]))
      note("vertex " + std::to_string(v.idx()) + " has a non-finite normal");
    normals[v.idx()] = glm::vec3(n[0], n[1], n[2]);
    ++normals_set_;
  }
  void set_normal(VertexHandle v, const Vec3d& n) override { set_normal(v, Vec3f(n)); }
  void set_texcoord(VertexHandle v, const Vec2f& t) override {
    auto& uvs = out_.mesh.uvs;
    if (uvs.size() < out_.mesh.positions.size()) uvs.resize(out_.mesh.positions.size());
    if (v.idx() < 0 || std::size_t(v.idx()) >= uvs.size()) return;
    if (!std::isfinite(t[0]) || !std::isfinite(t[1]))
      note("vertex " + std::to_string(v.idx()) + " has a non-finite texture coordinate");
    uvs[v.idx()] = glm::vec2(t[0], t[1]);
    ++uvs_set_;
  }

  size_t n_vertices() const override { return out_.mesh.positions.size(); }
  size_t n_faces() const override { return out_.file_faces; }
  size_t n_edges() const override { return 0; }

  // Halfedge-level construction, colours, status and face normals: not used by OFF and STL, or
  // not wanted (facet normals are not vertex normals).
  HalfedgeHandle add_edge(VertexHandle, VertexHandle) override { return HalfedgeHandle(); }
  FaceHandle add_face(HalfedgeHandle) override { return FaceHandle(); }
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec2f>&) override {}
  void add_face_texcoords(FaceHandle, VertexHandle, const std::vector<Vec3f>&) override {}
  void set_face_texindex(FaceHandle, int) override {}
  void set_point(VertexHandle v, const Vec3f& p) override {
    if (v.idx() >= 0 && std::size_t(v.idx()) < out_.mesh.positions.size())
      out_.mesh.positions[v.idx()] = glm::vec3(p[0], p[1], p[2]);
  }
  void set_halfedge(VertexHandle, HalfedgeHandle) override {}
  void set_color(VertexHandle, const Vec3uc&) override {}
  void set_color(VertexHandle, const Vec4uc&) override {}
  void set_color(VertexHandle, const Vec3f&) override {}
  void set_color(VertexHandle, const Vec4f&) override {}
  void set_status(VertexHandle, const StatusInfo&) override {}
  void set_next(HalfedgeHandle, HalfedgeHandle) override {}
  void set_face(HalfedgeHandle, FaceHandle) override {}
  void request_face_texcoords2D() override {}
  void set_texcoord(HalfedgeHandle, const Vec2f&) override {}
  void set_texcoord(VertexHandle, const Vec3f&) override {}
  void set_texcoord(HalfedgeHandle, const Vec3f&) override {}
  void set_status(HalfedgeHandle, const StatusInfo&) override {}
  void set_color(EdgeHandle, const Vec3uc&) override {}
  void set_color(EdgeHandle, const Vec4uc&) override {}
  void set_color(EdgeHandle, const Vec3f&) override {}
  void set_color(EdgeHandle, const Vec4f&) override {}
  void set_status(EdgeHandle, const StatusInfo&) override {}
  void set_normal(FaceHandle, const Vec3f&) override {}
  void set_normal(FaceHandle, const Vec3d&) override {}
  void set_color(FaceHandle, const Vec3uc&) override {}
  void set_color(FaceHandle, const Vec4uc&) override {}
  void set_color(FaceHandle, const Vec3f&) override {}
  void set_color(FaceHandle, const Vec4f&) override {}
  void set_status(FaceHandle, const StatusInfo&) override {}
  void add_texture_information(int, std::string) override {}

  // Counts were validated before reading, so reserving them is safe.
  void reserve(unsigned int vertices, unsigned int, unsigned int faces) override {
    out_.mesh.positions.reserve(vertices);
    out_.mesh.position_index.reserve(3 * std::size_t(faces));
    out_.mesh.source_face.reserve(faces);
  }

 private:
  void note(const std::string& problem) {
    if (problem_.empty()) problem_ = problem;
  }

  ParsedMesh& out_;
  std::string problem_;
  std::vector<Corner> corners_;
  std::size_t normals_set_ = 0, uvs_set_ = 0;
};

// OpenMesh's readers are singletons with per-read state and report through the global omerr(), so
// one read at a time; while it runs, omerr() writes into a string instead of stderr.
std::mutex openmesh_mutex;

// Swaps omerr()'s stream buffer rather than using mostream::connect/disconnect: disconnect() drops
// the target object it allocated in connect() without deleting it, a leak per load under ASan.
class OmerrCapture {
 public:
  OmerrCapture() : previous_(omerr().rdbuf(text_.rdbuf())) {}
  ~OmerrCapture() { omerr().rdbuf(previous_); }
  OmerrCapture(const OmerrCapture&) = delete;
  OmerrCapture& operator=(const OmerrCapture&) = delete;

  // What OpenMesh wrote, on one line.
  std::string text() const {
    std::string s = text_.str();
    while (!s.empty() && is_space(s.back())) s.pop_back();
    for (char& c : s)
      if (c == '\n') c = ';';
    return s;
  }

 private:
  std::ostringstream text_;
  std::streambuf* previous_;
};

// Runs `read` (an OpenMesh reader call) into `out` and turns everything it leaves unsaid into errors.
template <typename Read>
void read_with_openmesh(const std::string& path, ParsedMesh& out, Read read) {
  std::lock_guard<std::mutex> lock(openmesh_mutex);
  FlatImporter importer(out);
  OmerrCapture capture;
  bool ok = read(importer);
  std::string messages = capture.text();
  if (!importer.problem().empty()) fail(path, importer.problem());
  if (!messages.empty()) fail(path, "OpenMesh: " + messages);
  if (!ok) fail(path, "OpenMesh could not read the file");
  const std::size_t vertices = out.mesh.positions.size();
  out.faces_with_normals = importer.normals_set() == vertices && vertices > 0 ? out.faces : 0;
  out.faces_with_uvs = importer.uvs_set() == vertices && vertices > 0 ? out.faces : 0;
  if (out.faces_with_uvs == 0) out.first_face_without_uvs = "face 0";
}

// OFF pre-scan ------------------------------------------------------------------------------------

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
      std::size_t hash = line.find('#');
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

// Reads `count` finite numbers from `line` at `pos` into `out`, or fails naming the line and vertex.
template <typename Real>
void read_numbers(const std::string& path, std::string_view line, std::size_t& pos, int count, const std::string& where,
                  const char* what, Real* out) {
  for (int i = 0; i < count; ++i) {
    std::string_view token = next_token(line, pos);
    if (token.empty()) fail(path, where + " has fewer than " + std::to_string(count) + " " + what);
    if (!parse_real(token, out[i])) fail(path, where + " has a malformed number " + quote(token));
    if (!std::isfinite(out[i]) || !std::isfinite(static_cast<float>(out[i]))) fail(path, where + " has a non-finite " + what);
  }
}

// What check_off() reads of an ASCII OFF file.
struct OffScan {
  std::string clean;  // what OpenMesh's reader is given
  std::size_t vertex_count = 0, face_count = 0;
  std::vector<glm::dvec3> positions;  // in double (OpenMesh reads float)
  std::vector<glm::vec3> normals;     // per vertex, for NOFF
  std::vector<glm::vec2> uvs;         // per vertex, for STOFF
};

// Validates an ASCII OFF file and returns it in the plain shape OpenMesh's reader needs: "OFF"
// alone on the first line, the counts on the second, then one vertex (x y z) or face (corner count
// and indices) per line, nothing else. OpenMesh reads a face line's indices with operator>> and
// leaves the rest, so anything after the last index (a face colour, junk) was read as the next
// face's corner count: a fuzzed file made it push 2^32 corners. It also takes N, ST and C from
// the magic only in a private call, so normals and texture coordinates are read here.
OffScan check_off(const std::string& path, std::string_view text) {
  OffScan scan;
  LineCursor lines(text);
  std::string_view line;
  if (!lines.next(line)) fail(path, "no faces");
  std::size_t p = 0;
  std::string_view magic = next_token(line, p);
  if (!is_off_magic(magic)) fail(path, "not an OFF file (it does not start with 'OFF')");
  if (magic.find_first_of("4n") != std::string_view::npos) fail(path, quote(magic) + " (4D or n-D OFF) is not supported");
  std::string_view word = next_token(line, p);
  if (word == "BINARY") fail(path, "binary OFF is not supported; save it as ASCII OFF or as PLY");
  const bool has_texcoords = magic.substr(0, 2) == "ST";
  const bool has_colours = magic.find('C') != std::string_view::npos;
  const bool has_normals = magic.find('N') != std::string_view::npos;

  // The counts follow on the magic's line or on the next one.
  std::string_view counts_line = line.substr(p - word.size());
  if (word.empty() && !lines.next(counts_line)) fail(path, "file ends before the vertex and face counts");
  std::size_t cp = 0;
  long long counts[2] = {0, 0};
  for (long long& c : counts) {
    std::string_view token = next_token(counts_line, cp);
    if (!parse_int(token, c))
      fail(path, "line " + std::to_string(lines.line_number()) + ": malformed vertex or face count " + quote(token));
    if (c < 0) fail(path, "line " + std::to_string(lines.line_number()) + ": negative count " + std::to_string(c));
  }
  if (counts[0] > UINT32_MAX || counts[1] > INT32_MAX) fail(path, "too many vertices or faces");
  scan.vertex_count = static_cast<std::size_t>(counts[0]);
  scan.face_count = static_cast<std::size_t>(counts[1]);

  std::string& clean = scan.clean;
  clean = "OFF\n" + std::to_string(scan.vertex_count) + " " + std::to_string(scan.face_count) + " 0\n";
  auto at_line = [&] { return "line " + std::to_string(lines.line_number()) + ": "; };
  for (std::size_t v = 0; v < scan.vertex_count; ++v) {
    if (!lines.next(line))
      fail(path, "truncated: file ends in vertex " + std::to_string(v) + " of " + std::to_string(scan.vertex_count));
    const std::string where = at_line() + "vertex " + std::to_string(v);
    std::size_t q = 0;
    double x[3];
    read_numbers(path, line, q, 3, where, "coordinate", x);
    scan.positions.emplace_back(x[0], x[1], x[2]);
    clean.append(line.substr(0, q)).push_back('\n');
    if (has_normals) {
      float n[3];
      read_numbers(path, line, q, 3, where, "normal", n);
      scan.normals.emplace_back(n[0], n[1], n[2]);
    }
    if (has_texcoords) {
      // x y z [normal] [colour] s t: after a colour (1 to 4 values) the texture coordinate is last.
      if (has_colours) {
        std::vector<std::size_t> token_ends;
        for (std::size_t r = q; !next_token(line, r).empty();) token_ends.push_back(r);
        if (token_ends.size() > 2) q = token_ends[token_ends.size() - 3];
      }
      float t[2];
      read_numbers(path, line, q, 2, where, "texture coordinate", t);
      scan.uvs.emplace_back(t[0], t[1]);
    }
  }
  for (std::size_t f = 0; f < scan.face_count; ++f) {
    if (!lines.next(line))
      fail(path, "truncated: file ends in face " + std::to_string(f) + " of " + std::to_string(scan.face_count));
    const std::string face = "face " + std::to_string(f);
    std::size_t q = 0;
    std::string_view token = next_token(line, q);
    long long corners = 0;
    if (!parse_int(token, corners)) fail(path, at_line() + face + " has a malformed corner count " + quote(token));
    if (corners < 3) fail(path, at_line() + face + " has only " + std::to_string(corners) + " corners");
    for (long long c = 0; c < corners; ++c) {
      token = next_token(line, q);
      long long index = 0;
      if (token.empty()) fail(path, at_line() + face + " lists fewer than its " + std::to_string(corners) + " corners");
      if (!parse_int(token, index)) fail(path, at_line() + face + " has a malformed vertex index " + quote(token));
      if (index < 0 || index >= counts[0])
        fail(path, at_line() + face + " refers to vertex " + std::to_string(index) + " but the file has " +
                       std::to_string(scan.vertex_count));
    }
    clean.append(line.substr(0, q)).push_back('\n');  // a face colour, or anything after the indices, is dropped
  }
  return scan;
}

// STL pre-scan --------------------------------------------------------------------------------------

std::uint32_t binary_stl_count(std::string_view bytes) {
  std::uint32_t count = 0;
  std::memcpy(&count, bytes.data() + 80, 4);  // little-endian, as is every platform we build for
  return count;
}

void check_binary_stl(const std::string& path, std::string_view bytes) {
  const std::uint32_t count = binary_stl_count(bytes);
  for (std::uint32_t f = 0; f < count; ++f) {
    float values[9];
    std::memcpy(values, bytes.data() + 84 + 50 * std::size_t(f) + 12, sizeof values);  // skip the facet normal
    for (float v : values)
      if (!std::isfinite(v)) fail(path, "facet " + std::to_string(f) + " has a non-finite coordinate");
  }
}

// Returns the number of facets.
std::size_t check_ascii_stl(const std::string& path, std::string_view text) {
  LineCursor lines(text);
  std::string_view line;
  std::size_t facets = 0, vertices = 0;
  bool in_facet = false;
  while (lines.next(line)) {
    std::size_t p = 0;
    std::string_view keyword = next_token(line, p);
    auto facet_fail = [&](const std::string& problem) {
      fail(path, "line " + std::to_string(lines.line_number()) + ": facet " + std::to_string(facets) + " " + problem);
    };
    if (keyword == "facet") {
      in_facet = true;
      vertices = 0;
    } else if (keyword == "vertex") {
      if (!in_facet) facet_fail("has a vertex outside 'facet ... endfacet'");
      for (int axis = 0; axis < 3; ++axis) {
        std::string_view token = next_token(line, p);
        float value = 0;
        if (!parse_real(token, value)) facet_fail("has a malformed vertex coordinate " + quote(token));
        if (!std::isfinite(value)) facet_fail("has a non-finite coordinate");
      }
      ++vertices;
    } else if (keyword == "endfacet") {
      if (vertices != 3) facet_fail("has " + std::to_string(vertices) + " vertices; STL facets are triangles");
      in_facet = false;
      ++facets;
    }
  }
  if (in_facet) fail(path, "truncated: file ends in facet " + std::to_string(facets));
  return facets;
}

}  // namespace

bool is_binary_stl(std::string_view bytes) {
  return bytes.size() >= 84 && bytes.size() == 84 + 50 * std::uint64_t(binary_stl_count(bytes));
}

ParsedMesh parse_off(const std::string& path, std::string_view text) {
  ParsedMesh out;
  out.format = "off";
  const OffScan scan = check_off(path, text);
  if (scan.face_count == 0) return out;  // load_mesh reports "no faces"
  std::istringstream stream(scan.clean);
  read_with_openmesh(path, out, [&](FlatImporter& importer) {
    OpenMesh::IO::Options options;
    return OpenMesh::IO::OFFReader().read(stream, importer, options);
  });
  if (out.mesh.positions.size() != scan.vertex_count || out.file_faces != scan.face_count)
    fail(path, "OpenMesh read " + std::to_string(out.mesh.positions.size()) + " of " + std::to_string(scan.vertex_count) +
                   " vertices and " + std::to_string(out.file_faces) + " of " + std::to_string(scan.face_count) + " faces");
  out.exact_positions = scan.positions;
  // Every corner indexes its normal and UV by its vertex (FlatImporter::add_face).
  if (!scan.normals.empty()) {
    out.mesh.normals = scan.normals;
    out.faces_with_normals = out.faces;
  }
  if (!scan.uvs.empty()) {
    out.mesh.uvs = scan.uvs;
    out.faces_with_uvs = out.faces;
    out.first_face_without_uvs.clear();
  }
  return out;
}

ParsedMesh parse_stl(const std::string& path, std::string_view bytes) {
  ParsedMesh out;
  out.format = "stl";
  std::size_t facets = 0;
  OpenMesh::IO::Options options;
  if (is_binary_stl(bytes)) {
    check_binary_stl(path, bytes);
    facets = binary_stl_count(bytes);
    options += OpenMesh::IO::Options::Binary;
  } else {
    std::size_t p = 0;
    if (next_token(bytes, p) != "solid") {
      if (bytes.size() < 84) fail(path, "truncated: too short for a binary STL header and not ASCII STL");
      fail(path, "truncated: binary STL header says " + std::to_string(binary_stl_count(bytes)) + " facets (" +
                     std::to_string(84 + 50 * std::uint64_t(binary_stl_count(bytes))) + " bytes) but the file has " +
                     std::to_string(bytes.size()) + " bytes");
    }
    facets = check_ascii_stl(path, bytes);
  }
  if (facets == 0) return out;  // load_mesh reports "no faces"
  std::istringstream stream{std::string(bytes)};
  read_with_openmesh(path, out,
                     [&](FlatImporter& importer) { return OpenMesh::IO::STLReader().read(stream, importer, options); });
  // OpenMesh welds coincident vertices and drops facets left with a repeated corner.
  if (out.file_faces > facets)
    fail(path, "OpenMesh read " + std::to_string(out.file_faces) + " facets but the file has " + std::to_string(facets));
  out.degenerate_faces_dropped = facets - out.file_faces;
  out.file_faces = facets;
  return out;
}

}  // namespace nmbake::mesh_io_detail
