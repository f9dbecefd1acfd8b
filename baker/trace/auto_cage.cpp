#include "trace/auto_cage.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <utility>

#include "core/mesh_topology.h"
#include "core/parallel.h"

namespace nmbake {

namespace {

// How far (radians) rays between two corners may lean from the ray normals where a neighbouring
// part limits one corner's front distance (ease): 20 degrees. Only edges whose ray normals differ
// by more than twice that are bound (a coarse part of fewer than 9 sides): along gentler ones the
// distances' weighting cannot lean rays that far. Chosen on the generated thin parts
// (tests/procedural/thin_parts.h): a tighter bound cost appearance, a looser one left suspect
// texels on three-sided legs.
constexpr double kMaxTilt = 0.349;
// How many points the dense probes of a low-poly with few triangles take in all (make_probes): the
// full 8 x 8 grid up to kDenseProbes / 64 triangles (the coarse parts this is for), beyond that a
// quarter of it, so a low-poly of a few thousand triangles pays for its edge midpoints only.
constexpr double kDenseProbes = 100000.0;
constexpr double kDenseProbesFiner = 25000.0;

// A point the probes start from, the unit direction they go (out: +dir, in: -dir), and the welded
// vertices its findings count for.
struct Probe {
  glm::dvec3 p, n;
  std::uint32_t v[3];
  int nv;
  std::uint32_t group;  // its triangle's match group (0 without groups)
  bool need_only;       // measures how far the high-poly lies, not how far the next part is
};

glm::dvec3 unit_or_face(const glm::dvec3& n, const glm::dvec3& p0, const glm::dvec3& p1, const glm::dvec3& p2) {
  const double len = glm::length(n);
  if (len > 1e-12) return n / len;
  const glm::dvec3 f = glm::cross(p1 - p0, p2 - p0);
  const double fl = glm::length(f);
  return fl > 0.0 ? f / fl : glm::dvec3(0, 0, 1);
}

// An edge of the welded low-poly: the other end, the length, and, where the ray normals at its ends
// differ by more than twice kMaxTilt (a coarse part's sharp edge, the only ones tilt_ratio bounds),
// the index of that angle in Adjacency::sharp_angle (kNotSharp otherwise: 16 bytes an edge end,
// as many as a low-poly of a million triangles keeps six million of).
constexpr std::uint32_t kNotSharp = std::numeric_limits<std::uint32_t>::max();
struct Edge {
  std::uint32_t to;
  std::uint32_t sharp;
  double length;
};
struct Adjacency {
  std::vector<std::vector<Edge>> edges;  // per welded vertex
  std::vector<double> sharp_angle;       // radians, between the ray normals at the ends
};

// The largest ratio of the front distances at an edge's ends that keeps the rays between them
// within `tilt` (radians) of the ray normals: a cage point interpolates the corners moved by
// their distances, so P - cage leans towards the corner moved farther, by about
// (angle / 2) (f1 - f0) / (f1 + f0) half way along the edge (infinity: no bound needed).
double tilt_ratio(double angle, double tilt) {
  const double k = 2.0 * tilt / angle;
  return k >= 1.0 ? std::numeric_limits<double>::infinity() : (1.0 + k) / (1.0 - k);
}

// Over the edges: raises values so that none is more than slope x length below a neighbour's
// (spread = true, from the largest down), or lowers them so that none is more than slope x length
// above a neighbour's (spread = false, from the smallest up), nor, with `tilt`, more than
// tilt_ratio(angle, kMaxTilt) times it. Exact, in one pass of a heap.
void ease(std::vector<double>& value, const Adjacency& adjacent, double slope, bool spread, bool tilt = false) {
  using Item = std::pair<double, std::uint32_t>;
  auto cmp = [spread](const Item& a, const Item& b) { return spread ? a.first < b.first : a.first > b.first; };
  std::priority_queue<Item, std::vector<Item>, decltype(cmp)> heap(cmp);
  for (std::uint32_t v = 0; v < value.size(); ++v) heap.push({value[v], v});
  while (!heap.empty()) {
    const auto [val, v] = heap.top();
    heap.pop();
    if (val != value[v]) continue;  // stale
    for (const Edge& e : adjacent.edges[v]) {
      const std::uint32_t u = e.to;
      double bound = spread ? val - slope * e.length : val + slope * e.length;
      if (!spread && tilt && e.sharp != kNotSharp)
        bound = std::min(bound, val * tilt_ratio(adjacent.sharp_angle[e.sharp], kMaxTilt));
      if (spread ? bound > value[u] : bound < value[u]) {
        value[u] = bound;
        heap.push({bound, u});
      }
    }
  }
}

std::uint32_t group_of(const CageBase& low, std::size_t triangle) { return low.group ? (*low.group)[triangle] : 0u; }

// Positions welded by value, and with groups, apart where their groups differ (a position takes
// the group of the first triangle that uses it).
std::vector<std::uint32_t> weld_in_groups(const CageBase& low, std::size_t* count) {
  std::vector<std::uint32_t> weld = weld_positions(*low.positions, count);
  if (!low.group) return weld;
  const std::vector<std::uint32_t>& index = *low.index;
  const std::uint32_t unset = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> group(low.positions->size(), unset);
  for (std::size_t c = 0; c < index.size(); ++c)
    if (group[index[c]] == unset) group[index[c]] = group_of(low, c / 3);
  std::vector<std::pair<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t>> keys(weld.size());
  for (std::uint32_t p = 0; p < weld.size(); ++p) keys[p] = {{weld[p], group[p]}, p};
  std::sort(keys.begin(), keys.end());
  std::size_t n = 0;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    if (k > 0 && keys[k].first != keys[k - 1].first) ++n;
    weld[keys[k].second] = std::uint32_t(n);
  }
  *count = keys.empty() ? 0 : n + 1;
  return weld;
}

// Per welded vertex values to per position (file vertex), as floats.
std::vector<float> per_position(const std::vector<double>& welded, const std::vector<std::uint32_t>& weld) {
  std::vector<float> out(weld.size());
  for (std::size_t p = 0; p < weld.size(); ++p) out[p] = float(welded[weld[p]]);
  return out;
}

// Probes: one at every welded vertex a face uses, and at the centre and near each corner of
// every triangle (all three corners hear of these: the cage between them must cover them).
std::vector<Probe> make_probes(const CageBase& low, const std::vector<std::uint32_t>& weld, std::size_t nw) {
  const std::vector<glm::vec3>& pos = *low.positions;
  const std::vector<std::uint32_t>& index = *low.index;
  const std::vector<glm::vec3>& rn = *low.ray_normals;
  const std::size_t tris = index.size() / 3;
  std::vector<Probe> probes;
  {
    std::vector<std::uint8_t> seen(nw, 0);
    for (std::size_t c = 0; c < index.size(); ++c) {
      const std::uint32_t pi = index[c], w = weld[pi];
      if (seen[w]) continue;
      seen[w] = 1;
      probes.push_back({glm::dvec3(pos[pi]), glm::normalize(glm::dvec3(rn[pi])), {w, w, w}, 1, group_of(low, c / 3), false});
    }
  }
  const std::size_t stride = std::max<std::size_t>(1, tris / 50000);
  static const double bary[4][3] = {
      {1 / 3.0, 1 / 3.0, 1 / 3.0}, {4 / 6.0, 1 / 6.0, 1 / 6.0}, {1 / 6.0, 4 / 6.0, 1 / 6.0}, {1 / 6.0, 1 / 6.0, 4 / 6.0}};
  auto add = [&](std::size_t t, const double b[3], bool need_only) {
    const std::uint32_t* c = &index[3 * t];
    const glm::dvec3 p0(pos[c[0]]), p1(pos[c[1]]), p2(pos[c[2]]);
    const glm::dvec3 p = b[0] * p0 + b[1] * p1 + b[2] * p2;
    const glm::dvec3 n = b[0] * glm::dvec3(rn[c[0]]) + b[1] * glm::dvec3(rn[c[1]]) + b[2] * glm::dvec3(rn[c[2]]);
    probes.push_back({p, unit_or_face(n, p0, p1, p2), {weld[c[0]], weld[c[1]], weld[c[2]]}, 3, group_of(low, t), need_only});
  };
  for (std::size_t t = 0; t < tris; t += stride)
    for (const auto& b : bary) add(t, b, false);
  // A coarse low-poly's long triangles and edges span detail of the high-poly that the points
  // above step over (a valley between two rings of a decimated leg, under the ridge that joins
  // them): where the low-poly has few triangles, a grid of n x n sub-triangles' corners over each
  // (about kDenseProbes points in all) measures the needs too.
  const double budget = double(tris) * 64.0 <= kDenseProbes ? kDenseProbes : kDenseProbesFiner;
  const int n = int(std::min(8.0, std::floor(std::sqrt(budget / double(std::max<std::size_t>(tris, 1))))));
  for (std::size_t t = 0; n >= 2 && t < tris; ++t)
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        if (i == n || j == n || i + j == 0) continue;  // the corners: probed as vertices
        const double b[3] = {double(i) / n, double(j) / n, double(n - i - j) / n};
        add(t, b, true);
      }
  return probes;
}

