// The maps of a texture set (--maps): their names, what each needs, and the options of their
// definitions (README, "Texture sets"). Every map is computed from the same primary hit per
// sample as the normal map, so the maps of one bake line up texel for texel.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace nmbake {

enum class MapKind : std::uint8_t {
  normal,         // tangent or object space, as --space says (BakeResult::map)
  object_normal,  // the high-poly normal in object space, encoded n * 0.5 + 0.5
  ao,             // unoccluded share of cosine-weighted rays from the hit, 1 = open
  bent_normal,    // mean unoccluded direction of the AO rays, encoded like the normal map
  height,         // signed distance from the low-poly surface to the hit, mapped by the height range
  thickness,      // mean of min(hit distance, D) / D of rays into the inverted normal, 1 = thick
  curvature,      // the high-poly's mean curvature at the hit, 0.5 = flat, convex brighter
  position,       // the hit, normalised to the high-poly's bounding box per axis (R = x, G = y, B = z)
  object_id,      // one flat colour per high-poly object (from its name)
  material_id,    // one flat colour per high-poly material (from its name)
  vertex_color,   // the high-poly's interpolated vertex colours
};
constexpr int kMapKinds = 11;

// "normal", "object-normal", "ao", "bent-normal", "height", "thickness", "curvature", "position",
// "object-id", "material-id", "vertex-color".
const char* map_name(MapKind kind);
// Whether `name` is one of map_name's; sets `kind` when it is.
bool parse_map_name(const std::string& name, MapKind& kind);
// Every name, comma-separated, in MapKind order (for messages and --help).
std::string map_name_list();
// Channels of the map's file: 1 for ao, height, thickness, curvature; 3 for the others.
int map_channels(MapKind kind);
// Channels of the map's image in memory (BakedMap::image): as map_channels, except the ID maps
// (map_is_flat), held as 1 channel of palette indices (expand_palette) until they are written.
int map_image_channels(MapKind kind);
// Maps whose texel takes one sample's value (the most frequent among its hit samples), never a
// mean: the ID maps.
bool map_is_flat(MapKind kind);
// Maps that cast secondary rays from the hit (ao, bent-normal, thickness).
bool map_casts_rays(MapKind kind);

constexpr int kDefaultAoRays = 64;
constexpr int kMaxAoRays = 65536;
// --ao-rays auto: the default --max-ao-error (on the accuracy bench's sculpts auto at 0.02 has 0.90
// and 1.26 times the RMS error of 256 independent random rays per texel, the bake before stratified
// chains: docs/accuracy/ao.md) and the most rays per texel.
constexpr double kDefaultMaxAoError = 0.02;
constexpr int kMaxAutoAoRays = 1024;
// --curvature-smoothing: the default rings of smoothing (measured: docs/accuracy/map_defaults.md)
// and the most the option takes.
constexpr int kDefaultCurvatureSmoothing = 2;
constexpr int kMaxCurvatureSmoothing = 16;

struct MapOptions {
  std::vector<MapKind> maps{MapKind::normal};  // in the order asked; each once
  // AO and bent normals: a ray that meets the high-poly within this distance (scene units) is
  // occluded; <= 0: automatic (kAutoAoDistance of the scene's diagonal).
  double ao_distance = 0.0;
  int ao_rays = kDefaultAoRays;  // rays per texel for ao, bent-normal and thickness (unused with ao_rays_auto)
  // --ao-rays auto: per texel, a first round of 32 rays, then rounds of more while the texel's
  // standard error (AO's for ao and bent-normal, thickness's own for thickness) is above
  // max_ao_error (a share: AO and thickness are in [0, 1]), at most ao_rays_max rays per texel.
  bool ao_rays_auto = false;
  double max_ao_error = kDefaultMaxAoError;
  int ao_rays_max = kMaxAutoAoRays;
  // The secondary rays' scrambles (keyed by texel, chain and this): 0 gives the maps every
  // release bakes; another value, rays independent of them (the accuracy bench's reference).
  std::uint64_t ray_seed = 0;
  // The accuracy bench's baseline only: independent random directions per ray (the release before
  // stratified chains) instead of each texel's Owen-scrambled Sobol chains; maps otherwise alike.
  bool ao_independent_rays = false;
  bool ao_occluders_all = false;  // with --match names: every object occludes, not only the group's
  // Height: the distance mapped to 0 and to 1 (scene units); not given: the bake's own range,
  // symmetric about 0.
  bool height_range_given = false;
  double height_min = 0.0, height_max = 0.0;
  // Thickness: the distance that counts as thick (scene units); <= 0: automatic (kAutoThickness of
  // the scene's diagonal).
  double thickness_distance = 0.0;
  // Curvature: the mean curvature (1/scene units) that reaches 0 or 1; <= 0: automatic (from the
  // bake's distribution, reported).
  double curvature_scale = 0.0;
  // Curvature: passes of smoothing over the high-poly's welded mesh (rings of neighbours,
  // core/curvature.h CurvatureOptions), 0 to kMaxCurvatureSmoothing.
  int curvature_smoothing = kDefaultCurvatureSmoothing;

  bool wants(MapKind kind) const {
    for (MapKind k : maps)
      if (k == kind) return true;
    return false;
  }
  // Any map beside the normal map (its own images, BakeResult::maps).
  bool wants_extra() const {
    for (MapKind k : maps)
      if (k != MapKind::normal) return true;
    return false;
  }
  bool wants_rays() const {
    for (MapKind k : maps)
      if (map_casts_rays(k)) return true;
    return false;
  }
};

// The automatic distances, as a share of the scene's bounding-box diagonal, measured on the sculpts
// (docs/accuracy/map_defaults.md): AO's reaches the sculpted detail's cavities (90% of their
// darkening at the whole diagonal) while the base shape alone still darkens under 1% on the torus;
// thickness's spreads its values most between thin and thick parts.
constexpr double kAutoAoDistance = 0.1;
constexpr double kAutoThickness = 0.2;

}  // namespace nmbake
