// The asset formats artists export (glTF 2.0, FBX, DAE, 3DS and whatever else Assimp reads),
// through Assimp. The only code that includes Assimp.
//
// Every mesh of every node is placed by the node's transform (its own times its parents'), in
// double; a mirroring transform (negative determinant) has its triangles' corners reversed so that
// they stay counter-clockwise from the front. FBX files are brought to metres by their
// UnitScaleFactor (centimetres: 0.01), as glTF is by definition and Assimp's COLLADA reader does
// from the file's <unit>; MeshLoadInfo::unit_scale says what was applied. Positions equal after
// placing are welded (Assimp splits a vertex at every seam and hard edge), normals and UVs stay
// per corner, so hard edges and seams are kept as in an OBJ file. Points and lines are left out.
// Each node with meshes is an object named after the node (Mesh::objects); a node name met twice
// is one object. Each mesh's material is named by its AI_MATKEY_NAME (Mesh::materials; meshes of one
// name share it): Assimp's stand-ins for a mesh without one (named "DefaultMaterial"; for glTF an
// unnamed one after the file's own) are "", any other material without a name is "material N" (N
// its number in the file). Vertex colours are the meshes' first
// colour set (glTF COLOR_0), per corner like normals, kept when every mesh has them.
#include <assimp/DefaultIOSystem.h>
#include <assimp/DefaultLogger.hpp>
#include <assimp/Importer.hpp>
#include <assimp/LogStream.hpp>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/memory_budget.h"
#include "io/mesh_io_assimp_guard.h"
#include "io/mesh_io_detail.h"

namespace nmbake::mesh_io_detail {
namespace {

struct PositionHash {
  std::size_t operator()(const glm::dvec3& p) const {
    std::uint64_t h = 1469598103934665603ull;
    for (int k = 0; k < 3; ++k) {
      std::uint64_t bits = 0;
      const double v = p[k] == 0.0 ? 0.0 : p[k];  // -0 and +0 weld
      std::memcpy(&bits, &v, sizeof bits);
      h = (h ^ bits) * 1099511628211ull;
    }
    return std::size_t(h ^ (h >> 29));
  }
};

glm::dmat4 to_glm(const aiMatrix4x4& m) {
  // aiMatrix4x4 is row-major (a1..a4 the first row), glm column-major.
  return glm::dmat4(m.a1, m.b1, m.c1, m.d1, m.a2, m.b2, m.c2, m.d2, m.a3, m.b3, m.c3, m.d3, m.a4, m.b4, m.c4, m.d4);
}

// The scale that brings the scene to metres, where the file says its unit.
double unit_scale_to_metres(const aiScene& scene, const std::string& ext) {
  if (ext != "fbx" || !scene.mMetaData) return 1.0;
  double centimetres_per_unit = 0.0;
  float f = 0.0f;
  if (scene.mMetaData->Get("UnitScaleFactor", centimetres_per_unit) && centimetres_per_unit > 0.0)
    return centimetres_per_unit / 100.0;
  if (scene.mMetaData->Get("UnitScaleFactor", f) && f > 0.0f) return double(f) / 100.0;
  return 1.0;
}

class SceneReader {
 public:
  SceneReader(const std::string& path, const aiScene& scene, double scale, unsigned uv_set, bool gltf)
      : path_(path), scene_(scene), scale_(scale), uv_set_(uv_set), gltf_(gltf) {
    out_.unit_scale = scale;
    // Which attributes every mesh with faces has decides whether corners get UV or normal slots.
    bool any = false;
    std::size_t meshes = 0, colored = 0, uncolored_vertices = 0;
    for (unsigned i = 0; i < scene.mNumMeshes; ++i) {
      const aiMesh& m = *scene.mMeshes[i];
      if (!(m.mPrimitiveTypes & (aiPrimitiveType_TRIANGLE | aiPrimitiveType_POLYGON))) continue;
      any = true;
      out_.corner_uvs = out_.corner_uvs && m.HasTextureCoords(uv_set_);
      out_.corner_normals = out_.corner_normals && m.HasNormals();
      colored += m.HasVertexColors(0) ? 1 : 0;
      if (!m.HasVertexColors(0)) uncolored_vertices += m.mNumVertices;
      ++meshes;
    }
    if (!any) out_.corner_uvs = out_.corner_normals = false;
    out_.corner_colors = any && colored == meshes;
    // Some meshes with colours, some without: load_mesh drops them all and reports it.
    if (colored > 0 && colored < meshes) out_.vertices_without_colors = uncolored_vertices;
  }

