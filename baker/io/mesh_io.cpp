// load_mesh(): reads the file once into memory, hands it to the reader for its extension, then
// applies the checks and repairs every format shares. The readers live in mesh_io_obj.cpp,
// mesh_io_ply.cpp, mesh_io_off.cpp, mesh_io_stl.cpp and mesh_io_assimp.cpp (glTF, FBX, DAE, 3DS...).
#include "io/mesh_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <new>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/bounds.h"
#include "core/errors.h"
#include "core/image.h"
#include "core/parallel.h"
#include "io/mesh_io_detail.h"

namespace nmbake {
namespace {

using mesh_io_detail::fail;
using mesh_io_detail::ParsedMesh;

// A normal shorter than this carries no direction; a file normal off unit length by more than
// kUnitTolerance is counted as renormalized (6-digit exports are never exactly unit, which is fine).
constexpr float kZeroNormalLength = 1e-6f;
constexpr float kUnitTolerance = 1e-3f;

std::string lower_extension(const std::string& path) {
  std::size_t slash = path.find_last_of('/');
  std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::string cannot_open(int error) { return std::string("cannot open: ") + std::strerror(error); }

// Non-regular files are refused so a FIFO or a device cannot block or flood us.
void check_regular_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) fail(path, cannot_open(errno));
  if (S_ISDIR(st.st_mode)) fail(path, "is a directory");
  if (!S_ISREG(st.st_mode)) fail(path, "is not a regular file");
}

// The whole file, read into memory left unset (a std::string would be zeroed first: a third pass
// over the file). Not mapped: the C library sizes its later allocations by the largest block
// freed so far, and a mapping freed after loading raised the bake's peak memory.
class FileBytes {
 public:
  explicit FileBytes(const std::string& path) {
    int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) fail(path, cannot_open(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
      int error = errno;
      ::close(fd);
      fail(path, cannot_open(error));
    }
    const std::size_t size = static_cast<std::size_t>(st.st_size);
    try {
      bytes_.reset(new char[std::max<std::size_t>(size, 1)]);
    } catch (const std::bad_alloc&) {
      ::close(fd);
      throw ResourceError(path + ": out of memory reading " + std::to_string(size) + " bytes");
    }
    // A large file in one part per core (pread), each thread faulting in its own part of the buffer;
    // a part cut short (the file shrank meanwhile) sends the whole file to the one read below.
    int parts = size >= kPartsFrom ? worker_threads(0) : 1;
    if (parts > 1) {
      std::atomic<int> error{0};
      std::atomic<bool> short_part{false};
      run_on_threads(parts, [&](int k) {
        std::size_t at = size * std::size_t(k) / std::size_t(parts);
        const std::size_t end = size * std::size_t(k + 1) / std::size_t(parts);
        while (at < end && !error && !short_part) {
          const ssize_t n = ::pread(fd, bytes_.get() + at, end - at, off_t(at));
          if (n < 0 && errno == EINTR) continue;
          if (n < 0) error = errno;
          else if (n == 0) short_part = true;
          else at += std::size_t(n);
        }
      });
      if (error) read_failed(path, fd, error);
      if (!short_part) size_ = size;
      else parts = 1;
    }
    while (parts == 1 && size_ < size) {
      ssize_t n = ::pread(fd, bytes_.get() + size_, size - size_, off_t(size_));
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) read_failed(path, fd, errno);
      if (n == 0) break;  // the file shrank while we read it
      size_ += static_cast<std::size_t>(n);
    }
    ::close(fd);
  }

  std::string_view view() const { return {bytes_.get(), size_}; }

 private:
  static constexpr std::size_t kPartsFrom = std::size_t(8) << 20;  // bytes

  [[noreturn]] static void read_failed(const std::string& path, int fd, int error) {
    ::close(fd);
    fail(path, std::string("cannot read: ") + std::strerror(error));
  }

  std::unique_ptr<char[]> bytes_;
  std::size_t size_ = 0;
};

bool is_whitespace_only(std::string_view bytes) {
  for (char c : bytes)
    if (!mesh_io_detail::is_space(c)) return false;
  return true;
}

// A byte-order mark, or ASCII characters interleaved with zero bytes.
bool looks_like_utf16(std::string_view b) {
  auto byte = [&](std::size_t i) { return static_cast<unsigned char>(b[i]); };
  if (b.size() >= 2 && ((byte(0) == 0xFE && byte(1) == 0xFF) || (byte(0) == 0xFF && byte(1) == 0xFE))) return true;
  if (b.size() < 4) return false;
  bool big_endian = byte(0) == 0 && byte(1) != 0 && byte(2) == 0 && byte(3) != 0;
  bool little_endian = byte(0) != 0 && byte(1) == 0 && byte(2) != 0 && byte(3) == 0;
  return big_endian || little_endian;
}

