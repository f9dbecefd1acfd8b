// UDIM tiles in nmview: a map path with <UDIM> names one file per tile of the low-poly's UV layout,
// as `nmbake -o normal.<UDIM>.png` writes them (docs/usage.md, "UDIM tiles"): <UDIM> is replaced by
// the tile's number 1001 + u + 10 v (u in 0..9, v in 0..99: 1001 the unit square, 1002 the square
// to its right, 1011 the one above). It composes with <MAP> (crate_<MAP>.<UDIM>.png).
//
// A triangle belongs to the tile holding its UV centroid, the baker's rule (pipeline/udim.cpp), and
// is shown with that tile's map at its UVs minus the tile's corner; a triangle in no tile, or in a
// tile with no file, has no map (the renderer draws it kMissingTileColour). CPU only, no GL.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "vertex_data.h"

namespace nmview {

constexpr const char* kUdimPatternToken = "<UDIM>";
constexpr int kUdimFirstTile = 1001;  // the number of the unit square's tile
constexpr int kUdimTileColumns = 10;  // u in [0, 10)
constexpr int kUdimTileRows = 100;    // v in [0, 100): numbers up to 2000
constexpr int kUdimCells = kUdimTileColumns * kUdimTileRows;

// A face whose tile has no map: magenta, unlit (linear RGB 0..1), in the lit pane, the map views
// and the difference pane alike. Listed in --help and viewer/README.md.
constexpr float kMissingTileColour[3] = {1.0f, 0.0f, 1.0f};

bool has_udim_token(const std::string& pattern);
// `pattern` with every <UDIM> replaced by `number`.
std::string udim_tile_path(const std::string& pattern, int number);
// 1001 + u + 10 v of cell u + 10 v.
inline int udim_tile_number(int cell) { return kUdimFirstTile + cell; }

struct UdimTileFile {
  int number = kUdimFirstTile;  // 1001 ... 2000
  std::string path;
};

// The tiles of `pattern` that exist, by increasing number, looked up in the filesystem only
// (nothing is read). A path whose status cannot be taken as "no such file" counts as found, so that
// its loader says what is wrong with it. Throws nothing.
std::vector<UdimTileFile> find_udim_files(const std::string& pattern);

// The cell u + 10 v of the tile holding the centroid of UVs a, b, c, or -1 when none does (u below
// 0 or from 10 on, v below 0 or from 100 on, or not finite): the baker's rule.
int udim_cell(glm::vec2 a, glm::vec2 b, glm::vec2 c);

// udim_cell of every triangle of `low`, in index-buffer order (the GL primitive id).
std::vector<std::int32_t> face_udim_cells(const LowVertices& low);

// One map's tiles as read.
struct UdimTileImage {
  int number = kUdimFirstTile;
  std::string path;
  nmbake::Image image;
};

// Throws nmbake::InputError unless every tile of one map has the first tile's size ("b.1002.png is
// 512x512 but b.1001.png is 1024x1024; every UDIM tile of a map must have one size").
void check_tile_sizes(const std::vector<UdimTileImage>& tiles);

// What the faces use: triangles per cell, and those in no tile.
struct UdimUse {
  std::vector<std::size_t> triangles = std::vector<std::size_t>(kUdimCells, 0);  // by cell
  std::size_t outside = 0;                                                       // in no tile
};
UdimUse count_udim_use(const std::vector<std::int32_t>& face_cells);

// The tiles that faces use and `found` lacks, by increasing number (found: the tile numbers that
// have a file).
std::vector<int> missing_udim_tiles(const UdimUse& use, const std::vector<int>& found);

// "1002 (8 triangles), 1011 (2 triangles)"
std::string describe_missing_tiles(const UdimUse& use, const std::vector<int>& missing);

// "1001, 1002, 1011"
std::string tile_number_list(const std::vector<int>& numbers);

// The pane label's tile range of a map's tiles (any order): "MAP 1001-1004" when every number in
// the range has a tile, "MAP 1001-1011, 3 TILES" when some are missing, "MAP 1002" for one tile,
// "" for none (the renderer adds the convention after a comma).
std::string udim_range_label(const std::vector<int>& numbers);

}  // namespace nmview
