// Stage 4 of the bake, BVH: the high-poly triangles some ray can reach (select.h) in Embree's
// BVH, with per-triangle arrays (vertex indices, corner normals, facing codes) in the BVH's own
// order, so a hit's triangle index reads them without a mapping.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "core/mesh.h"
#include "pipeline/prepare.h"
#include "pipeline/select.h"
#include "raycast.h"

namespace nmbake {

struct HighScene {
  std::shared_ptr<const raycast::Scene> scene;  // shared with later bakes through a BvhCache
  const glm::vec3* positions = nullptr;         // re-centred, Prepared::high_pos
  // 3 vertex indices, 3 corner normals and a facing code per BVH triangle. They point into the
  // mesh and Prepared, or, when some triangles are left out, into the kept_ copies.
  const std::uint32_t* index = nullptr;
  const glm::vec3* normals = nullptr;
  const std::int8_t* facing = nullptr;
  std::size_t triangles = 0;
  raycast::BuildQuality quality = raycast::BuildQuality::medium;
  std::vector<std::uint32_t> kept_index;
  CornerNormals kept_normals;
  std::vector<std::int8_t> kept_facing;
  // Per BVH triangle, its high-poly object (Mesh::triangle_object), or null: one object.
  const std::uint32_t* object = nullptr;
  std::vector<std::uint32_t> kept_object;

  // The rule the trace applies to hits (raycast::HitRule) over these triangles.
  raycast::HitRule hit_rule() const {
    raycast::HitRule rule;
    rule.facing = facing;
    rule.corner_normals = normals;
    return rule;
  }
};

// The match groups of a bake (BakeOptions::low_object_group, high_object_group) as rays and hits
// read them: per low-poly triangle and per BVH triangle; both empty without matching.
struct RayGroups {
  std::vector<std::uint32_t> low, high;
  bool active() const { return !low.empty(); }
};
RayGroups ray_groups(const Prepared& s, const HighScene& h, const BakeOptions& opt);

// The rule the trace casts under, or null for none: h.hit_rule() when back faces are skipped
// (BakeStats::Distances::backfaces_skipped); with match groups, the groups too (alone when back faces are
// kept). `rule` holds it.
const raycast::HitRule* trace_rule(const HighScene& h, bool backfaces_skipped, const RayGroups& groups, raycast::HitRule& rule);

// Builds (or rebuilds) `h` over the high-poly triangles `kept` (increasing; empty: all of them).
// With `reuse`, its BVH (built over the same triangles `kept`, on the same centre) is taken instead.
// With `share`, Embree reads the positions and indices in place (raycast::Scene's share_buffers):
// only for a BVH that lives no longer than `s`, `high` and `h` (not one a BvhCache keeps).
void build_high_scene(HighScene& h, const Prepared& s, const Mesh& high, const std::vector<std::uint32_t>& kept,
                      raycast::BuildQuality quality, int threads, std::shared_ptr<const raycast::Scene> reuse = nullptr,
                      bool share = false);

// The BVH build quality a bake with these options picks for `triangles` high-poly triangles (after
// culling): with fewer than 16 rays per triangle the quick Morton build wins end to end (its
// build saves more than its slower trace costs); with 16 or more, the high-quality build's faster
// trace wins (docs/bench.md).
raycast::BuildQuality bvh_quality_for(const BakeOptions& options, std::size_t triangles);

// "low", "medium" or "high" (BakeStats::Bvh::quality).
const char* quality_name(raycast::BuildQuality quality);

// A BVH a BvhCache keeps (bake.h) and what it was built from. Keyed by content, not by address: a
// hash of the re-centred positions and vertex indices the BVH reads (bvh_content), and the centre
// and diagonal of the scene they were re-centred in.
struct KeptBvh {
  std::uint64_t content = 0;
  glm::dvec3 centre{0.0};
  double diagonal = 0.0;
  HighSelection selection;  // the triangles in it
  std::shared_ptr<const raycast::Scene> scene;
  raycast::BuildQuality quality = raycast::BuildQuality::medium;
};

// KeptBvh::content of this scene's high-poly: a 64-bit hash of s.high_pos and high.position_index,
// one pass over 18 bytes a triangle (a BVH build reads them many times over).
std::uint64_t bvh_content(const Prepared& s, const Mesh& high);

// The one way to a kept BVH: the one `cache` keeps when it was built from the same content, on the
// same centre and diagonal, else null (also for a null or empty cache).
const KeptBvh* find_kept_bvh(const BvhCache* cache, const Prepared& s, std::uint64_t content);

// The high-poly found inverted (BakeStats::HighFacing): fronts are taken the other way round, and
// normals nmbake computed itself are turned outwards with them (a file's normals are kept: the map
// then is what it was without the rule). Applies to the BVH's copies too.
void turn_inverted_high(Prepared& s, HighScene& h, bool normals_computed);

}  // namespace nmbake
