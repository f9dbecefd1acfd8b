// Comparison of two tangent-space normal maps by the angle between their decoded normals.
//
// Pure functions on in-memory images (no file I/O), shared by the nmdiff program and the golden-map
// tests. A texel's encoded value c in [0,1]^3 decodes to n = normalize(c * 2 - 1) in tangent space
// with green = +bitangent (OpenGL, "up"); a "down" (DirectX) map has its green negated first. A
// texel that decodes to a zero or non-finite vector is invalid: it is counted, never compared.
// Texel (x, y) has row 0 at the top of the image, as in image.h.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/image.h"
#include "core/mesh.h"

namespace nmbake::diff {

enum class GreenAxis { up, down };  // up = OpenGL "Y+" (nmbake's default), down = DirectX "Y-"

// How map B is brought onto A's texel grid when the sizes differ.
enum class Resample {
  none,      // sizes must match (compare_normal_maps throws InputError otherwise)
  nearest,   // the B texel under A's texel centre
  bilinear,  // B interpolated at A's texel centre (clamped at the borders)
  box,       // mean of the B texels whose centres fall inside A's texel (bilinear when B is smaller)
};

// Defaults accept 8-bit rounding: a float map against its own 8-bit quantisation differs by at
// most 0.39 deg (sqrt(3)/255 rad; mean 0.17 deg over random normals, 0.32 deg everywhere on a flat
// map); two 8-bit roundings of nearly equal float maps differ by at most 0.78 deg (p99 0.45).
struct Tolerances {
  double max_mean_deg = 0.5;  // mean angular difference, degrees
  double max_p99_deg = 1.0;   // 99th percentile, degrees
  double max_deg = 2.0;       // largest difference of any compared texel, degrees
};

struct DiffOptions {
  GreenAxis green_a = GreenAxis::up;  // convention map A is encoded in
  GreenAxis green_b = GreenAxis::up;  // convention map B is encoded in
  std::vector<std::uint8_t> mask;     // A's width * height, row-major from the top; nonzero =
                                      // compare; empty = every texel
  bool use_alpha = true;              // a 4th channel is coverage: alpha < 0.5 is not compared
  bool include_padding = false;       // compare texels outside the mask and alpha coverage too
  Resample resample = Resample::none;
  Tolerances tolerances;                   // decides DiffStats::within
  bool detect_convention_mistakes = true;  // warn about a green flip or R/G swap between the maps
};

struct DiffStats {
  int width = 0, height = 0;  // the compared grid (map A's size)
  std::size_t texels_compared = 0;
  double mean_deg = 0, rms_deg = 0, p95_deg = 0, p99_deg = 0, max_deg = 0;  // 0 when none compared
  double over_1deg = 0, over_5deg = 0;  // fraction of compared texels with a difference > 1 / > 5 deg
  int worst_x = -1, worst_y = -1;       // first texel (row-major) with the largest difference; -1: none

  // Texels not compared, by the first reason that applies.
  std::size_t skipped_mask = 0;      // outside the mask
  std::size_t skipped_alpha = 0;     // alpha < 0.5 in A or B
  std::size_t invalid_a = 0;         // A decodes to a zero or non-finite vector
  std::size_t invalid_b = 0;         // B decodes to a zero or non-finite vector (A valid)
  std::size_t padding_compared = 0;  // compared only because of include_padding
  // Compared texels with a channel that is not finite (NaN, infinity) in A or B: each counts as a
  // difference of 180 degrees, never as "not compared", and any makes the maps not within.
  std::size_t nonfinite_texels = 0;

  bool within = false;                // all three tolerances met, at least one texel compared, none not finite
  std::vector<std::string> warnings;  // one line each, e.g. a likely green flip
};

// Per texel of A's grid, the angular difference in degrees, or -1 where not compared.
struct AngleField {
  int width = 0, height = 0;
  std::vector<float> degrees;
};

// Throws InputError "<name>: ..." when `map` cannot be a normal map (fewer than 3 channels, empty).
void check_normal_map(const Image& map, const std::string& name);

// Decodes an encoded value (r, g, b) to a unit normal in the "up" convention; false when it is a
// zero or non-finite vector.
bool decode_normal(const float* rgb, GreenAxis green, double n[3]);

// `src` resampled onto a width x height grid (all channels). Resample::none requires equal sizes.
Image resample_image(const Image& src, int width, int height, Resample mode);

// B at A's size, as both comparisons take it: `b` itself when the sizes agree, else `b` resampled
// with `mode` into `storage`. Throws InputError when the sizes differ and `asked` (the user's
// --resample) is Resample::none, or when `mask` is neither empty nor one byte per texel of A.
const Image& comparable_b(const Image& a, const Image& b, Resample asked, Resample mode, const std::vector<std::uint8_t>& mask,
                          Image& storage);

// Texels of a width x height map covered by `low`'s UV layout (the baker's rasterizer: a texel
// counts when its centre is inside a UV triangle). Throws InputError when `low` has no UVs.
std::vector<std::uint8_t> uv_layout_mask(const Mesh& low, int width, int height);

// Compares A (e.g. a fresh bake) with B (e.g. the golden map). Throws InputError when a map is
// unusable, the sizes differ without a resample mode, or the mask has the wrong size.
// `field` (optional) receives the per-texel differences for a heatmap.
DiffStats compare_normal_maps(const Image& a, const Image& b, const DiffOptions& options = {}, AngleField* field = nullptr);

// One-line summary "mean=<deg> p99=<deg> max=<deg> texels=<n> within=<0|1>".
std::string summary_line(const DiffStats& stats);

// A colour picture of `field`: 0 deg dark blue-violet rising through teal and green to yellow at
// `scale_max_deg` (and above); texels not compared are dark grey. A legend bar from 0 (left) to
// scale_max_deg (right) is drawn under the map, with the two values written in small digits when
// the picture is wide enough, each followed by `unit` ("o" draws a degree sign; "" for the other
// maps, whose field holds differences in their own units). RGB, values in [0,1].
Image render_heatmap(const AngleField& field, double scale_max_deg, const std::string& unit = "o");

// The automatic heatmap scale: max(tolerances.max_deg, stats.p99_deg), at least 0.1 deg.
double auto_heatmap_scale(const DiffStats& stats, const Tolerances& tolerances);

}  // namespace nmbake::diff
