// Checks of what a user gave the command, before a bake that could not be right: meshes that do not
// lie in one place or are of different sizes (a unit mismatch), LOW and HIGH given the wrong way
// round, and UVs stacked so deep that the map would be confetti (tiled UVs).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "core/bounds.h"
#include "core/mesh.h"
#include "core/uv_overlap.h"

namespace nmbake {

// How the low-poly's and the high-poly's boxes compare.
struct PairBoxes {
  Box low, high;  // in the files' coordinates (the meshes' origin added back)
  // The larger box diagonal over the smaller (1: the same size).
  double size_ratio = 1.0;
  // Along the axis where the boxes overlap least, the length they share over the smaller of the
  // two lengths, each box first grown by 1% of the larger diagonal on every side (so a flat mesh
  // has a length): 1 when one box's extent holds the other's, 0 when they are apart.
  double overlap = 1.0;
  enum class Mismatch { none, apart, size } mismatch = Mismatch::none;
  bool mismatched() const { return mismatch != Mismatch::none; }
};

// Thresholds: boxes sharing less than a quarter of the smaller extent along some axis lie apart (most
// rays would miss); one diagonal ten or more times the other is a different size (units: 10 mm in a
// cm, 100 cm in a m).
constexpr double kApartOverlap = 0.25;
constexpr double kSizeRatio = 10.0;

PairBoxes compare_boxes(const Mesh& low, const Mesh& high, int threads = 0);

// The one-line message for a mismatch ("" when none): both files, their roles and boxes, and the
// likely cause; without `allowed`, how to bake anyway.
std::string mismatch_text(const PairBoxes& b, const std::string& low_path, const std::string& high_path, bool allowed);

// A warning when the low-poly has many more triangles than a high-poly that has UVs (LOW and HIGH
// given the wrong way round: what came as HIGH looks like a low-poly), else nullopt. `kSwapRatio`:
// the low-poly's triangles over the high-poly's.
constexpr double kSwapRatio = 2.0;
std::optional<std::string> swap_warning(std::size_t low_triangles, std::size_t high_triangles, bool high_has_uvs,
                                        const std::string& low_path, const std::string& high_path);

// UV overlap is refused (without --allow-overlap) when more than this share of the covered texels
// lies under three or more triangles: stacked mirrored halves (two layers) pass, tiled UVs do not.
constexpr double kStackedShareRefuse = 0.10;
// The overlap check's grid: the map's size, at most this many texels a side (the share does not
// need the full resolution and tiled UVs cost their layers per texel).
constexpr int kOverlapGridSide = 512;

// The overlap of the low-poly's UVs at (a grid no finer than) the map's size.
UvOverlap measure_map_overlap(const Mesh& low, int width, int height, bool udim, int threads);

// Whether `o` is refused (kStackedShareRefuse), and its one-line text: the shares and layers (and
// the bake's count of samples covered more than once, `samples`), and, when refused and not
// `allowed`, how to bake anyway. "" without overlap.
bool overlap_refused(const UvOverlap& o);
std::string overlap_text(const UvOverlap& o, std::uint64_t samples, const std::string& low_path, bool allowed);

// The report's "pair" (boxes, size ratio, overlap, mismatch) and "uv_overlap" objects.
nlohmann::json pair_report(const PairBoxes& b);
nlohmann::json overlap_report(const UvOverlap& o);

}  // namespace nmbake
