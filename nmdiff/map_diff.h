// Comparison of the texture set's other maps (README "Texture sets") in their own units.
//
// Pure functions on in-memory images (no file I/O), beside compare_normal_maps (nmdiff.h), which
// the normal-like kinds (normal, object-normal, bent-normal) still use. A map's kind comes from
// its "nmbake:map" metadata or the command line; its stored values v in [0,1] are decoded with
// the ranges its metadata states:
//   height     "nmbake:height_range" "A:B"                  -> A + v (B - A), scene units
//   position   "nmbake:position_box" "x0,y0,z0:x1,y1,z1"   -> x0 + v (x1 - x0) per axis, scene units
//   curvature  "nmbake:curvature_scale" "S"                -> (2v - 1) S, 1/scene units
//   ao, thickness                                           -> v, a share (1 = open, 1 = thick)
//   vertex-color                                            -> v per channel, RGB in [0,1]
//   object-id, material-id                                  -> the colour, compared exactly (8-bit steps)
// Grey maps use channel 0 (1 channel as nmbake writes them); position, vertex-color and the ID
// maps channels 0-2, position and vertex-color by the largest of the three differences per texel.
// Alpha is coverage as for normal maps: the 2nd channel of a 2-channel image, the 4th of 4+.
// Texel (x, y) has row 0 at the top of the image, as in image.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/maps.h"
#include "nmdiff.h"

namespace nmbake::diff {

// How a kind is compared: by angle (compare_normal_maps), by absolute difference in its units
// (compare_maps), or by exact colour (compare_maps, the share of texels that differ).
enum class MapFamily { normal, grey, id };
MapFamily map_family(MapKind kind);

// The kind to compare as: `given` (--map) when not empty, else the kinds the maps' nmbake:map
// metadata state ("" = absent; one absent takes the other's; both absent: normal). Throws
// InputError naming both files and kinds when they state different kinds, or naming the file and
// value when a name is not a map kind.
MapKind resolve_map_kind(const std::string& given, const std::string& kind_a, const std::string& kind_b,
                         const std::string& name_a, const std::string& name_b);

// How one map's stored values v become values in its units: offset[c] + v * scale[c] for channel c
// (channels 0-2; grey maps use c = 0).
struct MapDecoding {
  MapKind kind = MapKind::ao;
  double offset[3] = {0.0, 0.0, 0.0};
  double scale[3] = {1.0, 1.0, 1.0};
  bool from_metadata = false;  // height, position, curvature: the range came from the metadata
  std::string range_text;      // the metadata value it came from ("" when none)
};

// The decoding of a map of `kind` whose metadata is `metadata`. Height, position and curvature
// without their range: the identity (stored values), from_metadata false. Throws InputError
// "<name>: nmbake:height_range '<text>' is not ..." when the range is malformed or not finite
// (B == A, a box of zero extent and S == 0 are legal: every texel decodes to one value).
MapDecoding map_decoding(MapKind kind, const std::map<std::string, std::string>& metadata, const std::string& name);

// The units the differences of `kind` are in: "scene units" (height, position), "1/scene units"
// (curvature), "share" (ao, thickness), "rgb" (vertex-color, values in [0,1]), "texels" (ID maps:
// the share of texels that differ), "deg" (normal-like); "value" for a ranged kind decoded without
// its range (stored values).
std::string map_units(const MapDecoding& decoding);

// Tolerances in the map's units (grey maps) or as a share of texels (ID maps).
struct MapTolerances {
  double max_mean = 0.0;   // mean absolute difference
  double max_p99 = 0.0;    // 99th percentile of the absolute difference
  double max_abs = 0.0;    // largest absolute difference of any compared texel
  double max_share = 0.0;  // ID maps: share of compared texels whose colour differs, in [0,1]
};

// Defaults that accept 8-bit rounding, as nmdiff's for normal maps do: a share of the map's full
// range R (height B - A, position the box's largest extent, curvature 2S, 1 for the others):
// mean 0.005 R, p99 0.01 R, max 0.02 R (one 8-bit step is 0.0039 R); ID maps share 0.
MapTolerances default_map_tolerances(const MapDecoding& a);

struct MapDiffOptions {
  MapDecoding decoding_a, decoding_b;  // kinds equal; the kind compared is decoding_a.kind
  std::vector<std::uint8_t> mask;      // A's width * height, row-major; nonzero = compare; empty = all
  bool use_alpha = true;               // alpha < 0.5 in A or B is not compared
  bool include_padding = false;        // compare texels outside the mask and alpha coverage too
  Resample resample = Resample::none;  // ID maps always take the nearest texel (no mixed colours)
  MapTolerances tolerances;            // decides MapDiffStats::within
};

struct MapDiffStats {
  MapKind kind = MapKind::ao;
  std::string units;          // map_units(decoding_a)
  int width = 0, height = 0;  // the compared grid (map A's size)
  std::size_t texels_compared = 0;
  // Grey maps: the absolute difference in `units` (position, vertex-color: the largest of the
  // three channels' per texel). ID maps: 1 for a texel whose colour differs, else 0.
  double mean = 0, rms = 0, p95 = 0, p99 = 0, max = 0;
  std::size_t texels_differing = 0;  // ID maps: compared texels whose colour differs
  double share_differing = 0;        // ID maps: texels_differing / texels_compared (0 when none)
  int worst_x = -1, worst_y = -1;    // first texel (row-major) with the largest difference; -1: none

  std::size_t skipped_mask = 0;      // outside the mask
  std::size_t skipped_alpha = 0;     // alpha < 0.5 in A or B
  std::size_t padding_compared = 0;  // compared only because of include_padding
  // Compared texels with a channel that is not finite in A or B: not in the statistics, and any
  // makes the maps not within.
  std::size_t nonfinite_texels = 0;

  bool within = false;  // the tolerances met, at least one texel compared, none not finite
  std::vector<std::string> warnings;
};

// Compares A with B in the units of options.decoding_a.kind (a grey or ID kind). Throws InputError
// when a map has too few channels for its kind, is empty, the sizes differ without a resample mode,
// or the mask has the wrong size. `field` (optional) receives the per-texel differences (in
// `units`; ID maps 1 or 0; -1 where not compared) for a heatmap.
MapDiffStats compare_maps(const Image& a, const Image& b, const MapDiffOptions& options, AngleField* field = nullptr);

// One-line summary. Grey maps: "map=<kind> units=<units> mean=<v> p99=<v> max=<v> texels=<n>
// within=<0|1>"; ID maps: "map=<kind> units=texels differing=<n> share=<v> texels=<n> within=<0|1>"
// (units with spaces written with '-': "scene-units").
std::string map_summary_line(const MapDiffStats& stats);

}  // namespace nmbake::diff