  ParsedMesh read() {
    // Depth first without recursion: Assimp checks nothing of the tree's depth.
    std::vector<std::pair<const aiNode*, glm::dmat4>> stack{{scene_.mRootNode, glm::dmat4(scale_)}};
    while (!stack.empty()) {
      const auto [node, parent] = stack.back();
      stack.pop_back();
      const glm::dmat4 world = parent * to_glm(node->mTransformation);
      visit(*node, world);
      for (unsigned i = node->mNumChildren; i-- > 0;) stack.push_back({node->mChildren[i], world});
    }
    out_.mesh.positions.reserve(out_.exact_positions.size());
    for (const glm::dvec3& p : out_.exact_positions) out_.mesh.positions.emplace_back(p);
    return std::move(out_);
  }

 private:
  void visit(const aiNode& node, const glm::dmat4& world) {
    for (unsigned i = 0; i < node.mNumMeshes; ++i) {
      if (node.mMeshes[i] >= scene_.mNumMeshes) fail(path_, "node " + quote(node.mName.C_Str()) + " names no mesh");
      // A node's meshes (one per material) are one object, named after the node (or its first mesh).
      if (i == 0) {
        const std::string mesh_name = scene_.mMeshes[node.mMeshes[0]]->mName.C_Str();
        start_object(out_, node.mName.length ? std::string(node.mName.C_Str()) : mesh_name);
      }
      add_mesh(*scene_.mMeshes[node.mMeshes[i]], world);
    }
  }

  // The name of mesh `m`'s material (Mesh::materials).
  std::string material_name(const aiMesh& m) const {
    const unsigned k = m.mMaterialIndex;
    aiString name;
    if (k >= scene_.mNumMaterials || !scene_.mMaterials[k] || scene_.mMaterials[k]->Get(AI_MATKEY_NAME, name) != AI_SUCCESS)
      name.Clear();
    const std::string text(name.C_Str(), std::min<std::size_t>(name.length, 256));
    // Assimp's glTF reader adds an unnamed material after the file's own for primitives without one.
    if (text == AI_DEFAULT_MATERIAL_NAME || (text.empty() && gltf_ && k + 1 == scene_.mNumMaterials)) return "";
    return text.empty() ? "material " + std::to_string(k) : text;
  }

  void add_mesh(const aiMesh& m, const glm::dmat4& world) {
    if (!(m.mPrimitiveTypes & (aiPrimitiveType_TRIANGLE | aiPrimitiveType_POLYGON))) return;
    const std::string name = "mesh " + quote(m.mName.C_Str());
    start_material(out_, material_name(m));
    const glm::dmat3 normal_matrix = glm::transpose(glm::inverse(glm::dmat3(world)));
    const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
    std::vector<std::uint32_t> position(m.mNumVertices);
    const std::uint32_t normal_base = std::uint32_t(out_.mesh.normals.size());
    const std::uint32_t uv_base = std::uint32_t(out_.mesh.uvs.size());
    const std::uint32_t color_base = std::uint32_t(out_.mesh.colors.size());
    for (unsigned v = 0; v < m.mNumVertices; ++v) {
      const aiVector3D& a = m.mVertices[v];
      const glm::dvec3 p = glm::dvec3(world * glm::dvec4(a.x, a.y, a.z, 1.0));
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(path_, name + ": vertex " + std::to_string(v) + " has a non-finite coordinate");
      auto [it, added] = weld_.try_emplace(p, std::uint32_t(out_.exact_positions.size()));
      if (added) out_.exact_positions.push_back(p);
      position[v] = it->second;
      if (out_.corner_normals) {
        const aiVector3D& n = m.mNormals[v];
        glm::dvec3 w = normal_matrix * glm::dvec3(n.x, n.y, n.z);
        const double length = glm::length(w);
        // A singular transform (a node scaled by 0, as glTF hides nodes) leaves no direction: a
        // zero normal, which load_mesh replaces by computed ones.
        w = length > 0.0 && std::isfinite(length) ? w / length : glm::dvec3(0.0);
        out_.mesh.normals.emplace_back(w);
      }
      if (out_.corner_uvs) {
        const aiVector3D& t = m.mTextureCoords[uv_set_][v];
        if (!std::isfinite(t.x) || !std::isfinite(t.y))
          fail(path_, name + ": vertex " + std::to_string(v) + " has a non-finite texture coordinate");
        out_.mesh.uvs.emplace_back(t.x, t.y);
      }
      if (out_.corner_colors) {
        const aiColor4D& c = m.mColors[0][v];
        if (!std::isfinite(c.r) || !std::isfinite(c.g) || !std::isfinite(c.b) || !std::isfinite(c.a))
          fail(path_, name + ": vertex " + std::to_string(v) + " has a non-finite colour");
        out_.mesh.colors.emplace_back(unit_color(c.r), unit_color(c.g), unit_color(c.b), unit_color(c.a));
      }
    }
    std::vector<Corner> corners;
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
      const aiFace& face = m.mFaces[f];
      ++out_.file_faces;
      if (face.mNumIndices < 3) continue;  // a point or a line
      corners.clear();
      for (unsigned c = 0; c < face.mNumIndices; ++c) {
        const unsigned k = face.mIndices[c];
        if (k >= m.mNumVertices)
          fail(path_, name + ": face " + std::to_string(f) + " uses vertex " + std::to_string(k) + " of " +
                          std::to_string(m.mNumVertices));
        corners.push_back({position[k], uv_base + k, normal_base + k, color_base + k});
      }
      if (mirrored) std::reverse(corners.begin() + 1, corners.end());
      add_polygon(out_, corners.data(), corners.size(), std::uint32_t(out_.file_faces - 1));
      if (out_.corner_uvs) ++out_.faces_with_uvs;
      if (out_.corner_normals) ++out_.faces_with_normals;
      if (!out_.corner_uvs && out_.first_face_without_uvs.empty())
        out_.first_face_without_uvs =
            name + " face " + std::to_string(f) + (uv_set_ ? " (UV set " + std::to_string(uv_set_) + ")" : "");
    }
  }

