// Loading meshes: OBJ, PLY (ascii and binary), OFF and STL (ascii and binary) by readers of our own,
// glTF, FBX, DAE, 3DS and others through Assimp.
//
// Every error in the file throws InputError with the file name and the element, e.g.
// "high.ply: vertex 17 has a non-finite coordinate" or "low.obj: line 812: face index 9001 out of
// range (8000 vertices)". Polygons are fanned into triangles. Nothing is rescaled.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "core/mesh.h"

namespace nmbake {

struct LoadOptions {
  bool require_uvs = false;  // throw "<file>: face N has no UVs" when any face lacks them
  // Which UV set to read (--uv-set): 0 the first. OBJ, PLY, OFF and STL have one; glTF, FBX, DAE
  // may have several (read through Assimp, up to kMaxUvSets).
  unsigned uv_set = 0;
  // The point subtracted (in double) from the file's coordinates: Mesh::origin. Unset: the centre
  // of the mesh's bounds when the mesh lies farther from the file's origin than kFarFactor times
  // its size, else (0,0,0). Meshes baked together must share one: load the low-poly first and
  // pass its origin for the high-poly and the cage.
  std::optional<glm::dvec3> origin = std::nullopt;
};

constexpr unsigned kMaxUvSets = 8;

// A mesh whose largest coordinate exceeds kFarFactor times its bounding-box diagonal is loaded
// re-centred (float would lose more than 4 bits of its precision there).
constexpr double kFarFactor = 16.0;

// Positions whose values carry steps coarser than kPrecisionLimit of the mesh's diagonal (a far
// mesh saved in float precision, or beyond double's reach) are refused: the map would be off by
// degrees (the same bound as kCoordinateSpacingWarn for positions given to the library).
constexpr double kPrecisionLimit = 1e-3;

// Reads `path`. Throws InputError on a missing, empty, unreadable or invalid file (no faces,
// non-finite coordinates, indices out of range, truncated binary data, ...).
Mesh load_mesh(const std::string& path, const LoadOptions& options = {}, MeshLoadInfo* info = nullptr);

// The same checks and parsing on a file's bytes already in memory: `name` picks the reader by its
// extension and names the file in messages (the fuzz target, tests/fuzz, uses this).
Mesh load_mesh_from_memory(const std::string& name, std::string_view bytes, const LoadOptions& options = {},
                           MeshLoadInfo* info = nullptr);

// The mesh as OBJ text: positions (each float exactly, %.9g), UVs when it has them, and its
// triangles (v/vt), in the mesh's own vertex order, so reading it back gives the same arrays.
// `comment` becomes the first line (after "# ").
std::string obj_text(const Mesh& mesh, const std::string& comment);

}  // namespace nmbake
