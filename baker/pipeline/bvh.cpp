#include "pipeline/bvh.h"

#include <functional>
#include <string_view>

#include "core/parallel.h"

namespace nmbake {

raycast::BuildQuality bvh_quality_for(const BakeOptions& o, std::size_t triangles) {
  const double rays = double(o.width) * double(o.height) * double(o.samples);
  return rays < 16.0 * double(triangles) ? raycast::BuildQuality::low : raycast::BuildQuality::high;
}

const char* quality_name(raycast::BuildQuality q) {
  return q == raycast::BuildQuality::low ? "low" : q == raycast::BuildQuality::medium ? "medium" : "high";
}

std::uint64_t bvh_content(const Prepared& s, const Mesh& high) {
  const auto bytes = [](const auto& v) {
    return std::hash<std::string_view>{}({reinterpret_cast<const char*>(v.data()), v.size() * sizeof(v[0])});
  };
  return bytes(s.high_pos) * 0x9e3779b97f4a7c15ull ^ bytes(high.position_index);
}

const KeptBvh* find_kept_bvh(const BvhCache* cache, const Prepared& s, std::uint64_t content) {
  const KeptBvh* k = cache ? cache->kept.get() : nullptr;
  return k && k->content == content && k->centre == s.centre && k->diagonal == s.diagonal ? k : nullptr;
}

void build_high_scene(HighScene& h, const Prepared& s, const Mesh& high, const std::vector<std::uint32_t>& kept,
                      raycast::BuildQuality quality, int threads, std::shared_ptr<const raycast::Scene> reuse, bool share) {
  h.scene.reset();  // before the arrays a shared BVH reads change
  h.positions = s.high_pos.data();
  h.index = high.position_index.data();
  h.normals = s.high_corner_normals.data();
  h.facing = s.high_facing.data();
  h.kept_index.clear();
  h.kept_normals.clear();
  h.kept_facing.clear();
  h.kept_object.clear();
  h.object = high.triangle_object.empty() ? nullptr : high.triangle_object.data();
  if (!kept.empty()) {
    std::vector<std::uint32_t> index(3 * kept.size());
    CornerNormals normals(3 * kept.size());
    std::vector<std::int8_t> facing(kept.size());
    parallel_chunks(threads, kept.size(), std::size_t(1) << 16, [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        for (int c = 0; c < 3; ++c) {
          index[3 * i + c] = high.position_index[3 * std::size_t(kept[i]) + c];
          normals[3 * i + c] = s.high_corner_normals[3 * std::size_t(kept[i]) + c];
        }
        facing[i] = s.high_facing[kept[i]];
      }
    });
    h.kept_index = std::move(index);
    h.kept_normals = std::move(normals);
    h.kept_facing = std::move(facing);
    h.index = h.kept_index.data();
    h.normals = h.kept_normals.data();
    h.facing = h.kept_facing.data();
    if (h.object) {
      h.kept_object.resize(kept.size());
      for (std::size_t i = 0; i < kept.size(); ++i) h.kept_object[i] = high.triangle_object[kept[i]];
      h.object = h.kept_object.data();
    }
  }
  h.triangles = kept.empty() ? high.triangle_count() : kept.size();
  h.quality = quality;
  // Embree may read the positions in place where Prepared keeps room for its 16-byte loads past the
  // last vertex (prepare.cpp reserves it).
  share = share && s.high_pos.capacity() > s.high_pos.size();
  h.scene = reuse ? std::move(reuse)
                  : std::make_shared<const raycast::Scene>(&s.high_pos[0].x, s.high_pos.size(), h.index, h.triangles, quality,
                                                           threads, share);
}

RayGroups ray_groups(const Prepared& s, const HighScene& h, const BakeOptions& opt) {
  RayGroups g;
  if (opt.low_object_group.empty()) return g;
  auto group_of = [](const std::vector<std::uint32_t>& groups, std::uint32_t object) {
    return object < groups.size() ? groups[object] : kNoMatch;
  };
  g.low.resize(s.low_tris.size());
  for (std::size_t t = 0; t < g.low.size(); ++t) g.low[t] = group_of(opt.low_object_group, s.low_object ? s.low_object[t] : 0u);
  g.high.resize(h.triangles);
  // A high-poly object without a match is in no group, not even that of the unmatched low-poly rays.
  for (std::size_t t = 0; t < g.high.size(); ++t) {
    const std::uint32_t k = group_of(opt.high_object_group, h.object ? h.object[t] : 0u);
    g.high[t] = k == kNoMatch ? kNoMatch - 1 : k;
  }
  return g;
}

const raycast::HitRule* trace_rule(const HighScene& h, bool backfaces_skipped, const RayGroups& groups, raycast::HitRule& rule) {
  if (backfaces_skipped) {
    rule = h.hit_rule();
  } else if (groups.active()) {
    rule = raycast::HitRule{};
    rule.skip_backfaces = false;
  } else {
    return nullptr;
  }
  rule.group = groups.active() ? groups.high.data() : nullptr;
  return &rule;
}

void turn_inverted_high(Prepared& s, HighScene& h, bool normals_computed) {
  // A file's normals now point against the fronts: how far they lean is then unknown (127).
  for (auto* v : {&s.high_facing, &h.kept_facing})
    for (std::int8_t& f : *v) f = normals_computed ? std::int8_t(-f) : raycast::facing_code(f < 0 ? 1 : -1, 2.0);
  if (normals_computed)
    for (auto* v : {&s.high_corner_normals, &h.kept_normals})
      for (glm::vec3& n : *v) n = -n;
}

}  // namespace nmbake
