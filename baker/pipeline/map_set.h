// The texture set's other maps around the trace: what they read, made before it
// (make_map_inputs), and from the trace's raw values the encoded maps (finish_maps; pad_map then
// pads them with the normal map).
// Definitions and why: README, "Texture sets".
#pragma once

#include <cstdint>
#include <vector>

#include "pipeline/bake.h"
#include "pipeline/texel_maps.h"

namespace nmbake {

// The high-poly's mean curvature per position (core/curvature.h) when opt.maps asks for the
// curvature map, else empty: it reads the mesh alone, so it runs beside the stages before the trace.
std::vector<float> map_curvature(const BakeOptions& opt, const Mesh& high);

// The inputs of opt.maps's extra maps over the BVH `scene` of the triangles `selection` keeps,
// with the curvature of map_curvature, the high-poly's bounding box and its names' colours.
MapInputs make_map_inputs(const BakeOptions& opt, const Prepared& s, const HighScene& scene, const HighSelection& selection,
                          const Mesh& high, std::vector<float> curvature);

// The ranges the raw values are mapped to [0, 1] by: height, opt.maps's range or the bake's own,
// symmetric about 0 (0.5 is the low-poly surface); curvature, opt.maps's scale or the bake's own,
// the mean plus one standard deviation of |curvature| over the covered texels (Unreal's automatic
// range). Over every part of the bake (`raw[t]` with `coverage[t]`: the UDIM tiles share them).
struct MapRanges {
  double height_min = 0.0, height_max = 0.0, curvature_scale = 0.0;
};
MapRanges map_ranges(const BakeOptions& opt, const Prepared& s, const std::vector<const MapTargets*>& raw,
                     const std::vector<const std::vector<std::uint8_t>*>& coverage);

// The encoded maps of `raw` (MapTargets, trace order of opt.maps), their covered texels (`coverage`)
// only: height and curvature by `ranges` (position and the IDs come encoded from the trace, by
// the bounding box and the colours `in` holds). Not padded: pad_map (pad.h) pads them with the normal map, in one pass.
std::vector<BakedMap> finish_maps(const BakeOptions& opt, const Prepared& s, const Mesh& high, const MapInputs& in,
                                  const MapRanges& ranges, MapTargets& raw, const std::vector<std::uint8_t>& coverage,
                                  int threads);

// The colour of an ID map's name: from a hash of the name alone (stable across runs and scenes),
// saturated enough to tell apart, in 8-bit steps. Names whose colours collide in one bake are
// told apart by id_colors.
glm::vec3 id_color(const std::string& name);
// Per name, its colour: id_color, or where two names of `names` would share one, the later name
// (in sorted order) rehashed until it differs.
std::vector<glm::vec3> id_colors(const std::vector<std::string>& names);

}  // namespace nmbake