  const std::string& path_;
  const aiScene& scene_;
  const double scale_;
  const unsigned uv_set_;
  const bool gltf_;
  ParsedMesh out_;
  std::unordered_map<glm::dvec3, std::uint32_t, PositionHash> weld_;
};

// Assimp's warnings while a file is read. Some tell of data it dropped and read on without (faces
// with indices out of range, the vertices of an incomplete triangle): such a file is refused, not
// baked with holes. One logger for the process (Assimp's is global), collecting while a read runs.
class DroppedDataLog : public Assimp::LogStream {
 public:
  static DroppedDataLog& instance() {
    static DroppedDataLog* log = [] {
      auto* l = new DroppedDataLog;  // owned by Assimp's logger from here on
      Assimp::DefaultLogger::create("", Assimp::Logger::NORMAL, 0);
      Assimp::DefaultLogger::get()->attachStream(l, Assimp::Logger::Warn | Assimp::Logger::Err);
      return l;
    }();
    return *log;
  }
  void write(const char* message) override {
    const std::string m = message;
    if (first_.empty() && (m.find("out-of-range indices") != std::string::npos ||
                           m.find("not compatible with the TRIANGLES mode") != std::string::npos)) {
      const std::size_t colon = m.find(": ");  // after "Warn,  T0"
      first_ = colon == std::string::npos ? m : m.substr(colon + 2);
      while (!first_.empty() && (first_.back() == '\n' || first_.back() == '\r')) first_.pop_back();
    }
  }
  // Runs `read` alone and returns what it dropped ("" for nothing).
  template <typename Read>
  std::string collect(Read&& read) {
    const std::lock_guard<std::mutex> lock(mutex_);
    first_.clear();
    read();
    return first_;
  }

