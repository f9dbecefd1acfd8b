// libFuzzer target over mesh loading and validation: load_mesh_from_memory() on arbitrary bytes,
// then the checks every later stage relies on, then the stages that consume a loaded mesh first
// (smooth normals, tangent frames).
//
// Input: byte 0 picks the reader by the file name it gives ('o' OBJ, 'p' PLY, 'f' OFF, 's' STL,
// through Assimp 'g' glTF JSON, 'b' GLB, 'd' COLLADA, 'x' FBX; any other byte: byte % 8 in that
// order), the rest is the file. From memory a .gltf has no side files: its buffers are data URIs
// (Assimp looks any other URI up relative to the working folder). A refusal must be an InputError or ResourceError of one line
// naming the file; anything else (another exception, a broken invariant, a NaN) aborts, which
// libFuzzer reports as a crash. ASan/UBSan catch memory errors and undefined behaviour.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "core/errors.h"
#include "io/mesh_io.h"
#include "core/normals.h"
#include "core/tangent_frames.h"

namespace {

using namespace nmbake;

[[noreturn]] void broken(const char* what, std::size_t index) {
  std::fprintf(stderr, "fuzz_mesh_load: invariant broken: %s (element %zu)\n", what, index);
  std::abort();
}

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(glm::vec4 v) { return finite(glm::vec3(v)) && std::isfinite(v.w); }
bool finite(glm::vec2 v) { return std::isfinite(v.x) && std::isfinite(v.y); }

// What load_mesh() promises about a mesh it returns (mesh.h, mesh_io.h).
void check_loaded(const Mesh& m) {
  const std::size_t tris = m.triangle_count();
  if (tris == 0) broken("a loaded mesh has no triangles", 0);
  if (m.position_index.size() != 3 * tris) broken("position_index is not 3 per triangle", m.position_index.size());
  if (m.source_face.size() != tris) broken("source_face is not 1 per triangle", m.source_face.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    if (!finite(m.positions[i])) broken("non-finite position", i);
  for (std::size_t i = 0; i < m.position_index.size(); ++i)
    if (m.position_index[i] >= m.positions.size()) broken("position index out of range", i);
  if (m.has_normals()) {
    if (m.normal_index.size() != 3 * tris) broken("normal_index is not 3 per triangle", m.normal_index.size());
    for (std::size_t i = 0; i < m.normal_index.size(); ++i) {
      if (m.normal_index[i] >= m.normals.size()) broken("normal index out of range", i);
      const glm::vec3 n = m.normals[m.normal_index[i]];
      if (!finite(n) || std::fabs(glm::length(n) - 1.0f) > 1e-3f) broken("used normal not finite and unit", i);
    }
  }
  if (m.has_uvs()) {
    if (m.uv_index.size() != 3 * tris) broken("uv_index is not 3 per triangle", m.uv_index.size());
    for (std::size_t i = 0; i < m.uv_index.size(); ++i) {
      if (m.uv_index[i] >= m.uvs.size()) broken("uv index out of range", i);
      if (!finite(m.uvs[m.uv_index[i]])) broken("used UV not finite", i);
    }
  }
  if (m.has_colors()) {
    if (m.color_index.size() != 3 * tris) broken("color_index is not 3 per triangle", m.color_index.size());
    for (std::size_t i = 0; i < m.color_index.size(); ++i) {
      if (m.color_index[i] >= m.colors.size()) broken("color index out of range", i);
      const glm::vec4 c = m.colors[m.color_index[i]];
      if (!(c.r >= 0 && c.r <= 1 && c.g >= 0 && c.g <= 1 && c.b >= 0 && c.b <= 1 && c.a >= 0 && c.a <= 1))
        broken("used colour outside [0, 1]", i);
    }
  }
  if (!m.triangle_material.empty()) {
    if (m.triangle_material.size() != tris) broken("triangle_material is not 1 per triangle", m.triangle_material.size());
    for (std::size_t t = 0; t < tris; ++t)
      if (m.triangle_material[t] >= m.materials.size()) broken("material out of range", t);
  }
}

// The first stages of a bake on the loaded mesh: never NaN (normals.h, tangent_frames.h).
void check_stages(Mesh m) {
  ensure_normals(m);
  if (m.normal_index.size() != m.position_index.size()) broken("ensure_normals left normals unset", 0);
  for (std::size_t i = 0; i < m.normals.size(); ++i)
    if (!finite(m.normals[i])) broken("computed normal not finite", i);
  if (!m.has_uvs()) return;
  const TangentFrames frames = compute_tangent_frames(m);
  if (frames.normal.size() != m.position_index.size() || frames.tangent.size() != m.position_index.size())
    broken("tangent frames are not 1 per corner", frames.normal.size());
  for (std::size_t i = 0; i < frames.normal.size(); ++i)
    if (!finite(frames.normal[i]) || !finite(frames.tangent[i])) broken("tangent frame not finite", i);
}

void check_message(const std::string& message, const std::string& name) {
  if (message.compare(0, name.size() + 2, name + ": ") != 0) broken("error message does not start with the file name", 0);
  if (message.find('\n') != std::string::npos) broken("error message is not one line", message.find('\n'));
}

}  // namespace

// LeakSanitizer (ASan builds): Assimp 5.2 leaks on the error paths of several readers (README,
// open/leak_*); those leaks are its own, and without this a fuzzing run stops at the first one.
extern "C" const char* __lsan_default_suppressions() { return "leak:libassimp.so\n"; }

// NMBAKE_FUZZ_READERS=own: only our own readers (OBJ, PLY, OFF, STL); the Assimp inputs are
// skipped. scripts/fuzz.sh (CI) fuzzes those by default: Assimp 5.2 allocates what a count says
// before checking it (GBs) and has known memory errors of its own (README, open/), which a timed
// run finds within seconds. The corpus replay runs every input, Assimp's included.
bool own_readers_only() {
  static const bool own = [] {
    const char* v = std::getenv("NMBAKE_FUZZ_READERS");
    return v && std::string(v) == "own";
  }();
  return own;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char kLetters[] = "opfsgbdx";
  static const char* const kNames[] = {"fuzz.obj",  "fuzz.ply", "fuzz.off", "fuzz.stl",
                                       "fuzz.gltf", "fuzz.glb", "fuzz.dae", "fuzz.fbx"};
  const char* letter = data[0] ? std::strchr(kLetters, data[0]) : nullptr;
  const std::size_t reader = letter ? std::size_t(letter - kLetters) : data[0] % 8u;
  if (reader >= 4 && own_readers_only()) return 0;
  const std::string name = kNames[reader];
  const std::string_view bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    MeshLoadInfo info;
    Mesh mesh = load_mesh_from_memory(name, bytes, {}, &info);
    if (info.format.empty()) broken("MeshLoadInfo::format not set", 0);
    check_loaded(mesh);
    check_stages(std::move(mesh));
  } catch (const InputError& e) {
    check_message(e.what(), name);
  } catch (const ResourceError& e) {
    check_message(e.what(), name);
  }
  return 0;
}