// Per low-poly triangle: 1 when its winding agrees with its ray normals, else -1.
std::vector<std::int8_t> facing_of(const CageBase& low) {
  const std::vector<glm::vec3>& pos = *low.positions;
  const std::vector<std::uint32_t>& index = *low.index;
  const std::vector<glm::vec3>& rn = *low.ray_normals;
  const std::size_t tris = index.size() / 3;
  std::vector<std::int8_t> facing(tris, 1);
  for (std::size_t t = 0; t < tris; ++t) {
    const glm::dvec3 p0(pos[index[3 * t]]), p1(pos[index[3 * t + 1]]), p2(pos[index[3 * t + 2]]);
    const glm::dvec3 n = glm::dvec3(rn[index[3 * t]]) + glm::dvec3(rn[index[3 * t + 1]]) + glm::dvec3(rn[index[3 * t + 2]]);
    if (glm::dot(glm::cross(p1 - p0, p2 - p0), n) < 0.0) facing[t] = -1;
  }
  return facing;
}

// Per welded vertex, its edges along the low-poly.
Adjacency welded_edges(const CageBase& low, const std::vector<std::uint32_t>& weld, std::size_t nw) {
  const std::vector<glm::vec3>& pos = *low.positions;
  const std::vector<std::uint32_t>& index = *low.index;
  Adjacency adjacent;
  adjacent.edges.resize(nw);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  for (std::size_t t = 0; t < index.size() / 3; ++t)
    for (int c = 0; c < 3; ++c) {
      std::uint32_t a = weld[index[3 * t + c]], b = weld[index[3 * t + (c + 1) % 3]];
      if (a == b) continue;
      if (a > b) std::swap(a, b);
      edges.push_back({a, b});
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<glm::dvec3> wpos(nw), wn(nw);
  for (std::size_t p = 0; p < pos.size(); ++p) {
    wpos[weld[p]] = glm::dvec3(pos[p]);
    wn[weld[p]] = glm::normalize(glm::dvec3((*low.ray_normals)[p]));
  }
  for (const auto& [a, b] : edges) {
    const double len = glm::length(wpos[a] - wpos[b]);
    const double angle = std::acos(std::clamp(glm::dot(wn[a], wn[b]), -1.0, 1.0));
    std::uint32_t sharp = kNotSharp;
    if (std::isfinite(tilt_ratio(angle, kMaxTilt))) {
      sharp = std::uint32_t(adjacent.sharp_angle.size());
      adjacent.sharp_angle.push_back(angle);
    }
    adjacent.edges[a].push_back({b, sharp, len});
    adjacent.edges[b].push_back({a, sharp, len});
  }
  return adjacent;
}

}  // namespace