std::string_view skip_utf8_bom(std::string_view text) {
  if (text.size() >= 3 && text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  return text;
}

// Formats with a reader of our own; any other extension Assimp reads goes to Assimp.
bool own_format(const std::string& ext) { return ext == "obj" || ext == "ply" || ext == "off" || ext == "stl"; }

ParsedMesh parse_by_extension(const std::string& path, const std::string& ext, std::string_view bytes, bool read_path,
                              unsigned uv_set) {
  if (!own_format(ext)) return mesh_io_detail::parse_assimp(path, ext, bytes, read_path, uv_set);
  if (uv_set > 0)
    fail(path, "." + ext + " files have one UV set; UV set " + std::to_string(uv_set) +
                   " needs a format with several (glTF, FBX, DAE)");
  if (ext == "obj") return mesh_io_detail::parse_obj(path, skip_utf8_bom(bytes));
  if (ext == "ply") return mesh_io_detail::parse_ply(path, bytes);
  if (ext == "off") return mesh_io_detail::parse_off(path, skip_utf8_bom(bytes));
  return mesh_io_detail::parse_stl(path, bytes);
}

// The objects as the bake reads them (Mesh::objects): every one named (the unnamed first one after
// the file), each with triangles, and triangle_object only when there are two or more.
void settle_objects(ParsedMesh& parsed, const std::string& path) {
  Mesh& m = parsed.mesh;
  std::string stem = path.substr(path.find_last_of('/') + 1);
  if (const auto dot = stem.find_last_of('.'); dot != std::string::npos && dot > 0) stem.resize(dot);
  if (m.objects.empty()) m.objects.push_back({});
  std::vector<std::size_t> triangles(m.objects.size(), 0);
  if (m.triangle_object.empty()) triangles[0] = m.triangle_count();
  for (std::uint32_t k : m.triangle_object) ++triangles[k];
  std::vector<std::uint32_t> renumber(m.objects.size(), 0);
  std::vector<Mesh::Object> kept;
  for (std::size_t k = 0; k < m.objects.size(); ++k) {
    if (triangles[k] == 0) continue;
    renumber[k] = std::uint32_t(kept.size());
    kept.push_back({m.objects[k].name.empty() ? stem : m.objects[k].name, path});
  }
  m.objects = std::move(kept);
  if (m.objects.size() == 1) m.triangle_object.clear();
  for (std::uint32_t& k : m.triangle_object) k = renumber[k];
}

// The materials as the bake reads them (Mesh::materials): only those some triangle has, in the
// order of first use, none when no triangle has a named one, and triangle_material only when two or
// more are left.
void settle_materials(ParsedMesh& parsed) {
  Mesh& m = parsed.mesh;
  if (m.materials.empty()) return;
  constexpr std::uint32_t kUnused = UINT32_MAX;
  std::vector<std::uint32_t> renumber(m.materials.size(), kUnused);
  std::vector<std::string> kept;
  auto use = [&](std::uint32_t k) {
    if (renumber[k] != kUnused) return;
    renumber[k] = std::uint32_t(kept.size());
    kept.push_back(m.materials[k]);
  };
  if (m.triangle_material.empty()) use(0);
  for (std::uint32_t k : m.triangle_material) use(k);
  m.materials = std::move(kept);
  if (m.materials.size() == 1 && m.materials[0].empty()) m.materials.clear();
  if (m.materials.size() <= 1) m.triangle_material.clear();
  for (std::uint32_t& k : m.triangle_material) k = renumber[k];
}

// Keeps colours only when every vertex has them; colours per position get their corners' indices.
void settle_colors(ParsedMesh& parsed, MeshLoadInfo& info) {
  Mesh& m = parsed.mesh;
  if (parsed.vertices_without_colors > 0) {
    info.colors_dropped = true;
    info.vertices_without_colors = parsed.vertices_without_colors;
    m.colors.clear();
  }
  if (m.colors.empty()) {
    m.colors.shrink_to_fit();
    m.color_index.clear();
    m.color_index.shrink_to_fit();
  } else if (!parsed.corner_colors) {
    m.color_index = m.position_index;
  }
}

// Keeps UVs only when every face has them.
void settle_uvs(ParsedMesh& parsed, const std::string& path, const LoadOptions& options, MeshLoadInfo& info) {
  Mesh& m = parsed.mesh;
  if (parsed.faces_with_uvs == parsed.faces) return;
  if (options.require_uvs) fail(path, parsed.first_face_without_uvs + " has no UVs");
  if (parsed.faces_with_uvs > 0) {
    info.uvs_dropped = true;
    info.faces_without_uvs = parsed.faces - parsed.faces_with_uvs;
  }
  m.uv_index.clear();
  m.uvs.clear();
}

// Keeps normals only when every face has them and none is ~zero; makes the kept ones unit length.
void settle_normals(ParsedMesh& parsed, MeshLoadInfo& info) {
  Mesh& m = parsed.mesh;
  bool keep = parsed.faces_with_normals == parsed.faces;
  if (!keep && parsed.faces_with_normals > 0) {
    info.normals_dropped = true;
    info.faces_without_normals = parsed.faces - parsed.faces_with_normals;
  }
  if (keep) {
    // Only normals some corner uses count: an unused zero normal in an OBJ harms nobody. Marked on
    // every core.
    std::vector<std::uint8_t, DefaultInitAllocator<std::uint8_t>> used(m.normals.size());
    mark_on_threads(0, m.normal_index, used);
    // On every core, each chunk's counts summed after.
    std::atomic<std::size_t> zero{0}, renormalized{0};
    parallel_chunks(0, m.normals.size(), std::size_t(1) << 16, [&](std::size_t begin, std::size_t end) {
      std::size_t z = 0, r = 0;
      for (std::size_t i = begin; i < end; ++i) {
        if (!used[i]) continue;
        // In double: the squared length of a float normal with components near 1e20 or more
        // overflows float, and dividing by an infinite length would give a zero normal.
        const glm::dvec3 n(m.normals[i]);
        const double length = glm::length(n);
        if (!(length >= kZeroNormalLength)) {  // NaN too
          ++z;
          continue;
        }
        if (std::fabs(length - 1.0) > kUnitTolerance) ++r;
        m.normals[i] = glm::vec3(n / length);
      }
      zero += z;
      renormalized += r;
    });
    info.zero_normals += zero;
    info.normals_renormalized += renormalized;
    if (info.zero_normals > 0) {
      keep = false;
      info.normals_dropped = true;
      info.normals_renormalized = 0;
    }
  }
  if (!keep) {
    m.normal_index.clear();
    m.normals.clear();
  }
}

// The step between neighbouring values of type Real at magnitude x.
template <typename Real>
double step_at(double x) {
  const Real r = static_cast<Real>(std::fabs(x));
  return double(std::nextafter(r, std::numeric_limits<Real>::infinity())) - double(r);
}

// Refuses positions whose values are too coarse for the mesh's size (kPrecisionLimit), then moves
// the mesh to its origin (LoadOptions::origin): positions = file's coordinates - origin, in double.
void place(ParsedMesh& parsed, const std::string& path, const LoadOptions& options, MeshLoadInfo& info) {
  Mesh& m = parsed.mesh;
  std::vector<glm::dvec3>& exact = parsed.exact_positions;
  if (exact.size() != m.positions.size()) exact.assign(m.positions.begin(), m.positions.end());  // STL: float
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  grow_box(lo, hi, exact, m.position_index);
  double largest = 0.0;
  for (int k = 0; k < 3; ++k) largest = std::max({largest, std::fabs(lo[k]), std::fabs(hi[k])});
  const double diagonal = glm::length(hi - lo);
  info.largest_coordinate = largest;
  // The values' steps: float's at the largest coordinate when (nearly) every coordinate is a float
  // value, as when a far mesh was saved from float, else double's.
  double step = step_at<double>(largest);
  if (step_at<float>(largest) > kPrecisionLimit * diagonal) {
    std::size_t float_values = 0;
    for (const glm::dvec3& p : exact)
      for (int k = 0; k < 3; ++k) float_values += double(static_cast<float>(p[k])) == p[k];
    if (double(float_values) >= 0.9 * 3.0 * double(exact.size())) step = step_at<float>(largest);
  }
  // Only a far mesh is judged: a mesh collapsed to a point at the origin is degenerate, not imprecise.
  const bool far = largest > kFarFactor * diagonal;
  if (far && step > kPrecisionLimit * diagonal) {
    char problem[400];
    std::snprintf(problem, sizeof problem,
                  "coordinates reach %.3g from the origin, where its values move in steps of %.3g (%s) while the mesh is "
                  "%.3g across: the map would be off by degrees; export it with more digits or move it near the origin",
                  largest, step, step == step_at<double>(largest) ? "beyond double precision" : "saved in float precision",
                  diagonal);
    fail(path, problem);
  }
  const glm::dvec3 origin = options.origin ? *options.origin : far ? (lo + hi) * 0.5 : glm::dvec3(0.0);
  m.origin = origin;
  if (origin != glm::dvec3(0.0))
    for (std::size_t i = 0; i < exact.size(); ++i) m.positions[i] = glm::vec3(exact[i] - origin);
}

Mesh finish_mesh(ParsedMesh parsed, const std::string& path, const LoadOptions& options, MeshLoadInfo& info) {
  if (parsed.faces == 0) fail(path, "no faces");
  info.format = parsed.format;
  info.file_faces = parsed.file_faces;
  info.polygons_triangulated = parsed.polygons_triangulated;
  info.degenerate_faces_dropped = parsed.degenerate_faces_dropped;
  info.unit_scale = parsed.unit_scale;
  settle_uvs(parsed, path, options, info);
  settle_normals(parsed, info);
  settle_objects(parsed, path);
  settle_materials(parsed);
  settle_colors(parsed, info);
  place(parsed, path, options, info);
  parsed.mesh.source = path;
  return std::move(parsed.mesh);
}

void check_extension(const std::string& path) {
  std::string ext = lower_extension(path);
  if (!own_format(ext) && !mesh_io_detail::assimp_reads(ext))
    fail(path, (ext.empty() ? std::string("has no file extension") : "unknown file type '." + ext + "'") +
                   "; supported: .obj .ply .off .stl, and through Assimp .gltf .glb .fbx .dae .3ds and others");
}

// `read_path`: an Assimp format is read by its path (a .gltf finds its .bin beside it).
Mesh parse_bytes(const std::string& path, std::string_view bytes, const LoadOptions& options, MeshLoadInfo& info,
                 bool read_path) {
  const std::string ext = lower_extension(path);
  if (bytes.empty() || is_whitespace_only(bytes)) fail(path, "file is empty");
  // Binary STL is the only binary format of our own readers whose first bytes are arbitrary;
  // Assimp's formats are binary or read UTF-16 themselves (COLLADA).
  if (own_format(ext) && !(ext == "stl" && mesh_io_detail::is_binary_stl(bytes)) && looks_like_utf16(bytes))
    fail(path, "looks like UTF-16 text; save it as UTF-8");
  if (options.uv_set >= kMaxUvSets)
    fail(path,
         "UV set " + std::to_string(options.uv_set) + " asked for; sets are numbered 0 to " + std::to_string(kMaxUvSets - 1));
  return finish_mesh(parse_by_extension(path, ext, bytes, read_path, options.uv_set), path, options, info);
}

}  // namespace

