// The texture set nmview shows: the maps nmbake writes for one bake (`nmbake --maps normal,ao,...
// -o crate_<MAP>.png` writes crate_normal.png, crate_ao.png, ...; README, "Texture sets"). A map
// path with <MAP> names the set; every map name of core/maps.h is tried in its place, and the files
// that exist are its members. A path without <MAP> is the normal map alone, as before. With
// <UDIM> too (or alone), each member is a set of UDIM tiles (udim_tiles.h), found when one exists.
//
// Members are shown on the low-poly's UVs as they are (UV space, row 0 = v = 1, any size per map):
// the normal map lights the low-poly, ao multiplies the lit render, and any member can be shown
// unlit in its own colours (grey maps as grey, ID maps texel-exact).
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/maps.h"
#include "udim_tiles.h"

namespace nmview {

struct SetFile {
  nmbake::MapKind kind = nmbake::MapKind::normal;
  std::string path;  // the pattern with <MAP> replaced by map_name(kind) (<UDIM> kept)
  // With <UDIM>: the member's tiles that exist, by number (at least one); else empty.
  std::vector<UdimTileFile> tiles;
};

struct TextureSetFiles {
  std::string pattern;                   // as given; without <MAP> the normal map's path
  bool has_token = false;                // the pattern contains <MAP>
  bool udim = false;                     // the pattern contains <UDIM>: every member is tiled
  std::vector<SetFile> found;            // in MapKind order, existing (not necessarily readable) files
  std::vector<nmbake::MapKind> missing;  // the names with no file (only with <MAP>)
  // The member of `kind`, or nullptr.
  const SetFile* find(nmbake::MapKind kind) const;
};

// The set's files, looked up in the filesystem only (nothing is read). A path whose status cannot
// be taken as "no such file" counts as found, so that its loader reports what is wrong with it.
// Without <MAP>: `pattern` itself as the normal map, whether or not it exists (with <UDIM>: found
// when one of its tiles exists). Throws nothing.
TextureSetFiles find_texture_set(const std::string& pattern);

// Throws nmbake::InputError (exit 2, as for a missing map) when the set has no member ("<pattern>:
// no file of the texture set exists (<MAP> as normal, ao, ...: crate_normal.png, ...)") or no normal
// map (the lit render needs one). With <UDIM> and no tile at all: "<pattern>: no UDIM tile exists
// (<UDIM> replaced by 1001 to 2000: suz.1001.png, suz.1002.png, ...)".
void require_normal_map(const TextureSetFiles& files);

// "found normal, ao, curvature; not found: object-normal, ..." (one line, no newline).
std::string describe_set(const TextureSetFiles& files);

// A member other than the normal map, read for display.
struct SetMap {
  nmbake::MapKind kind = nmbake::MapKind::ao;
  std::string path;
  nmbake::Image image;  // as read: 1 channel (grey), 2 (grey, alpha), 3 or 4 (RGB[A]); values 0..1
  // With <UDIM>: every tile as read, one size (`image` is then a copy of the first).
  std::vector<UdimTileImage> tiles;
};

// Reads `file` with nmbake::read_image. Throws nmbake::InputError for an empty image (and the
// loader's errors for a missing or bad file). A file whose nmbake:map metadata names another map
// gets a one-line warning in `log`; it is shown as the name in its path says. A tiled member reads
// every tile and refuses tiles of different sizes (check_tile_sizes).
SetMap load_set_map(const SetFile& file, std::ostream& log);

// `image`'s texels as RGB for display, rows flipped so that row 0 is v = 0 (texture t = mesh v):
// one channel (or grey + alpha) is repeated into R, G and B; alpha is dropped.
std::vector<float> display_rgb(const nmbake::Image& image);

// Maps shown with nearest filtering and without anti-aliasing, so that no pixel mixes two IDs
// (nmbake::map_is_flat: object-id, material-id).
bool shown_texel_exact(nmbake::MapKind kind);

}  // namespace nmview
