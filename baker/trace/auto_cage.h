// Ray distances per low-poly vertex, measured locally: the automatic cage.
//
// A single front/rear distance for the whole scene cannot serve a model whose parts need different
// reaches (a bulge on one finger beside a narrow gap to the next). Here every vertex gets its own:
// probes from the vertex and from points of the triangles around it, cast both ways along the ray
// normals, find how far the high-poly lies outside (front) and inside (rear) the low-poly there;
// probes against the low-poly itself find how far the next part of the low-poly lies along the
// normal, and the cage stops half way to it, so that cages of facing parts never cross and no ray
// starts beyond a neighbouring part; where that part's high-poly stands out towards this one past
// the half-way point, the cage stops before its surface. Needs are spread over neighbours and limits eased off with
// distance (each changes by at most its edge's length along an edge, and a limit, across a coarse
// part's sharp edge, by a bounded ratio, so that rays lean at most about 20 degrees), so the cage
// has neither spikes nor notches; positions are welded by value first, so hard edges (split
// normals) open no cracks. A low-poly with few triangles is probed densely (a grid over each).
// All coordinates are re-centred scene units.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raycast.h"

namespace nmbake {

// The high-poly as the probes see it: its BVH, positions, and per BVH triangle its vertex indices
// and the side its normals point to (raycast::HitRule::facing).
struct ProbeTarget {
  const raycast::Scene* scene = nullptr;
  const glm::vec3* positions = nullptr;
  const std::uint32_t* index = nullptr;  // 3 per BVH triangle
  const std::int8_t* facing = nullptr;   // per BVH triangle (raycast::HitRule::facing: its sign)
  // Per BVH triangle, its match group (raycast::HitRule::group), or null: one group. With groups a
  // probe sees only its own group's triangles.
  const std::uint32_t* group = nullptr;
};

// First hits of `count` rays on `scene`, whatever the faces; with `triangle_group` (per triangle)
// and `ray_group` (per ray), each ray sees only the triangles of its own group.
void intersect_first(const raycast::Scene& scene, const raycast::Ray* rays, raycast::Hit* hits, std::size_t count,
                     const std::uint32_t* triangle_group, const std::uint32_t* ray_group);

// For BVH triangle t: the dot product of its front's (unnormalized) normal with `dir`: positive
// when its front faces along dir.
inline float front_along(const ProbeTarget& high, std::uint32_t t, const glm::vec3& dir) {
  const std::uint32_t* v = high.index + 3 * std::size_t(t);
  const glm::vec3 ng = glm::cross(high.positions[v[1]] - high.positions[v[0]], high.positions[v[2]] - high.positions[v[0]]);
  return (high.facing[t] < 0 ? -1.0f : 1.0f) * glm::dot(ng, dir);
}

// The low-poly: re-centred positions (file vertices), 3 position indices per triangle, and the ray
// normal of each position (unit, the same for positions with equal coordinates).
struct CageBase {
  const std::vector<glm::vec3>* positions = nullptr;
  const std::vector<std::uint32_t>* index = nullptr;
  const std::vector<glm::vec3>* ray_normals = nullptr;
  // Per triangle, its match group (BakeOptions::low_object_group as RayGroups::low), or null: one
  // group. With groups a vertex is probed against its own group's triangles only, of both meshes:
  // another object's low-poly is not a next part (its rays pass through it), nor is its high-poly
  // a surface to reach. Positions are welded within a group.
  const std::vector<std::uint32_t>* group = nullptr;
};

struct LocalDistances {
  // Per low-poly position (file vertex), scene units, at least `floor`.
  std::vector<float> front, rear;
  // Per low-poly position: how far out the high-poly was found, before any limit (at least the
  // scene's front distance): rays search that far out, and take a hit beyond the cage only when
  // none lies within it.
  std::vector<float> search;
  // Welded vertices whose measured need the limit (half the distance to the next part) cut.
  std::size_t front_limited = 0, rear_limited = 0;
  std::size_t vertices = 0;  // welded
  std::size_t probes = 0;    // probe points (each cast both ways against both meshes)
};

// `reach`: how far a probe looks (farther is another part of the model); `floor`: the least
// distance (coincident meshes); `front_base`, `rear_base`: the distances measured for the whole
// scene (the bake's global probe), which every vertex gets at least unless a neighbouring part
// limits it: local needs (1.25 x the distance found plus floor) only add where the high-poly lies
// farther. `need_slope`: how much a need falls per unit of length along an edge (a bulge's need
// covers its surroundings as far as it is tall with 1); `limit_slope`: how much a limit rises (the
// cage's tilt where a neighbouring part limits it stays within atan(limit_slope)).
LocalDistances measure_local_distances(const CageBase& low, const ProbeTarget& high, double reach, double floor,
                                       double front_base, double rear_base, double need_slope, double limit_slope, int threads);

}  // namespace nmbake