Mesh load_mesh_from_memory(const std::string& name, std::string_view bytes, const LoadOptions& options, MeshLoadInfo* info) {
  MeshLoadInfo local_info;
  MeshLoadInfo& out_info = info ? *info : local_info;
  out_info = MeshLoadInfo{};
  try {
    check_extension(name);
    return parse_bytes(name, bytes, options, out_info, false);
  } catch (const std::bad_alloc&) {
    throw ResourceError(name + ": out of memory while loading");
  } catch (const std::length_error&) {
    throw ResourceError(name + ": out of memory while loading");
  }
}

Mesh load_mesh(const std::string& path, const LoadOptions& options, MeshLoadInfo* info) {
  MeshLoadInfo local_info;
  MeshLoadInfo& out_info = info ? *info : local_info;
  out_info = MeshLoadInfo{};
  try {
    check_regular_file(path);
    check_extension(path);
    const FileBytes bytes(path);
    return parse_bytes(path, bytes.view(), options, out_info, true);
  } catch (const std::bad_alloc&) {
    throw ResourceError(path + ": out of memory while loading");
  } catch (const std::length_error&) {
    throw ResourceError(path + ": out of memory while loading");
  }
}

std::string obj_text(const Mesh& mesh, const std::string& comment) {
  std::string out = "# " + comment + "\n";
  char line[160];
  for (const glm::vec3& p : mesh.positions) {
    if (mesh.origin == glm::dvec3(0.0)) {
      std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", double(p.x), double(p.y), double(p.z));
    } else {
      const glm::dvec3 q = glm::dvec3(p) + mesh.origin;  // back where the file had it, in double
      std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", q.x, q.y, q.z);
    }
    out += line;
  }
  for (const glm::vec2& t : mesh.uvs) {
    std::snprintf(line, sizeof line, "vt %.9g %.9g\n", double(t.x), double(t.y));
    out += line;
  }
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    out += "f";
    for (int c = 0; c < 3; ++c) {
      if (mesh.has_uvs())
        std::snprintf(line, sizeof line, " %u/%u", mesh.position_index[3 * t + c] + 1, mesh.uv_index[3 * t + c] + 1);
      else std::snprintf(line, sizeof line, " %u", mesh.position_index[3 * t + c] + 1);
      out += line;
    }
    out += "\n";
  }
  return out;
}

}  // namespace nmbake
