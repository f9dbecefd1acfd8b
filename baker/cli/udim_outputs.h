// UDIM output on the command line: `-o normal.<UDIM>.png` writes one map per occupied tile of the
// low-poly's UV layout (pipeline/udim.h), `<UDIM>` replaced by the tile's number (1001, 1002, ...).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/args.h"
#include "core/mesh.h"
#include "pipeline/udim.h"

namespace nmbake {

constexpr const char* kUdimToken = "<UDIM>";

bool has_udim(const std::string& path);
// `pattern` with its <UDIM> replaced by the tile's number.
std::string udim_path(const std::string& pattern, int number);

// Refuses (UsageError) <UDIM> where tiles cannot go: in a folder's name, in --report or
// --save-cage (one file for the whole bake), in a mask when the map has none (or the other way
// round).
void check_udim_outputs(const Args& a);

// What the UV layout holds beyond the unit square, for the warnings (warnings.h).
struct UvTilesNote {
  bool udim = false;                                    // -o has <UDIM>
  std::size_t beyond_triangles = 0, beyond_texels = 0;  // without <UDIM>: in the tiles after 1001
  std::string beyond_tiles;                             // "1002, 1011"
};
// Without <UDIM>: the triangles and texels a UDIM bake would add (find_udim_tiles at the map's size,
// counted only when some triangle lies beyond 1001).
UvTilesNote uv_tiles_note(const Mesh& low, const Args& a, int width, int height);

// The report's "udim": per tile its number, file, triangles, straddling triangles, texels covered,
// coverage, overlapping samples, rays, hits and misses.
nlohmann::json udim_report(const UdimBake& bake, const std::string& pattern);

}  // namespace nmbake
