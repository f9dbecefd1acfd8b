// Known answers for maps baked from the hard assets (hard_assets.h), shared by the tests and the
// accuracy bench: for every covered texel centre, the exact normal of the analytic surface where
// the bake's own ray line (nmbake::low_ray_normals) through that low-poly point crosses the
// surface of the part the texel's triangle belongs to, and a map's angular error against them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "pipeline/bake.h"
#include "hard_assets.h"

namespace nmbake::procedural {

struct KnownTexel {
  std::uint32_t texel = 0;  // y * size + x
  std::uint32_t tri = 0;    // the low-poly triangle under its centre (the lowest index, as the bake)
  double b[3] = {0, 0, 0};  // barycentrics there
  int part = 0;             // HardAsset::low_part of tri
  glm::dvec3 normal{0.0};   // the exact unit normal (the crossing whose surface faces along the ray)
};

// The exact unit normal where the line through p along the unit outward direction dir crosses
// part `part` (the crossing whose surface faces along dir, as below).
glm::dvec3 known_normal(const HardAsset& asset, const glm::dvec3& p, const glm::dvec3& dir, int part);

// The covered texel centres of a size x size map. The crossing nearest to the point may be the
// part's far side, when its near side bulges out farther (a tall bulge): the answer is then the
// crossing on the other side, whose surface faces along the ray.
std::vector<KnownTexel> known_texels(const HardAsset& asset, int size);

struct KnownErrors {
  std::size_t texels = 0;  // measured: covered in the map, of a part asked for
  double mean_deg = 0.0, worst_deg = 0.0;
  double over1 = 0.0, over60 = 0.0;  // share of the texels more than 1 (60) degrees off
  std::size_t over60_texels = 0;
  std::size_t other_surface = 0;  // texels more than 120 degrees off: a surface facing the other way
};

// A tangent-space float map baked from asset.low (result.map, result.coverage; green up,
// per-pixel bitangent) against the known texels of parts `parts` (all when empty).
KnownErrors measure_against_known(const HardAsset& asset, const std::vector<KnownTexel>& known, const BakeResult& result,
                                  const std::vector<int>& parts = {});

}  // namespace nmbake::procedural