 private:
  std::mutex mutex_;
  std::string first_;
};

// Whether the bytes can be a file of this extension: Assimp tries every reader on a file its own
// refuses, and one of them (PLY) loops for ever on some inputs named .gltf.
bool signature_fits(const std::string& ext, std::string_view bytes) {
  const std::string_view head = bytes.substr(0, 65536);
  std::size_t first = 0;
  if (head.substr(0, 3) == "\xEF\xBB\xBF") first = 3;
  while (first < head.size() && std::isspace(static_cast<unsigned char>(head[first]))) ++first;
  const char lead = first < head.size() ? head[first] : '\0';
  if (ext == "glb") return head.substr(0, 4) == "glTF";
  if (ext == "gltf") return lead == '{';
  if (ext == "fbx")
    return head.substr(0, 18) == "Kaydara FBX Binary" || lead == ';' || head.find("FBXHeaderExtension") != std::string_view::npos;
  if (ext == "dae") return head.find("COLLADA") != std::string_view::npos;
  return true;
}

// A COLLADA array (<p>, <vcount>, <float_array>, ...) holding bytes that are not text: Assimp's
// reader takes them for numbers and can allocate without bound (tests/fuzz found it).
// Returns the problem, or "" when every array holds printable ASCII and white space (exporters
// write commas and such, which Assimp reads).
std::string collada_array_problem(std::string_view bytes) {
  for (const char* tag : {"p", "vcount", "v", "h", "float_array", "int_array", "bool_array"}) {
    const std::string open = std::string("<") + tag, close = std::string("</") + tag + ">";
    for (std::size_t at = bytes.find(open); at != std::string_view::npos; at = bytes.find(open, at + 1)) {
      const std::size_t after = at + open.size();
      if (after >= bytes.size() || !(bytes[after] == '>' || std::isspace(static_cast<unsigned char>(bytes[after])))) continue;
      const std::size_t start = bytes.find('>', after);
      if (start == std::string_view::npos || bytes[start - 1] == '/') continue;
      const std::size_t end = bytes.find(close, start);
      for (std::size_t i = start + 1; i < (end == std::string_view::npos ? bytes.size() : end); ++i) {
        const unsigned char c = static_cast<unsigned char>(bytes[i]);
        if ((c >= 0x20 && c < 0x7f) || std::isspace(c)) continue;
        return "<" + std::string(tag) + "> holds a byte that is not text (0x" + "0123456789abcdef"[c >> 4] +
               "0123456789abcdef"[c & 15] + " at byte " + std::to_string(i) + ")";
      }
    }
  }
  return "";
}

// What the guards (mesh_io_assimp_guard.h) find in the bytes before Assimp reads them, or "".
// `json` receives a glTF's JSON: a .glb's JSON chunk, else the bytes.
std::string shape_problem(const std::string& ext, std::string_view bytes, std::string_view& json) {
  json = bytes;
  if (ext == "glb")
    if (std::string problem = glb_problem(bytes, json); !problem.empty()) return problem;
  if (ext == "glb" || ext == "gltf") {
    std::string problem = nesting_problem(json, true);
    return problem.empty() ? gltf_nodes_problem(json) : problem;
  }
  std::string problem = ext == "dae" ? collada_array_problem(bytes) : ext == "fbx" ? fbx_problem(bytes) : "";
  if (problem.empty()) problem = nesting_problem(bytes, false);
  return problem.empty() && ext == "dae" ? collada_nodes_problem(bytes) : problem;
}

// Assimp's file access, refusing what is not a regular file: a FIFO named as a glTF's buffer
// blocked the read for ever. Exists() does not open (Assimp's own fopen()s, which blocks on a
// FIFO); Open() looks at the file without blocking first.
class RegularFiles : public Assimp::DefaultIOSystem {
 public:
  bool Exists(const char* file) const override {
    struct stat st;
    return ::stat(file, &st) == 0;
  }
  Assimp::IOStream* Open(const char* file, const char* mode) override {
    const int fd = ::open(file, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st;
    const bool regular = fd >= 0 && ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
    if (fd >= 0) ::close(fd);
    if (fd >= 0 && !regular) {
      if (refused.empty()) refused = file;
      return nullptr;
    }
    return DefaultIOSystem::Open(file, mode);
  }
  std::string refused;  // the first file refused
};

}  // namespace

bool assimp_reads(const std::string& ext) {
  static const Assimp::Importer importer;
  return !ext.empty() && importer.IsExtensionSupported("." + ext);
}

ParsedMesh parse_assimp(const std::string& path, const std::string& ext, std::string_view bytes, bool read_path,
                        unsigned uv_set) {
  if (!signature_fits(ext, bytes)) fail(path, "is not a ." + ext + " file (its first bytes say otherwise)");
  std::string_view json;
  if (const std::string problem = shape_problem(ext, bytes, json); !problem.empty()) fail(path, "malformed: " + problem);
  if (ext == "gltf" || ext == "glb")
    if (const std::string problem = gltf_accessor_problem(json, memory_budget_bytes()); !problem.empty())
      throw ResourceError(path + ": " + problem);
  ParsedMesh parsed;
  // Assimp recurses over the file and its node tree; the importer (which frees the tree, again
  // recursively) lives and dies on the big stack.
  run_on_big_stack(reader_stack_bytes(bytes.size()), [&] {
    Assimp::Importer importer;
    auto* files = new RegularFiles;  // owned by the importer
    importer.SetIOHandler(files);
    // Points and lines are dropped by the reader; the scene is checked for indices out of range.
    importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    const unsigned flags = aiProcess_ValidateDataStructure | aiProcess_SortByPType;
    // A file beside others (a .gltf and its .bin) is read by name; bytes alone for the fuzz target.
    const aiScene* scene = nullptr;
    const std::string dropped = DroppedDataLog::instance().collect([&] {
      scene = read_path ? importer.ReadFile(path, flags)
                        : importer.ReadFileFromMemory(bytes.data(), bytes.size(), flags, ext.c_str());
    });
    if (!files->refused.empty())
      fail(path, "refers to " + files->refused + ", which is not a regular file (a FIFO, a device or a folder)");
    if (scene && !dropped.empty()) fail(path, "malformed: " + one_line(dropped, kAssimpMessageMax));
    if (!scene || !scene->mRootNode) {
      const std::string why = one_line(importer.GetErrorString(), kAssimpMessageMax);
      fail(path, "cannot read as ." + ext + (why.empty() ? std::string() : ": " + why));
    }
    parsed = SceneReader(path, *scene, unit_scale_to_metres(*scene, ext), uv_set, ext == "gltf" || ext == "glb").read();
  });
  parsed.format = ext == "glb" || ext == "gltf" ? "gltf" : ext;
  return parsed;
}

}  // namespace nmbake::mesh_io_detail
