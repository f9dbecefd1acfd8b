// The texture set's other maps (--maps beyond normal) inside the trace: from each sample's primary
// hit (the one the normal map shades), its values for every extra map, and per texel their mean
// (or, for the ID maps, the value most of its samples take). AO, bent normals and thickness cast
// their secondary rays here, from the hit, on the bake's own BVH.
//
// Everything a texel gets is computed by the thread that traces its tile, in sample order, with
// directions keyed by texel (never by thread): the maps do not depend on the
// thread count.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "core/image.h"
#include "core/maps.h"
#include "pipeline/bake.h"
#include "pipeline/bvh.h"
#include "pipeline/prepare.h"

namespace nmbake {

// What the extra maps read, made once per bake (make_map_inputs) and shared by the trace threads.
struct MapInputs {
  const MapOptions* maps = nullptr;
  const Prepared* s = nullptr;
  const HighScene* scene = nullptr;
  const Mesh* high = nullptr;
  // Per BVH triangle its high-poly triangle (HighSelection::kept), or null: the same index.
  const std::uint32_t* source = nullptr;
  std::vector<float> curvature;  // with the curvature map: per high-poly position, 1 / scene units
  // Per BVH triangle, the high-poly object's / material's index (null, empty: 0 for all).
  const std::uint32_t* object = nullptr;
  std::vector<std::uint32_t> material;
  // AO and bent normals: rays meeting the high-poly within ao_distance are occluded; thickness:
  // hits farther than thickness_distance count as that distance. Scene units.
  double ao_distance = 0.0, thickness_distance = 0.0;
  double epsilon = 0.0;  // secondary rays start this far off the surface (scene units)
  NormalSpace space = NormalSpace::tangent;
  BitangentMode bitangent = BitangentMode::per_pixel;
  bool green_down = false;
  // With match groups: per low-poly triangle its group and per BVH triangle its group (RayGroups);
  // secondary rays then see only their group (unless MapOptions::ao_occluders_all).
  const RayGroups* groups = nullptr;
  // The encodings known before the trace, which TexelMaps::write applies itself: position, the
  // high-poly's bounding box (re-centred scene coordinates) to [0, 1]; the ID maps, per index its
  // colour (map_set.h id_colors): their palette, of which write needs the size only.
  glm::dvec3 position_lo{0.0}, position_hi{0.0};
  std::vector<glm::vec3> object_colors, material_colors;
};

// The raw values the trace writes for each extra map, per texel of the whole map (covered texels
// only; BakeResult::coverage says which):
//   object-normal, bent-normal: unit vector (x, y, z), the output space's (tangent or object);
//   ao: unoccluded share; thickness: mean of min(distance, D) / D;
//   height: mean signed distance (scene units); curvature: mean curvature (1 / scene units);
//   vertex-color: mean RGB;
// and already encoded, as finish_maps leaves them:
//   position: mean hit (re-centred scene coordinates) over MapInputs::position_lo..hi, each axis
//     clamped to [0, 1] (0.5 on a flat axis);
//   object-id, material-id: 1 + the index taken, as expand_palette reads it with MapInputs::*_colors
//     as the palette (0, black, for a texel whose samples all miss or an index without a colour).
// A texel whose samples all miss gets the map's miss value (texel_maps.cpp, kMiss*).
struct MapTargets {
  std::vector<Image> raw;  // per MapOptions::maps entry (map_image_channels); empty for normal
  // Per texel, the standard error of the ao / thickness value (the spread of the means of its
  // rays' independent chains over sqrt of their number, texel_maps.cpp); empty unless the map is
  // asked for.
  Image ao_error, thickness_error;
  // With --ao-rays auto (MapOptions::ao_rays_auto), per texel the AO's / thickness's rays cast
  // (summed over its samples); empty otherwise, or unless the map (ao or bent-normal / thickness) is
  // asked for.
  Image ao_rays, thickness_rays;
};

// The images of `maps` (raw, map_image_channels) and the error images, sized as the map.
MapTargets allocate_map_targets(const MapOptions& maps, int width, int height);

// One trace thread's part: per tile texel, sums of each extra map's sample values.
class TexelMaps {
 public:
  TexelMaps(const MapInputs& in, std::size_t tile_texels);
  ~TexelMaps();
  TexelMaps(const TexelMaps&) = delete;
  TexelMaps& operator=(const TexelMaps&) = delete;

  // The samples of one pass over a tile, as the trace holds them: per sample its low-poly
  // triangle and barycentrics, its texel in the tile, and its hit (BVH triangle or raycast's
  // no_hit, Embree's u, v) with the signed distance from the low-poly surface.
  struct Samples {
    const std::int32_t* low_tri;
    const double* const* b;  // b[0..2]
    const std::uint16_t* texel;
    const std::uint32_t* hit_tri;
    const float* u;
    const float* v;
    const double* dist;
    std::size_t count;
  };
  // Replaces the sums of the texels these samples fall in by theirs. `tile_x0`, `tile_y0`, `side`
  // and `width` place the tile's texels in the map (directions are keyed by map texel);
  // `level` (0 = first pass) and `per_texel` (the pass's samples per texel) spread a texel's
  // secondary rays over its samples.
  void shade(const Samples& samples, int tile_x0, int tile_y0, int side, int width, int level, std::size_t per_texel);
  // Adaptive passes: keep the sums so far, and after a refining pass put them back for the texels
  // it did not redo (refine[i] == 0).
  void keep();
  void restore_unrefined(const std::uint8_t* refine);
  // Writes the tile's texels that have samples into `out` (at x0, y0, w x h of the map).
  void write(MapTargets& out, int x0, int y0, int w, int h, int side, int width) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nmbake
