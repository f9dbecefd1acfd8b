#include "pipeline/distances.h"

#include <algorithm>
#include <atomic>
#include <vector>

#include "core/parallel.h"
#include "pipeline/rays.h"
#include "trace/auto_cage.h"

namespace nmbake {

namespace {

// How much the automatic cage's distances may change per unit length along the low-poly
// (measure_local_distances): a need falls at 45 degrees, so a bulge's need covers around it as far
// as it is tall; a neighbouring part's limit rises at atan(0.25) = 14 degrees.
constexpr double kNeedSlope = 1.0;
constexpr double kLimitSlope = 0.25;
// How far the distance probes look, as a share of the scene diagonal: farther is another part of
// the model. (A bulge of 15% of the diagonal, the hard-asset bench's tallest, is within it.)
constexpr double kProbeReach = 0.2;

double quantile(std::vector<float>& v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, std::size_t(q * double(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

// A summary of per-vertex distances.
void summarize(const std::vector<float>& v, BakeStats::Range& out) {
  if (v.empty()) return;
  double sum = 0.0;
  out.min = out.max = v[0];
  for (float x : v) {
    out.min = std::min(out.min, double(x));
    out.max = std::max(out.max, double(x));
    sum += x;
  }
  out.mean = sum / double(v.size());
}

// The scene-wide probes: pairs of rays from points of the low-poly out and in along its ray
// normals. They decide which way the high-poly's faces point (for the hit rule) and, when
// measuring, the distances for the whole scene (returned as front, rear; 0 when not measured).
// With match groups each probe sees only its own group's high-poly, as the bake's rays do (what
// another object's high-poly shows them, its inside or its nearness, is not what they will meet),
// and objects without a match are not probed (their texels are written flat).
std::pair<double, double> probe_scene(const ReachMode& mode, const BakeOptions& opt, int threads, const Prepared& s,
                                      const HighScene& h, const RayGroups& groups, BakeStats& st) {
  const std::vector<LowTriangle>& low_tris = s.low_tris;
  double global_front = 0.0, global_rear = 0.0;  // measured for the whole scene
  if (mode.probing || !opt.keep_backfaces) {
    const std::size_t tris = low_tris.size();
    const std::size_t stride = std::max<std::size_t>(1, tris / (mode.probing ? 50000 : 5000));
    static const double probe_bary[4][3] = {
        {1 / 3.0, 1 / 3.0, 1 / 3.0}, {4 / 6.0, 1 / 6.0, 1 / 6.0}, {1 / 6.0, 4 / 6.0, 1 / 6.0}, {1 / 6.0, 1 / 6.0, 4 / 6.0}};
    // The probed triangles, then their rays (an outward and an inward one per point, 8 per
    // triangle) made on every thread in that order.
    std::vector<std::uint32_t> probed;
    for (std::size_t t = 0; t < tris; t += stride)
      if (!(groups.active() && groups.low[t] == kNoMatch)) probed.push_back(std::uint32_t(t));
    constexpr std::size_t kPerTriangle = 2 * 4;
    std::vector<raycast::Ray> rays(kPerTriangle * probed.size());
    std::vector<std::uint32_t> ray_group(groups.active() ? rays.size() : 0);
    parallel_chunks(threads, probed.size(), 1024, [&](std::size_t begin, std::size_t end) {
      for (std::size_t k = begin; k < end; ++k) {
        const std::uint32_t t = probed[k];
        raycast::Ray* r = &rays[kPerTriangle * k];
        for (const auto& b : probe_bary) {
          const glm::dvec3 p = low_point(low_tris[t], b), n = low_ray_normal(low_tris[t], b);
          *r++ = {glm::vec3(p), 0.0f, glm::vec3(n), float(mode.reach)};
          *r++ = {glm::vec3(p), 0.0f, glm::vec3(-n), float(mode.reach)};
        }
        if (groups.active()) std::fill_n(&ray_group[kPerTriangle * k], kPerTriangle, groups.low[t]);
      }
    });
    std::vector<raycast::Hit> hits(rays.size());
    const std::size_t pairs = rays.size() / 2;
    // A back face: its front (by its normals) faces away from the low-poly's outside, +direction
    // of the outward probe (the first of a pair). Found for each chunk's hits on its thread.
    std::vector<std::uint8_t> is_back(rays.size(), 0);
    const ProbeTarget target{&*h.scene, h.positions, h.index, h.facing};
    std::atomic<std::size_t> next{0};
    run_parallel(threads, [&](int) {
      for (std::size_t i; (i = next.fetch_add(4096)) < pairs;) {
        const std::size_t n = std::min<std::size_t>(4096, pairs - i);
        intersect_first(*h.scene, &rays[2 * i], &hits[2 * i], 2 * n, groups.active() ? groups.high.data() : nullptr,
                        groups.active() ? &ray_group[2 * i] : nullptr);
        for (std::size_t j = 2 * i; j < 2 * (i + n); ++j)
          if (hits[j].hit()) is_back[j] = front_along(target, hits[j].triangle, rays[j & ~std::size_t(1)].direction) < 0.0f;
      }
    });
    std::size_t nearest_back = 0, probes_hit = 0;
    for (std::size_t i = 0; i < pairs; ++i) {  // how the faces point: by the nearest hit either way
      const raycast::Hit &o = hits[2 * i], &in = hits[2 * i + 1];
      if (!o.hit() && !in.hit()) continue;
      ++probes_hit;
      nearest_back += o.hit() && (!in.hit() || o.t <= in.t) ? is_back[2 * i] : is_back[2 * i + 1];
    }
    st.distances.backface_probe_share = probes_hit ? double(nearest_back) / double(probes_hit) : 0.0;
    if (!opt.keep_backfaces) {
      st.distances.high_facing = st.distances.backface_probe_share > kInvertedShare ? BakeStats::HighFacing::inverted
                                 : st.distances.backface_probe_share > kMixedShare  ? BakeStats::HighFacing::mixed
                                                                                    : BakeStats::HighFacing::sound;
      st.distances.backfaces_skipped = st.distances.high_facing != BakeStats::HighFacing::mixed;
    }
    // How far the high-poly lies: by the nearest hit either way that the rays may take (with back
    // faces skipped, not a back face as the faces were found to point: that is another part's inside).
    const std::uint8_t back_is = st.distances.high_facing == BakeStats::HighFacing::inverted ? 0 : 1;
    std::vector<float> outside, inside;
    for (std::size_t i = 0; i < pairs; ++i) {
      const raycast::Hit &o = hits[2 * i], &in = hits[2 * i + 1];
      const bool o_ok = o.hit() && !(st.distances.backfaces_skipped && is_back[2 * i] == back_is);
      const bool in_ok = in.hit() && !(st.distances.backfaces_skipped && is_back[2 * i + 1] == back_is);
      if (o_ok && (!in_ok || o.t <= in.t)) outside.push_back(o.t);
      else if (in_ok) inside.push_back(in.t);
    }
    if (mode.probing) {
      st.distances.auto_distances = true;
      // Cover all but the farthest 0.1% of probes, with a 25% margin and a floor for coincident meshes.
      global_front = 1.25 * quantile(outside, 0.999) + mode.floor;
      global_rear = 1.25 * quantile(inside, 0.999) + mode.floor;
      st.distances.scene_front = global_front;
      st.distances.scene_rear = global_rear;
    }
    if (mode.auto_distances) {
      const double front = global_front, rear = global_rear;
      if (opt.front < 0.0f) st.distances.front = float(front);
      if (opt.rear < 0.0f) st.distances.rear = float(rear);
      std::size_t beyond = 0;
      for (float d : outside) beyond += d > st.distances.front;
      for (float d : inside) beyond += d > st.distances.rear;
      st.distances.auto_probe_beyond = pairs ? double(beyond) / double(pairs) : 0.0;
    }
  }
  return {global_front, global_rear};
}

}  // namespace

ReachMode ReachMode::of(const BakeOptions& opt, const Mesh* cage, const Prepared& s) {
  ReachMode m;
  m.auto_cage = !cage && opt.front < 0.0f && opt.rear < 0.0f;
  m.auto_distances = !cage && !m.auto_cage && (opt.front < 0.0f || opt.rear < 0.0f);
  m.local_rear = m.auto_cage || (cage && opt.rear < 0.0f);
  m.probing = m.auto_distances || m.local_rear;
  m.file_cage = cage != nullptr;
  m.any_cage = m.file_cage || m.auto_cage;
  m.reach = kProbeReach * s.diagonal;
  m.floor = 1e-4 * s.diagonal;
  return m;
}

void measure_reach(const ReachMode& mode, const Mesh& low, const BakeOptions& opt, int threads, Prepared& s, HighScene& h,
                   BakeResult& result) {
  BakeStats& st = result.stats;
  st.distances.front = opt.front;
  st.distances.rear = opt.rear;
  const RayGroups groups = ray_groups(s, h, opt);
  const auto [global_front, global_rear] = probe_scene(mode, opt, threads, s, h, groups, st);
  if (st.distances.high_facing == BakeStats::HighFacing::inverted) turn_inverted_high(s, h, st.prepare.high_normals_computed());
  if (mode.local_rear) {
    // Per-vertex distances (after the facing decision: the probes judge faces by it).
    const LocalDistances ld =
        measure_local_distances({&s.low_pos, &low.position_index, &s.ray_normal, groups.active() ? &groups.low : nullptr},
                                {&*h.scene, h.positions, h.index, h.facing, groups.active() ? groups.high.data() : nullptr},
                                mode.reach, mode.floor, global_front, global_rear, kNeedSlope, kLimitSlope, threads);
    st.distances.auto_distances = true;
    st.distances.cage_front_limited = mode.auto_cage ? ld.front_limited : 0;
    st.distances.cage_rear_limited = ld.rear_limited;
    result.vertex_rear = ld.rear;
    result.vertex_search = ld.search;
    if (mode.auto_cage) {
      // The cage: every vertex moved along its ray normal by its front distance, in the meshes'
      // own coordinates (float, as a cage file holds them), then re-centred like a file's.
      result.cage_positions.resize(low.positions.size());
      for (std::size_t i = 0; i < low.positions.size(); ++i)
        result.cage_positions[i] = glm::vec3(glm::dvec3(low.positions[i]) + double(ld.front[i]) * glm::dvec3(s.ray_normal[i]));
      attach_cage(s, result.cage_positions, low.position_index);
    }
    summarize(mode.auto_cage ? ld.front : std::vector<float>(), st.distances.vertex_front);
    summarize(ld.rear, st.distances.vertex_rear);
    if (mode.auto_cage) st.distances.front = float(st.distances.vertex_front.max);
    st.distances.rear = float(st.distances.vertex_rear.max);
  }
  st.distances.cage = mode.file_cage   ? BakeStats::CageSource::file
                      : mode.auto_cage ? BakeStats::CageSource::automatic
                                       : BakeStats::CageSource::none;
  if (mode.any_cage) set_cage_reach(s, low, st.distances.rear, result.vertex_rear, result.vertex_search);
  if (mode.file_cage && st.distances.front < 0.0f) st.distances.front = 0.0f;
}

}  // namespace nmbake
