// Loading the three inputs of nmview through the baker's own code: nmbake::load_mesh,
// nmbake::read_image (and read_image_metadata for the map's convention), nmbake::compute_tangent_frames
// and nmbake::ensure_normals, so bad input gets the baker's errors and the low-poly gets exactly
// the frames the baker encoded with.
#pragma once

#include <cstddef>
#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "decoding.h"
#include "core/image.h"
#include "metrics.h"
#include "texture_set.h"
#include "vertex_data.h"

namespace nmview {

struct Scene {
  LowVertices low;       // low-poly with the baker's per-corner frames
  HighVertices high;     // high-poly with its file normals, else angle-weighted vertex normals
  nmbake::Image map;     // the normal map as read, at least 3 channels, any size
  MapDecoding decoding;  // the convention the map was baked with (metadata, then overrides)
  Bounds bounds;         // union of both meshes, object space
  float radius = 0.0f;   // largest distance of a vertex of either mesh from bounds.centre()
  std::string low_name, map_name, high_name;
  std::size_t low_triangles = 0, high_triangles = 0;
  // The texture set (a map path with <MAP>; map_name is that path): its files, and its members
  // other than the normal map as read, in MapKind order.
  TextureSetFiles map_files;
  std::vector<SetMap> set_maps;
  // The low-poly's Mesh::origin (load_mesh), shared by the high-poly and an overlay's cage.
  glm::dvec3 origin{0.0};
  // With <UDIM> (map_files.udim): the normal map's tiles as read (`map` is a copy of the first), and
  // each triangle's tile as u + 10 v (-1 in none; udim_tiles.h), in scene.low's index order.
  std::vector<UdimTileImage> map_tiles;
  std::vector<std::int32_t> face_cells;
};

// Throws nmbake::InputError (from the loaders, or "<map>: has N channel(s); a normal map needs
// RGB") on bad input, nmbake::UsageError for a bad override. `maps` is the texture set
// (find_texture_set): its normal map is required (require_normal_map, checked after the low-poly
// is read, so inputs are reported in command-line order); every other member is read into
// set_maps. Notes (the set's members, the map's decoding and where it came from, normals computed,
// a tangent-space map that does not look like one) go to `log`.
// `uv_set` is the low-poly's UV set the map was baked into (nmbake --uv-set, LoadOptions::uv_set:
// 0 the first, below nmbake::kMaxUvSets); its UVs and tangent frames are the ones shown.
// With <UDIM>: every tile of every member is read (tiles of one map must have one size), the
// decoding comes from the normal map's first tile, a note lists the tiles found and one warning
// lists the tiles that faces use but that have no file (and the faces in no tile). Without it, a
// note says when faces lie beyond the unit UV square (the map repeats over them).
Scene load_scene(const std::string& low_path, const TextureSetFiles& maps, const std::string& high_path, std::ostream& log,
                 const DecodingOverrides& overrides = {}, unsigned uv_set = 0);

// Refuses a screenshot path that is one of the scene's files (the meshes and every map of the set
// found: UsageError) or a file that cannot be written (OutputError: a special file, a folder, a
// dangling link), before anything is written (io/output_files.h). An empty path passes.
void check_screenshot(const std::string& path, const std::string& low_path, const TextureSetFiles& maps,
                      const std::string& high_path);

// Writes the RGB of `image` with nmbake::write_image (8-bit for PNG) under the output contract
// (io/output_files.h): one of the scene's files (UsageError), a special file, a folder or a
// dangling link (OutputError) refused, a temporary renamed into place when complete.
void write_screenshot(const std::string& path, const Rgba8Image& image, const Scene& scene);

}  // namespace nmview
