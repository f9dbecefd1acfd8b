// The in-memory triangle mesh every stage works on: flat arrays.
//
// Coordinates are object space exactly as in the file (never rotated or rescaled). Attributes are
// indexed per corner, like OBJ: corner c of triangle t uses positions[position_index[3t+c]],
// normals[normal_index[3t+c]] and uvs[uv_index[3t+c]], so split normals (hard edges) and UV seams
// are kept. Triangles are counter-clockwise seen from the front. UVs follow the OBJ convention:
// v = 0 at the bottom of the image, v = 1 at the top.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace nmbake {

struct Mesh {
  std::string source;  // file name, used in messages ("low.obj: face 3 ...")

  // Positions are relative to `origin`: a mesh far from the file's origin is loaded re-centred
  // (the file's coordinates minus origin, taken in double), so that float keeps its precision.
  // Meshes baked together share one origin (load_mesh's LoadOptions::origin).
  glm::dvec3 origin{0.0};
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  // unit length when present
  std::vector<glm::vec2> uvs;

  std::vector<std::uint32_t> position_index;  // 3 per triangle
  std::vector<std::uint32_t> normal_index;    // 3 per triangle, or empty when the mesh has no normals
  std::vector<std::uint32_t> uv_index;        // 3 per triangle, or empty when the mesh has no UVs

  // Face number in the file for each triangle (a polygon's fan triangles share it), for messages.
  std::vector<std::uint32_t> source_face;

  // The named parts of the mesh: an OBJ file's objects (`o`, or `g` in a file without `o`), a
  // glTF, FBX or DAE node's meshes; a file without names is one object named after the file.
  // Objects of several files merged (merge_meshes) keep their file. triangle_object[t] is triangle
  // t's object, or empty when there is one object (every triangle then is object 0).
  struct Object {
    std::string name;
    std::string file;
  };
  std::vector<Object> objects;
  std::vector<std::uint32_t> triangle_object;

  // The high-poly's materials (the material-id map): an OBJ file's `usemtl` names, a glTF, FBX or
  // DAE mesh's material name (meshes of one material share it), in the order triangles first use
  // them. A file that names no material has none (materials empty). In a file that names some, the
  // triangles without one (faces before the first `usemtl`, a glTF primitive without a material)
  // have the material named "". Materials of several files merged (merge_meshes) are one by name,
  // the triangles of a file that names none having "".
  // triangle_material[t] is triangle t's material, or empty when every triangle has material 0 (or
  // there are none).
  std::vector<std::string> materials;
  std::vector<std::uint32_t> triangle_material;

  // Vertex colours (the vertex-color map), RGBA in [0, 1] as the file stores them: no colour-space
  // conversion (glTF's COLOR_0 is linear, PLY and OBJ colours are usually sRGB-encoded); integer
  // values divided by their type's maximum (uchar by 255, ushort by 65535), floats as they are,
  // both clamped to [0, 1]; alpha 1 where the file has none. Corner c of triangle t has
  // colors[color_index[3t+c]]; color_index is empty when the mesh has no colours (merge_meshes
  // keeps them only when every file has them).
  std::vector<glm::vec4> colors;
  std::vector<std::uint32_t> color_index;  // 3 per triangle, or empty

  std::size_t triangle_count() const { return position_index.size() / 3; }
  bool has_normals() const { return !normal_index.empty(); }
  bool has_uvs() const { return !uv_index.empty(); }
  std::uint32_t object_of(std::size_t tri) const { return triangle_object.empty() ? 0u : triangle_object[tri]; }
  std::size_t object_count() const { return objects.empty() ? 1 : objects.size(); }
  bool has_colors() const { return !color_index.empty(); }
  std::uint32_t material_of(std::size_t tri) const { return triangle_material.empty() ? 0u : triangle_material[tri]; }
  std::size_t material_count() const { return materials.size(); }

  glm::vec3 corner_position(std::size_t tri, int corner) const { return positions[position_index[3 * tri + corner]]; }
  glm::vec2 corner_uv(std::size_t tri, int corner) const { return uvs[uv_index[3 * tri + corner]]; }
  glm::vec3 corner_normal(std::size_t tri, int corner) const { return normals[normal_index[3 * tri + corner]]; }
  glm::vec4 corner_color(std::size_t tri, int corner) const { return colors[color_index[3 * tri + corner]]; }
};

// The mesh moved to another origin: the same points, positions re-expressed in double.
inline Mesh with_origin(Mesh m, const glm::dvec3& origin) {
  const glm::dvec3 shift = m.origin - origin;
  for (glm::vec3& p : m.positions) p = glm::vec3(glm::dvec3(p) + shift);
  m.origin = origin;
  return m;
}

// Whether `high` and `cage` (may be null) share `low`'s origin, as meshes baked together must; the
// bake entry points move copies of them onto it when they do not.
inline bool share_origin(const Mesh& low, const Mesh& high, const Mesh* cage) {
  return high.origin == low.origin && (!cage || cage->origin == low.origin);
}

// What loading found and repaired, for the report.
struct MeshLoadInfo {
  std::size_t file_faces = 0;             // faces as written in the file
  std::size_t polygons_triangulated = 0;  // faces with more than 3 corners, fanned into triangles
  std::size_t normals_renormalized = 0;   // file normals that were not unit length
  std::size_t zero_normals = 0;           // file normals of length ~0 (replaced by computed ones)
  std::string format;                     // "obj", "ply-binary", "ply-ascii", "off", "stl", "gltf", "fbx", "dae", ...
  // The file's normals (or UVs) were discarded because only some faces had them, or (normals) one
  // had length ~0; normal_index (uv_index) is then empty and normals get computed later.
  bool normals_dropped = false;
  bool uvs_dropped = false;
  std::size_t faces_without_normals = 0;  // counted when only some faces had normals
  std::size_t faces_without_uvs = 0;      // counted when only some faces had UVs
  // The file's vertex colours were discarded because only some vertices had them (an OBJ mixing
  // `v x y z` and `v x y z r g b` lines; glTF, FBX or DAE meshes some of which have colours);
  // color_index is then empty.
  bool colors_dropped = false;
  std::size_t vertices_without_colors = 0;   // counted when only some vertices had colours
  std::size_t degenerate_faces_dropped = 0;  // STL facets whose corners welded together (dropped)
  double largest_coordinate = 0.0;           // largest |x|, |y| or |z| a face uses, as in the file
  // The scale applied to the file's coordinates: an FBX file's unit to metres (0.01 for
  // centimetres); 1 for every other format (glTF is in metres, OBJ, PLY, OFF and STL say nothing).
  double unit_scale = 1.0;
};

}  // namespace nmbake