void intersect_first(const raycast::Scene& scene, const raycast::Ray* rays, raycast::Hit* hits, std::size_t count,
                     const std::uint32_t* triangle_group, const std::uint32_t* ray_group) {
  if (!triangle_group) return scene.intersect(rays, hits, count);
  raycast::RayArrays arrays(rays, count);
  raycast::RayBatch batch = arrays.rays();
  batch.group = ray_group;
  raycast::HitRule rule;
  rule.skip_backfaces = false;  // every face counts, as without a rule
  rule.group = triangle_group;
  scene.intersect(batch, arrays.hits(), count, &rule);
  for (std::size_t i = 0; i < count; ++i) hits[i] = arrays.hit(i);
}

LocalDistances measure_local_distances(const CageBase& low, const ProbeTarget& high, double reach, double floor,
                                       double front_base, double rear_base, double need_slope, double limit_slope, int threads) {
  const std::vector<glm::vec3>& pos = *low.positions;
  const std::vector<std::uint32_t>& index = *low.index;
  const std::size_t tris = index.size() / 3;
  LocalDistances out;
  std::size_t nw = 0;
  const std::vector<std::uint32_t> weld = weld_in_groups(low, &nw);
  out.vertices = nw;

  const std::vector<Probe> probes = make_probes(low, weld, nw);
  out.probes = probes.size();

  // The low-poly itself, for the distance to its next part along the normal: only surfaces that
  // face the probe's start count (the probe's own part, left through its far side, does not).
  const std::vector<std::int8_t> low_facing = facing_of(low);
  const raycast::Scene self(&pos[0].x, pos.size(), index.data(), tris, raycast::BuildQuality::low, threads);
  raycast::HitRule facing_start;  // an "inward" ray under this rule takes surfaces facing its start
  facing_start.facing = low_facing.data();
  facing_start.group = low.group ? low.group->data() : nullptr;
  raycast::HitRule high_facing_start;
  high_facing_start.facing = high.facing;
  high_facing_start.group = high.group;

  // Per probe: the distances found (infinity: none). Front/rear needs from the high-poly's first
  // hits that face the low-poly's outside; limits from the low-poly.
  const double inf = std::numeric_limits<double>::infinity();
  // high_back_out: where a next part of the low-poly lies along the normal, the first high-poly
  // surface before the half-way point that faces back at the probe (that part's, standing out).
  std::vector<double> high_back_out(probes.size(), inf);
  std::vector<double> need_out(probes.size(), inf), need_in(probes.size(), inf), gap_out(probes.size(), inf),
      gap_in(probes.size(), inf);
  const float tnear = float(1e-2 * floor);
  const float inf_f = std::numeric_limits<float>::infinity();
  parallel_chunks(threads, probes.size(), 1024, [&](std::size_t i0, std::size_t i1) {
    std::vector<raycast::Ray> rays;
    std::vector<std::uint32_t> ray_group;
    rays.reserve(2 * (i1 - i0));
    for (std::size_t i = i0; i < i1; ++i) {
      rays.push_back({glm::vec3(probes[i].p), 0.0f, glm::vec3(probes[i].n), float(reach)});
      rays.push_back({glm::vec3(probes[i].p), 0.0f, glm::vec3(-probes[i].n), float(reach)});
      if (high.group) ray_group.insert(ray_group.end(), 2, probes[i].group);
    }
    std::vector<raycast::Hit> hits(rays.size());
    intersect_first(*high.scene, rays.data(), hits.data(), rays.size(), high.group, high.group ? ray_group.data() : nullptr);
    for (std::size_t i = i0; i < i1; ++i)
      for (int k = 0; k < 2; ++k) {
        const raycast::Hit& h = hits[2 * (i - i0) + k];
        if (!h.hit()) continue;
        // The low-poly's outside is +n: a front face there is the surface the probe looks for.
        if (front_along(high, h.triangle, glm::vec3(probes[i].n)) > 0.0f) (k == 0 ? need_out : need_in)[i] = h.t;
      }
    for (std::size_t i = 0; i < rays.size(); ++i) {
      // The surface around the probe is its own part, however it folds: triangles that share a
      // vertex with the probe's (a concave crease's other side) are looked past.
      const Probe& pr = probes[i0 + i / 2];
      if (pr.need_only) continue;
      raycast::Ray r = rays[i];
      r.tnear = tnear;
      for (int tries = 0; tries < 8; ++tries) {
        const raycast::Hit h = self.intersect(r, facing_start, false, nullptr, 0.0f, inf_f, pr.group);
        if (!h.hit()) break;
        bool near = false;
        for (int c = 0; c < 3 && !near; ++c)
          for (int j = 0; j < pr.nv; ++j) near |= weld[index[3 * std::size_t(h.triangle) + c]] == pr.v[j];
        if (!near) {
          (i % 2 == 0 ? gap_out : gap_in)[i0 + i / 2] = h.t;
          break;
        }
        r.tnear = std::nextafter(h.t, std::numeric_limits<float>::infinity());
      }
    }
    // Towards a next part: its high-poly surface facing back at the probe, before half way (this
    // part's own surface, met from inside, is passed over: an "inward" ray under the rule takes
    // the surfaces that face its start).
    for (std::size_t i = i0; i < i1; ++i) {
      if (!(gap_out[i] < inf)) continue;
      const raycast::Ray r{glm::vec3(probes[i].p), tnear, glm::vec3(probes[i].n), float(0.5 * gap_out[i])};
      const raycast::Hit h = high.scene->intersect(r, high_facing_start, false, nullptr, 0.0f, inf_f, probes[i].group);
      if (h.hit()) high_back_out[i] = h.t;
    }
  });

  // Per welded vertex: the largest need and the smallest limit its probes found.
  std::vector<double> front(nw, std::max(floor, front_base)), rear(nw, std::max(floor, rear_base)), front_cap(nw, reach),
      rear_cap(nw, reach);
  for (std::size_t i = 0; i < probes.size(); ++i)
    for (int j = 0; j < probes[i].nv; ++j) {
      const std::uint32_t w = probes[i].v[j];
      if (need_out[i] < inf) front[w] = std::max(front[w], 1.25 * need_out[i] + floor);
      if (need_in[i] < inf) rear[w] = std::max(rear[w], 1.25 * need_in[i] + floor);
      front_cap[w] = std::min(front_cap[w], 0.5 * gap_out[i]);
      // Nor past the high-poly surface of that next part, where it stands out towards this one
      // beyond the half-way point. (With no next part of the low-poly along the normal, a surface
      // facing back is this part's own overhang, whose lip the cage must pass: not looked for.)
      front_cap[w] = std::min(front_cap[w], 0.9 * high_back_out[i]);
      rear_cap[w] = std::min(rear_cap[w], 0.5 * gap_in[i]);
    }

  // Neither spikes nor notches: along every edge a need falls by at most need_slope times the
  // edge's length (it reaches as far around as it is tall), and a limit rises by at most
  // limit_slope times it (a neighbouring part's limit fades out gently).
  const Adjacency adjacent = welded_edges(low, weld, nw);
  ease(front, adjacent, need_slope, true);
  ease(rear, adjacent, need_slope, true);
  ease(front_cap, adjacent, limit_slope, false, true);
  ease(rear_cap, adjacent, limit_slope, false);
  const std::vector<double> search = front;
  for (std::size_t w = 0; w < nw; ++w) {
    out.front_limited += front_cap[w] < front[w];
    out.rear_limited += rear_cap[w] < rear[w];
    front[w] = std::max(floor, std::min(front[w], front_cap[w]));
    rear[w] = std::max(floor, std::min(rear[w], rear_cap[w]));
  }
  out.search = per_position(search, weld);
  out.front = per_position(front, weld);
  out.rear = per_position(rear, weld);
  return out;
}

}  // namespace nmbake
