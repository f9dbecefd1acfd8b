#include "pipeline/bake.h"

#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <fstream>
#include <limits>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "trace/auto_cage.h"
#include "core/cull.h"
#include "pipeline/memory_budget.h"
#include "core/mesh_topology.h"
#include "core/normals.h"
#include "core/padding.h"
#include "core/parallel.h"
#include "core/rasterize.h"
#include "raycast.h"
#include "trace/shade_batch.h"
#include "trace/tile_kernels.h"

namespace nmbake {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

constexpr std::size_t kTilesPerGrab = 4;  // consecutive tiles a trace thread takes at once
constexpr int kTile = 16;            // texels per tile side
// Tangent components this close to zero are written as exactly 0: a flat result is then
// (128,128,255) and not a coin flip between 127 and 128 decided by float noise.
constexpr double kSnap = 1e-6;
// How much the automatic cage's distances may change per unit length along the low-poly
// (measure_local_distances): a need falls at 45 degrees, so a bulge's need covers around it as far
// as it is tall; a neighbouring part's limit rises at atan(0.25) = 14 degrees.
constexpr double kNeedSlope = 1.0;
constexpr double kLimitSlope = 0.25;
// How far the distance probes look, as a share of the scene diagonal: farther is another part of
// the model. (A bulge of 15% of the diagonal, the hard-asset bench's tallest, is within it.)
constexpr double kProbeReach = 0.2;

// A low-poly triangle's cage: its corners (re-centred), and per corner the rear distance and how
// far out rays search (LocalDistances::search; 0: to the cage only).
struct CageTriangle {
  glm::dvec3 corner[3];
  double rear[3] = {0, 0, 0}, search[3] = {0, 0, 0};
};

// The scene in re-centred float coordinates, flat arrays for the hot loop.
struct Prepared {
  glm::dvec3 centre{0.0};
  double diagonal = 0.0;
  std::vector<glm::vec3> low_pos, cage_pos, high_pos;
  std::vector<glm::vec3> ray_normal;  // per low-poly position: mean of its corners' normals
  std::vector<glm::vec3> high_corner_normals;  // 3 per high-poly triangle: one cache line per hit
  // The triangles in the BVH, in its order: vertex indices and corner normals, 3 per triangle.
  // They point into the mesh and high_corner_normals, or, after culling, into the kept_ copies.
  const std::uint32_t* bvh_index = nullptr;
  const glm::vec3* bvh_normals = nullptr;
  const std::int8_t* bvh_facing = nullptr;
  std::vector<std::uint32_t> kept_index;
  std::vector<glm::vec3> kept_normals;
  std::vector<std::int8_t> kept_facing;
  // Per high-poly triangle: the side its normals point to, +1 that of cross(p1 - p0, p2 - p0)
  // (raycast::HitRule::facing).
  std::vector<std::int8_t> high_facing;
  TangentFrames frames;
  std::vector<LowTriangle> low_tris;
  std::vector<CageTriangle> cage_tris;  // per low-poly triangle, with a cage (attach_cage, set_cage_reach)
};

// Over the positions faces use: a vertex no face uses (a stray point far away) must not move the
// centre or stretch the diagonal that scales every distance.
void grow_box(glm::dvec3& lo, glm::dvec3& hi, const std::vector<glm::vec3>& pts, const std::vector<std::uint32_t>& index) {
  for (std::uint32_t i : index) {
    lo = glm::min(lo, glm::dvec3(pts[i]));
    hi = glm::max(hi, glm::dvec3(pts[i]));
  }
}

std::vector<glm::vec3> recentre(const std::vector<glm::vec3>& pts, const glm::dvec3& c) {
  std::vector<glm::vec3> out(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) out[i] = glm::vec3(glm::dvec3(pts[i]) - c);
  return out;
}

std::vector<glm::vec3> position_averaged_normals(const Mesh& low, const TangentFrames& frames, const std::vector<std::uint32_t>& weld,
                                                 std::size_t np) {
  // A position whose corners all use one normal keeps it bit for bit; one with several gets the
  // normalized mean over its corners (a normal shared by more faces weighs more).
  std::vector<glm::vec3> out(np, glm::vec3(0, 0, 1));
  std::vector<std::uint8_t> state(np, 0);  // 0 unseen, 1 one normal so far, 2 several
  for (std::size_t c = 0; c < low.position_index.size(); ++c) {
    const std::uint32_t p = weld[low.position_index[c]];
    if (state[p] == 0) {
      state[p] = 1;
      out[p] = frames.normal[c];
    } else if (frames.normal[c] != out[p]) {
      state[p] = 2;
    }
  }
  std::vector<glm::dvec3> sum(np, glm::dvec3(0.0));
  for (std::size_t c = 0; c < low.position_index.size(); ++c)
    if (state[weld[low.position_index[c]]] == 2) sum[weld[low.position_index[c]]] += glm::dvec3(frames.normal[c]);
  for (std::size_t p = 0; p < np; ++p) {
    const double len = glm::length(sum[p]);
    if (state[p] == 2 && len > 1e-12) out[p] = glm::vec3(sum[p] / len);
  }
  return out;
}

// Ray normals: one per position, the normalized mean of its corners' normals (a normal shared by
// more corners weighs more), so split normals (hard edges) open no gaps between the rays of
// neighbouring faces. Positions are welded by value first: glTF-style files split hard edges into
// separate vertices.
std::vector<glm::vec3> position_averaged_normals(const Mesh& low, const TangentFrames& frames) {
  std::size_t np = 0;
  const std::vector<std::uint32_t> weld = weld_positions(low.positions, &np);
  const std::vector<glm::vec3> welded = position_averaged_normals(low, frames, weld, np);
  std::vector<glm::vec3> out(low.positions.size());
  for (std::size_t p = 0; p < out.size(); ++p) out[p] = welded[weld[p]];
  return out;
}

double quantile(std::vector<float>& v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, std::size_t(q * double(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

// Per triangle, its raycast::HitRule::facing code: the side its corner normals (3 per triangle)
// point to, + that of cross(p1 - p0, p2 - p0) (also where that cannot be told: no area, normals
// that cancel), and how far they lean from the face.
std::vector<std::int8_t> triangle_facing(const std::vector<glm::vec3>& pos, const std::vector<std::uint32_t>& index,
                                         const std::vector<glm::vec3>& corner_normals) {
  std::vector<std::int8_t> out(index.size() / 3);
  parallel_chunks(0, out.size(), 65536, [&](std::size_t t0, std::size_t t1) {
  for (std::size_t t = t0; t < t1; ++t) {
    const glm::vec3 p0 = pos[index[3 * t]], p1 = pos[index[3 * t + 1]], p2 = pos[index[3 * t + 2]];
    const glm::vec3* c = &corner_normals[3 * t];
    glm::vec3 f = glm::cross(p1 - p0, p2 - p0);
    const int sign = glm::dot(f, c[0] + c[1] + c[2]) < 0.0f ? -1 : 1;
    const float f2 = glm::dot(f, f);
    double lean = 2.0;  // unknown
    if (f2 > 0.0f) {
      f *= float(sign) / std::sqrt(f2);
      lean = 0.0;
      for (int k = 0; k < 3 && lean < 1.0; ++k) {
        const float n2 = glm::dot(c[k], c[k]);
        // The sine of the angle from the face, rounded up by a little for the float arithmetic;
        // a normal past 90 degrees (or of no length) leaves it unknown.
        if (!(n2 > 0.0f) || !(glm::dot(c[k], f) > 0.0f)) lean = 2.0;
        else lean = std::max(lean, double(glm::length(glm::cross(c[k], f)) / std::sqrt(n2)) + 1e-4);
      }
    }
    out[t] = raycast::facing_code(sign, lean);
  }
  });
  return out;
}

template <typename Fn>
void run_parallel(int threads, Fn&& worker) {
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(worker, i);
  worker(0);
  for (auto& t : pool) t.join();
}

// The cage's corners, re-centred, 3 per low-poly triangle (its topology is the low-poly's: 3
// position indices per triangle).
void attach_cage(Prepared& s, const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& index) {
  s.cage_pos = recentre(positions, s.centre);
  s.cage_tris.resize(index.size() / 3);
  for (std::size_t t = 0; t < s.cage_tris.size(); ++t)
    for (int c = 0; c < 3; ++c) s.cage_tris[t].corner[c] = glm::dvec3(s.cage_pos[index[3 * t + c]]);
}

// A cage must enclose the low-poly: one whose vertices mostly lie inside it (moved against the ray
// normals) is refused.
void check_cage_encloses(const Prepared& s, const Mesh& cage) {
  std::vector<std::uint8_t> used(s.low_pos.size(), 0);
  for (std::uint32_t i : cage.position_index) used[i] = 1;
  std::size_t inside = 0, outside = 0;
  const double tiny = 1e-6 * s.diagonal;
  for (std::size_t i = 0; i < used.size(); ++i) {
    if (!used[i]) continue;
    const double off = glm::dot(glm::dvec3(s.cage_pos[i]) - glm::dvec3(s.low_pos[i]), glm::dvec3(s.ray_normal[i]));
    inside += off < -tiny;
    outside += off > tiny;
  }
  if (inside > outside)
    throw InputError(cage.source + ": the cage lies inside the low-poly (" + std::to_string(inside) + " of " +
                     std::to_string(inside + outside) + " moved vertices are moved inwards along the normals); a cage must enclose it");
}

// Suspect texels (BakeStats::suspect_texels) from the map before padding and the texels whose
// samples disagree; their mask and the UV region most of them lie in.
void find_suspects(const BakeOptions& opt, const std::vector<std::uint8_t>& disagree, BakeResult& result) {
  BakeStats& st = result.stats;
  const int W = opt.width, H = opt.height;
  // The encoded z of a tangent-space normal tilted kSuspectTiltDeg from (0, 0, 1).
  const float z_limit = float(0.5 + 0.5 * std::cos(kSuspectTiltDeg * 3.14159265358979323846 / 180.0));
  if (opt.suspect_mask) result.suspect_mask = Image(W, H, 1, 0.0f);
  std::size_t cells[8][8] = {};
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const std::size_t i = std::size_t(y) * W + std::size_t(x);
      if (!result.coverage[i]) continue;
      const bool tilted = opt.space == NormalSpace::tangent && result.map.pixels[3 * i + 2] < z_limit;
      if (!tilted && (disagree.empty() || !disagree[i])) continue;
      ++st.suspect_texels;
      if (opt.suspect_mask) result.suspect_mask.pixels[i] = 1.0f;
      ++cells[std::min(7, 8 * y / H)][std::min(7, 8 * x / W)];  // row 0 is the top: v = 1
    }
  if (!st.suspect_texels) return;
  st.suspect_share = st.texels_covered ? double(st.suspect_texels) / double(st.texels_covered) : 0.0;
  int best_r = 0, best_c = 0;
  for (int r = 0; r < 8; ++r)
    for (int c = 0; c < 8; ++c)
      if (cells[r][c] > cells[best_r][best_c]) best_r = r, best_c = c;
  st.suspect_region[0] = best_c / 8.0;
  st.suspect_region[1] = 1.0 - (best_r + 1) / 8.0;
  st.suspect_region[2] = (best_c + 1) / 8.0;
  st.suspect_region[3] = 1.0 - best_r / 8.0;
  st.suspect_region_share = double(cells[best_r][best_c]) / double(st.suspect_texels);
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

// The cage triangles' rear and search distances: per vertex (LocalDistances) when measured, else
// the one rear distance and no search beyond the cage.
void set_cage_reach(Prepared& s, const Mesh& low, double rear, const std::vector<float>& vertex_rear,
                    const std::vector<float>& vertex_search) {
  for (std::size_t t = 0; t < s.cage_tris.size(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = low.position_index[3 * t + c];
      s.cage_tris[t].rear[c] = vertex_rear.empty() ? rear : double(vertex_rear[v]);
      s.cage_tris[t].search[c] = vertex_search.empty() ? 0.0 : double(vertex_search[v]);
    }
}

// Everything the rays and the shading read, from the meshes: tangent frames, re-centred
// coordinates, ray normals, high-poly corner normals, the low-poly triangles in double. Fills the
// stats it learns on the way (degenerate counts, centre, coordinate precision, computed normals).
Prepared prepare(const Mesh& low, const Mesh& high, const Mesh* cage, BakeStats& st) {
  Prepared s;
  s.frames = compute_tangent_frames(low);
  st.degenerate_uv_triangles = s.frames.degenerate_uv_triangles;
  st.degenerate_3d_triangles = s.frames.degenerate_3d_triangles;
  st.corners_without_tangent = s.frames.corners_without_tangent;
  {
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    grow_box(lo, hi, low.positions, low.position_index);
    grow_box(lo, hi, high.positions, high.position_index);
    // Not the cage's: an automatic cage is made after this, and the same cage read from a file
    // must give the same centre, so the same rays to the bit.
    s.centre = 0.5 * (lo + hi);
    st.centre = s.centre;
    s.diagonal = glm::length(hi - lo);
    if (!(s.diagonal > 0.0)) s.diagonal = 1.0;
    // Float spacing at the largest coordinate: the precision the inputs carry (float positions).
    const glm::dvec3 far = glm::max(glm::abs(lo), glm::abs(hi));
    const float largest = float(std::max({far.x, far.y, far.z}));
    st.largest_coordinate = largest;
    st.coordinate_spacing = double(std::nextafter(largest, std::numeric_limits<float>::infinity()) - largest) / s.diagonal;
  }
  s.low_pos = recentre(low.positions, s.centre);
  s.high_pos = recentre(high.positions, s.centre);
  s.ray_normal = position_averaged_normals(low, s.frames);
  if (high.has_normals()) {
    s.high_corner_normals.resize(high.normal_index.size());
    for (std::size_t c = 0; c < high.normal_index.size(); ++c) s.high_corner_normals[c] = high.normals[high.normal_index[c]];
  } else {
    // Welded by value, duplicate faces once, one winding per piece (mesh_topology.h).
    s.high_corner_normals = compute_high_corner_normals(high, &st.high_faces_reoriented);
    st.high_normals_computed = true;
  }
  s.high_facing = triangle_facing(s.high_pos, high.position_index, s.high_corner_normals);
  s.low_tris.resize(low.triangle_count());
  for (std::size_t t = 0; t < low.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t pi = low.position_index[3 * t + c];
      s.low_tris[t].p[c] = glm::dvec3(s.low_pos[pi]);
      s.low_tris[t].ray_n[c] = glm::dvec3(s.ray_normal[pi]);
      s.low_tris[t].n[c] = glm::dvec3(s.frames.normal[3 * t + c]);
      s.low_tris[t].t[c] = glm::dvec4(s.frames.tangent[3 * t + c]);
    }
  if (cage) attach_cage(s, cage->positions, cage->position_index);
  s.bvh_index = high.position_index.data();
  s.bvh_normals = s.high_corner_normals.data();
  s.bvh_facing = s.high_facing.data();
  return s;
}

// The high-poly found inverted (BakeStats::HighFacing): fronts are taken the other way round, and
// normals nmbake computed itself are turned outwards with them (a file's normals are kept: the map
// then is what it was without the rule). Applies to the BVH's copies too.
void turn_inverted_high(Prepared& s, bool normals_computed) {
  // A file's normals now point against the fronts: how far they lean is then unknown (127).
  for (auto* v : {&s.high_facing, &s.kept_facing})
    for (std::int8_t& f : *v) f = normals_computed ? std::int8_t(-f) : raycast::facing_code(f < 0 ? 1 : -1, 2.0);
  if (normals_computed)
    for (auto* v : {&s.high_corner_normals, &s.kept_normals})
      for (glm::vec3& n : *v) n = -n;
}

glm::dvec3 low_point(const LowTriangle& lt, const double b[3]) { return b[0] * lt.p[0] + b[1] * lt.p[1] + b[2] * lt.p[2]; }

glm::dvec3 low_ray_normal(const LowTriangle& lt, const double b[3]) {
  const glm::dvec3 n = b[0] * lt.ray_n[0] + b[1] * lt.ray_n[1] + b[2] * lt.ray_n[2];
  const double len2 = glm::dot(n, n);
  if (len2 > 1e-24) return n * (1.0 / std::sqrt(len2));
  // Opposite corner normals cancel: fall back to the face normal.
  const glm::dvec3 f = glm::cross(lt.p[1] - lt.p[0], lt.p[2] - lt.p[0]);
  const double fl = glm::length(f);
  return fl > 0.0 ? f / fl : glm::dvec3(0, 0, 1);
}

// A sample's ray with a cage: P, the unit direction from the cage point to P, the distance from
// the cage point to P, how far out the ray searches (at least that), and the rear distance.
struct CageRay {
  glm::dvec3 p, d;
  double len, search, rear;
};

inline CageRay cage_ray(const LowTriangle& lt, const CageTriangle& ct, const double b[3], double diagonal) {
  CageRay r;
  r.p = low_point(lt, b);
  const glm::dvec3 pc = b[0] * ct.corner[0] + b[1] * ct.corner[1] + b[2] * ct.corner[2];
  r.rear = b[0] * ct.rear[0] + b[1] * ct.rear[1] + b[2] * ct.rear[2];
  const double search = b[0] * ct.search[0] + b[1] * ct.search[1] + b[2] * ct.search[2];
  const glm::dvec3 d = r.p - pc;
  r.len = glm::length(d);
  if (r.len > 1e-9 * diagonal) {
    r.d = d / r.len;
  } else {  // a cage point on the low-poly gives no direction: the ray normal's
    r.d = -low_ray_normal(lt, b);
    r.len = 0.0;
  }
  // Where a neighbouring part limits the cage, rays search on beyond it, as far out as the
  // high-poly was found there, for a hit to take only when none lies within the cage.
  r.search = std::max(r.len, search);
  return r;
}

// The inward ray of a cage sample: from `search` out along the line through the cage point to the
// rear distance beyond P; the part before the cage point is looked at last (prefer_lo).
inline raycast::Ray inward_ray(const CageRay& c, double* signed_base, float* prefer_lo) {
  signed_base[0] = c.search;
  prefer_lo[0] = c.search > c.len ? float(c.search - c.len) : 0.0f;
  return {glm::vec3(c.p - c.search * c.d), 0.0f, glm::vec3(c.d), float(c.search + c.rear)};
}

// How a bake casts its rays (policy.h of the options, with the distances chosen).
struct RaySetup {
  float front = 0.0f, rear = 0.0f;
  bool cage = false, closest = false;
  double diagonal = 1.0;
};

// The rays of the sample at barycentrics b of low-poly triangle `tri` (two for the closest-hit
// policy, else one) and, per ray, the distance from P to its origin along it and the part of the
// ray where hits are looked for first (raycast::RayBatch::prefer_lo/hi). Returns the count.
inline int sample_rays(const Prepared& s, std::size_t tri, const double b[3], const RaySetup& r, raycast::Ray* rays,
                       double* signed_base, float* prefer_lo, float* prefer_hi) {
  prefer_lo[0] = prefer_lo[1] = 0.0f;
  prefer_hi[0] = prefer_hi[1] = std::numeric_limits<float>::infinity();
  const LowTriangle& lt = s.low_tris[tri];
  if (r.cage) {
    const CageRay c = cage_ray(lt, s.cage_tris[tri], b, r.diagonal);
    if (r.closest) {  // from P out to the cage point (and on, searching), and in to the rear distance
      signed_base[0] = signed_base[1] = 0.0;
      rays[0] = {glm::vec3(c.p), 0.0f, glm::vec3(-c.d), float(c.search)};
      rays[1] = {glm::vec3(c.p), 0.0f, glm::vec3(c.d), float(c.rear)};
      if (c.search > c.len) prefer_hi[0] = float(c.len);
      return 2;
    }
    rays[0] = inward_ray(c, signed_base, prefer_lo);
    return 1;
  }
  const glm::dvec3 p = low_point(lt, b), n = low_ray_normal(lt, b);
  if (r.closest) {
    signed_base[0] = signed_base[1] = 0.0;
    rays[0] = {glm::vec3(p), 0.0f, glm::vec3(n), r.front};
    rays[1] = {glm::vec3(p), 0.0f, glm::vec3(-n), r.rear};
    return 2;
  }
  signed_base[0] = r.front;
  rays[0] = {glm::vec3(p + double(r.front) * n), 0.0f, glm::vec3(-n), r.front + r.rear};
  return 1;
}

// Of a sample's rays' hits (its rays start at `first`), the index of the one that counts, and its
// signed distance from the low-poly (positive: outside).
inline std::size_t chosen_hit(const raycast::HitBatch& hits, std::size_t first, const double* signed_base, bool closest,
                              double* dist) {
  if (closest) {
    const std::size_t out = first, in = first + 1;
    const bool out_hit = hits.triangle[out] != raycast::no_hit, in_hit = hits.triangle[in] != raycast::no_hit;
    // A hit taken only for want of another on its ray (outside the cage, then one whose normal
    // points away) yields to a better one on the other ray.
    const auto rank = [&](std::size_t i) {
      const int f = hits.flags ? hits.flags[i] : 0;
      return (f & raycast::hit_normal_disagrees) ? 2 : (f & raycast::hit_outside_preferred) ? 1 : 0;
    };
    const bool prefer_out = out_hit && in_hit && rank(out) != rank(in) ? rank(out) < rank(in) : hits.t[out] <= hits.t[in];
    if (out_hit && (!in_hit || prefer_out)) {
      *dist = hits.t[out];
      return out;
    }
    *dist = -double(hits.t[in]);
    return in;
  }
  *dist = signed_base[first] - hits.t[first];
  return first;
}

// One sample's value, one at a time: every case, with the fallbacks for degenerate hit normals and
// frames. encode_hits_per_pixel (shade_batch.h) gives the same bits for the common case, many at a
// time. `h` indexes the BVH's triangles (s.bvh_index, s.bvh_normals).
glm::dvec3 shade_sample(const Prepared& s, std::size_t tri, const double b[3], const raycast::Hit& h, const BakeOptions& opt) {
  const PixelFrame frame = interpolate_frame(s.low_tris[tri].n, s.low_tris[tri].t, b, opt.bitangent);
  if (!h.hit()) {
    const double nl = glm::length(frame.n);
    return opt.space == NormalSpace::tangent ? glm::dvec3(0, 0, 1) : (nl > 0 ? frame.n / nl : glm::dvec3(0, 0, 1));
  }
  const std::size_t ht = h.triangle;
  const double w[3] = {1.0 - double(h.u) - double(h.v), double(h.u), double(h.v)};
  glm::dvec3 nh(0.0);
  for (int c = 0; c < 3; ++c) nh += w[c] * glm::dvec3(s.bvh_normals[3 * ht + c]);
  const double len2 = glm::dot(nh, nh);
  // The encoding normalizes, so in tangent space the hit normal goes in at its own length, unless
  // that is too short to trust (encode_hits_per_pixel's test).
  if (opt.space == NormalSpace::tangent && len2 > kShortHitNormal2) return encode_tangent_normal(frame, nh);
  double len = std::sqrt(len2);
  if (!(len > 1e-12)) {
    const glm::dvec3 q0(s.high_pos[s.bvh_index[3 * ht]]), q1(s.high_pos[s.bvh_index[3 * ht + 1]]),
        q2(s.high_pos[s.bvh_index[3 * ht + 2]]);
    nh = glm::cross(q1 - q0, q2 - q0);
    len = glm::length(nh);
  }
  nh = len > 0.0 ? nh / len : glm::normalize(frame.n);
  return opt.space == NormalSpace::tangent ? encode_tangent_normal(frame, nh) : nh;
}

}  // namespace

std::vector<glm::vec3> low_ray_normals(const Mesh& low) { return position_averaged_normals(low, compute_tangent_frames(low)); }

std::vector<glm::dvec2> sample_offsets(int samples) {
  std::vector<glm::dvec2> out;
  if (samples <= 1) return {glm::dvec2(0.5, 0.5)};
  const int k = int(std::lround(std::sqrt(double(samples))));
  if (k * k == samples) {
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i) out.push_back({(i + 0.5) / k, (j + 0.5) / k});
    return out;
  }
  for (int i = 0; i < samples; ++i) {
    // Hammersley: x stratified in n strata, y the base-2 radical inverse, shifted off the edges.
    std::uint32_t b = std::uint32_t(i);
    b = (b << 16) | (b >> 16);
    b = ((b & 0x55555555u) << 1) | ((b & 0xAAAAAAAAu) >> 1);
    b = ((b & 0x33333333u) << 2) | ((b & 0xCCCCCCCCu) >> 2);
    b = ((b & 0x0F0F0F0Fu) << 4) | ((b & 0xF0F0F0F0u) >> 4);
    b = ((b & 0x00FF00FFu) << 8) | ((b & 0xFF00FF00u) >> 8);
    double y = double(b) * (1.0 / 4294967296.0) + 0.5 / samples;
    if (y >= 1.0) y -= 1.0;
    out.push_back({(i + 0.5) / samples, y});
  }
  return out;
}

raycast::BuildQuality bvh_quality_for(const BakeOptions& o, std::size_t triangles) {
  const double rays = double(o.width) * double(o.height) * double(o.samples);
  return rays < 16.0 * double(triangles) ? raycast::BuildQuality::low : raycast::BuildQuality::high;
}

std::uint64_t estimate_bake_bytes(const BakeOptions& o) {
  const std::uint64_t texels = std::uint64_t(std::max(o.width, 0)) * std::uint64_t(std::max(o.height, 0));
  // map (3 floats) + coverage (1 byte) + padding transform (double + int) + optional miss mask.
  std::uint64_t per_texel = 12 + 1 + (o.padding > 0 ? 12 : 0) + (o.miss_mask ? 4 : 0) + (o.suspect_mask ? 4 : 0) + (o.samples > 1 ? 1 : 0);
  return texels * per_texel;
}

BakeResult bake_normal_map(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt) {
  // Options.
  if (opt.width < 1 || opt.height < 1)
    throw UsageError("--size must be at least 1x1 (got " + std::to_string(opt.width) + "x" + std::to_string(opt.height) + ")");
  if (opt.width > kMaxMapSide || opt.height > kMaxMapSide)
    throw ResourceError("--size " + std::to_string(opt.width) + "x" + std::to_string(opt.height) +
                        " refused: the largest supported side is " + std::to_string(kMaxMapSide) + " texels");
  if (opt.samples < 1 || opt.samples > kMaxSamples)
    throw UsageError("--samples must be between 1 and " + std::to_string(kMaxSamples) + " (got " + std::to_string(opt.samples) + ")");
  if (opt.padding < 0) throw UsageError("--padding must not be negative");
  if (!std::isfinite(opt.front) || !std::isfinite(opt.rear)) throw UsageError("--front and --rear must be finite");
  if (!low.has_uvs()) throw InputError(low.source + ": the low-poly mesh has no UVs");
  if (low.triangle_count() == 0) throw InputError(low.source + ": no faces");
  if (high.triangle_count() == 0) throw InputError(high.source + ": no faces");
  if (cage && (cage->triangle_count() != low.triangle_count() || cage->positions.size() != low.positions.size() ||
               cage->position_index != low.position_index))
    throw InputError(cage->source + ": the cage must have the low-poly's topology (" + std::to_string(cage->triangle_count()) +
                     " triangles, " + std::to_string(cage->positions.size()) + " vertices; " + low.source + " has " +
                     std::to_string(low.triangle_count()) + " and " + std::to_string(low.positions.size()) + ")");
  {
    const std::uint64_t need = estimate_bake_bytes(opt);
    const std::uint64_t avail = opt.memory_limit ? opt.memory_limit : memory_budget_bytes();
    if (need > avail)
      throw ResourceError("--size " + std::to_string(opt.width) + "x" + std::to_string(opt.height) + " needs about " +
                          std::to_string(need >> 20) + " MiB for its buffers but only " + std::to_string(avail >> 20) +
                          " MiB are available");
  }
  const int threads = opt.threads > 0 ? opt.threads : std::max(1, int(std::thread::hardware_concurrency()));

  BakeResult result;
  BakeStats& st = result.stats;
  st.low_triangles = low.triangle_count();
  st.high_triangles = high.triangle_count();

  // Prepare: tangent frames, re-centred coordinates, ray normals, high-poly normals.
  auto t0 = Clock::now();
  // The output buffers, allocated by a helper while prepare runs on one core: the system zeroes
  // each fresh page at its first touch (18-40 ms for a 2048^2 map on our 2-core VM), work
  // that would otherwise fall between the trace's rays. Joined before the trace. Starting a thread
  // waits while another thread of the process is loading a shared library (glibc's loader lock; the
  // CLI loads its image module in the background, up to 0.2 s): in prepare's time, where it shows.
  std::exception_ptr output_error;
  std::vector<std::uint8_t> disagree;  // per texel: its samples disagree (suspect), with several samples
  std::thread output_alloc([&] {
    try {
      const std::size_t texels = std::size_t(opt.width) * std::size_t(opt.height);
      result.map = Image(opt.width, opt.height, 3, Image::Unset{});  // the trace writes the covered texels, padding the rest
      result.map.fault_in();
      result.coverage.assign(texels, 0);
      if (opt.miss_mask) result.miss_mask = Image(opt.width, opt.height, 1, 0.0f);
      if (opt.samples > 1) disagree.assign(texels, 0);
    } catch (...) {
      output_error = std::current_exception();
    }
  });
  struct JoinOnExit {
    std::thread& t;
    ~JoinOnExit() {
      if (t.joinable()) t.join();
    }
  } join_output_alloc{output_alloc};

  Prepared s = prepare(low, high, cage, st);
  if (cage) check_cage_encloses(s, *cage);
  for (std::size_t t = 0; t < low.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      const glm::vec2 uv = low.corner_uv(t, c);
      if (uv.x < 0.0f || uv.x > 1.0f || uv.y < 0.0f || uv.y > 1.0f) {
        ++st.uv_outside_triangles;
        glm::vec2 lo = uv, hi = uv;
        for (int k = 0; k < 3; ++k) lo = glm::min(lo, low.corner_uv(t, k)), hi = glm::max(hi, low.corner_uv(t, k));
        st.uv_outside_entirely_triangles += hi.x < 0.0f || lo.x > 1.0f || hi.y < 0.0f || lo.y > 1.0f;
        break;
      }
    }
  st.seconds_prepare = seconds_since(t0);

  const std::vector<LowTriangle>& low_tris = s.low_tris;

  // BVH over the high-poly triangles some ray can reach (all of them without culling). Each ray
  // stays within `margin` of its low-poly triangle's box (grown over the cage triangle): front
  // and rear when given, else the distance probe's reach, and after the probe the distances it
  // chose (the BVH is rebuilt then only if that leaves out a fifth of it or more).
  // How far rays reach: from a cage read from a file (its rear measured per vertex unless given);
  // one fixed distance for the whole scene where --front or --rear is given (the other measured for
  // the whole scene); else from the automatic cage, front and rear measured per vertex (auto_cage.h).
  const bool auto_cage = !cage && opt.front < 0.0f && opt.rear < 0.0f;
  const bool auto_distances = !cage && !auto_cage && (opt.front < 0.0f || opt.rear < 0.0f);
  const bool local_rear = auto_cage || (cage && opt.rear < 0.0f);
  const bool probing = auto_distances || local_rear;
  const double reach = kProbeReach * s.diagonal;  // the probe's: farther than this is another part of the model
  const double floor_dist = 1e-4 * s.diagonal;  // the least distance measured (coincident meshes)
  const bool any_cage = cage || auto_cage;
  std::vector<Box> regions;
  auto ray_margin = [&](double front, double rear) {
    // Rays are cast in float: a little slack keeps the test conservative.
    return 1.01 * (any_cage ? rear : std::max(front, rear)) + 1e-6 * s.diagonal;
  };
  std::vector<std::uint32_t> kept;  // triangles in the BVH, increasing; empty with all of them in
  std::optional<raycast::Scene> scene;
  auto build_scene = [&] {
    // The trace reads per-triangle arrays in BVH order, so a hit's triangle index needs no mapping.
    s.bvh_index = high.position_index.data();
    s.bvh_normals = s.high_corner_normals.data();
    s.bvh_facing = s.high_facing.data();
    if (!kept.empty()) {
      std::vector<std::uint32_t> index(3 * kept.size());
      std::vector<glm::vec3> normals(3 * kept.size());
      std::vector<std::int8_t> facing(kept.size());
      for (std::size_t i = 0; i < kept.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
          index[3 * i + c] = high.position_index[3 * std::size_t(kept[i]) + c];
          normals[3 * i + c] = s.high_corner_normals[3 * std::size_t(kept[i]) + c];
        }
        facing[i] = s.high_facing[kept[i]];
      }
      s.kept_index = std::move(index);
      s.kept_normals = std::move(normals);
      s.kept_facing = std::move(facing);
      s.bvh_index = s.kept_index.data();
      s.bvh_normals = s.kept_normals.data();
      s.bvh_facing = s.kept_facing.data();
    }
    const std::size_t tris = kept.empty() ? high.triangle_count() : kept.size();
    st.bvh_quality = bvh_quality_for(opt, tris);
    scene.reset();
    scene.emplace(&s.high_pos[0].x, s.high_pos.size(), s.bvh_index, tris, st.bvh_quality, opt.threads);
    st.high_triangles_culled = kept.empty() ? 0 : high.triangle_count() - kept.size();
  };
  // Each low-poly triangle's box, grown over its cage triangle when there is one.
  auto make_regions = [&] {
    regions.resize(low.triangle_count());
    for (std::size_t t = 0; t < low.triangle_count(); ++t) {
      Box b{low_tris[t].p[0], low_tris[t].p[0]};
      for (int c = 0; c < 3; ++c) {
        b.lo = glm::min(b.lo, low_tris[t].p[c]);
        b.hi = glm::max(b.hi, low_tris[t].p[c]);
        if (!s.cage_tris.empty()) {
          b.lo = glm::min(b.lo, s.cage_tris[t].corner[c]);
          b.hi = glm::max(b.hi, s.cage_tris[t].corner[c]);
        }
      }
      regions[t] = b;
    }
  };
  t0 = Clock::now();
  if (opt.cull_far) {
    make_regions();
    const double margin = probing ? reach * 1.01 + 1e-6 * s.diagonal : ray_margin(opt.front, opt.rear);
    kept = triangles_near(regions, margin, s.high_pos, high.position_index);
    if (kept.size() == high.triangle_count()) kept.clear();
  }
  build_scene();
  st.seconds_bvh = seconds_since(t0);

  // Ray distances: given, or measured by probing along the ray normals from points on the low-poly.
  // The same probes tell whether the high-poly's faces point the way its normals say (for the hit
  // rule), so they are cast whenever either is needed.
  t0 = Clock::now();
  st.front = opt.front;
  st.rear = opt.rear;
  double global_front = 0.0, global_rear = 0.0;  // measured for the whole scene
  if (probing || !opt.keep_backfaces) {
    const std::size_t tris = low.triangle_count();
    const std::size_t stride = std::max<std::size_t>(1, tris / (probing ? 50000 : 5000));
    static const double probe_bary[4][3] = {{1 / 3.0, 1 / 3.0, 1 / 3.0}, {4 / 6.0, 1 / 6.0, 1 / 6.0},
                                            {1 / 6.0, 4 / 6.0, 1 / 6.0}, {1 / 6.0, 1 / 6.0, 4 / 6.0}};
    std::vector<raycast::Ray> rays;
    for (std::size_t t = 0; t < tris; t += stride)
      for (const auto& b : probe_bary) {
        const glm::dvec3 p = low_point(low_tris[t], b), n = low_ray_normal(low_tris[t], b);
        rays.push_back({glm::vec3(p), 0.0f, glm::vec3(n), float(reach)});
        rays.push_back({glm::vec3(p), 0.0f, glm::vec3(-n), float(reach)});
      }
    std::vector<raycast::Hit> hits(rays.size());
    const std::size_t pairs = rays.size() / 2;
    std::atomic<std::size_t> next{0};
    run_parallel(threads, [&](int) {
      for (std::size_t i; (i = next.fetch_add(4096)) < pairs;) {
        const std::size_t n = std::min<std::size_t>(4096, pairs - i);
        scene->intersect(&rays[2 * i], &hits[2 * i], 2 * n);
      }
    });
    std::size_t nearest_back = 0, probes_hit = 0;
    // A back face: its front (by its normals) faces away from the low-poly's outside, +direction
    // of the outward probe (the first of a pair).
    std::vector<std::uint8_t> is_back(rays.size(), 0);
    const ProbeTarget target{&*scene, s.high_pos.data(), s.bvh_index, s.bvh_facing};
    for (std::size_t i = 0; i < rays.size(); ++i)
      if (hits[i].hit()) is_back[i] = front_along(target, hits[i].triangle, rays[i & ~std::size_t(1)].direction) < 0.0f;
    for (std::size_t i = 0; i < pairs; ++i) {  // how the faces point: by the nearest hit either way
      const raycast::Hit &o = hits[2 * i], &in = hits[2 * i + 1];
      if (!o.hit() && !in.hit()) continue;
      ++probes_hit;
      nearest_back += o.hit() && (!in.hit() || o.t <= in.t) ? is_back[2 * i] : is_back[2 * i + 1];
    }
    st.backface_probe_share = probes_hit ? double(nearest_back) / double(probes_hit) : 0.0;
    if (!opt.keep_backfaces) {
      st.high_facing = st.backface_probe_share > kInvertedShare ? BakeStats::HighFacing::inverted
                       : st.backface_probe_share > kMixedShare  ? BakeStats::HighFacing::mixed
                                                                : BakeStats::HighFacing::sound;
      st.backfaces_skipped = st.high_facing != BakeStats::HighFacing::mixed;
    }
    // How far the high-poly lies: by the nearest hit either way that the rays may take (with back
    // faces skipped, not a back face as the faces were found to point: that is another part's inside).
    const std::uint8_t back_is = st.high_facing == BakeStats::HighFacing::inverted ? 0 : 1;
    std::vector<float> outside, inside;
    for (std::size_t i = 0; i < pairs; ++i) {
      const raycast::Hit &o = hits[2 * i], &in = hits[2 * i + 1];
      const bool o_ok = o.hit() && !(st.backfaces_skipped && is_back[2 * i] == back_is);
      const bool in_ok = in.hit() && !(st.backfaces_skipped && is_back[2 * i + 1] == back_is);
      if (o_ok && (!in_ok || o.t <= in.t))
        outside.push_back(o.t);
      else if (in_ok)
        inside.push_back(in.t);
    }
    if (probing) {
      st.auto_distances = true;
      // Cover all but the farthest 0.1% of probes, with a 25% margin and a floor for coincident meshes.
      global_front = 1.25 * quantile(outside, 0.999) + floor_dist;
      global_rear = 1.25 * quantile(inside, 0.999) + floor_dist;
      st.scene_front = global_front;
      st.scene_rear = global_rear;
    }
    if (auto_distances) {
      const double front = global_front, rear = global_rear;
      if (opt.front < 0.0f) st.front = float(front);
      if (opt.rear < 0.0f) st.rear = float(rear);
      std::size_t beyond = 0;
      for (float d : outside) beyond += d > st.front;
      for (float d : inside) beyond += d > st.rear;
      st.auto_probe_beyond = pairs ? double(beyond) / double(pairs) : 0.0;
    }
  }
  if (st.high_facing == BakeStats::HighFacing::inverted) turn_inverted_high(s, st.high_normals_computed);
  if (local_rear) {
    // Per-vertex distances (after the facing decision: the probes judge faces by it).
    const LocalDistances ld = measure_local_distances({&s.low_pos, &low.position_index, &s.ray_normal},
                                                      {&*scene, s.high_pos.data(), s.bvh_index, s.bvh_facing}, reach, floor_dist,
                                                      global_front, global_rear, kNeedSlope, kLimitSlope, threads);
    st.auto_distances = true;
    st.cage_front_limited = auto_cage ? ld.front_limited : 0;
    st.cage_rear_limited = ld.rear_limited;
    result.vertex_rear = ld.rear;
    result.vertex_search = ld.search;
    if (auto_cage) {
      // The cage: every vertex moved along its ray normal by its front distance, in the meshes'
      // own coordinates (float, as a cage file holds them), then re-centred like a file's.
      result.cage_positions.resize(low.positions.size());
      for (std::size_t i = 0; i < low.positions.size(); ++i)
        result.cage_positions[i] = glm::vec3(glm::dvec3(low.positions[i]) + double(ld.front[i]) * glm::dvec3(s.ray_normal[i]));
      attach_cage(s, result.cage_positions, low.position_index);
    }
    summarize(auto_cage ? ld.front : std::vector<float>(), st.vertex_front);
    summarize(ld.rear, st.vertex_rear);
    if (auto_cage) st.front = float(st.vertex_front.max);
    st.rear = float(st.vertex_rear.max);
  }
  st.cage = cage ? BakeStats::CageSource::file : auto_cage ? BakeStats::CageSource::automatic : BakeStats::CageSource::none;
  if (any_cage) set_cage_reach(s, low, st.rear, result.vertex_rear, result.vertex_search);
  if (cage && st.front < 0.0f) st.front = 0.0f;
  st.seconds_distances = seconds_since(t0);
  if (opt.cull_far && probing) {
    make_regions();
    t0 = Clock::now();
    std::vector<std::uint32_t> all;
    if (kept.empty()) {
      all.resize(high.triangle_count());
      for (std::size_t t = 0; t < all.size(); ++t) all[t] = std::uint32_t(t);
    }
    const std::vector<std::uint32_t>& current = kept.empty() ? all : kept;
    // Rays from a cage reach the rear distance beyond P and, where they search beyond the cage,
    // as far out as they search.
    double reach_out = 0.0;
    for (float d : result.vertex_search) reach_out = std::max(reach_out, double(d));
    std::vector<std::uint32_t> nearer = triangles_near(regions, ray_margin(st.front, std::max<double>(st.rear, reach_out)), s.high_pos,
                                                       high.position_index, &current);
    if (double(nearer.size()) < 0.8 * double(current.size())) {
      kept = std::move(nearer);
      build_scene();
    }
    st.seconds_bvh += seconds_since(t0);
  }

  // Trace: tiles of texels, each rasterized against the triangles binned to it, rays in packets.
  t0 = Clock::now();
  const double cpu0 = process_cpu_seconds();
  const int W = opt.width, H = opt.height;
  // Tiles of 32 x 32 texels up to 4 samples, else 16 x 16: a triangle's rows within a tile are
  // longer with the larger ones (less set-up per texel), and a tile's samples stay within the
  // cache with the smaller.
  const int tile_side = opt.samples <= 4 ? 2 * kTile : kTile;
  const int tiles_x = (W + tile_side - 1) / tile_side, tiles_y = (H + tile_side - 1) / tile_side;
  const std::size_t tile_count = std::size_t(tiles_x) * tiles_y;
  std::vector<TexelTriangle> texel_tris(low.triangle_count());
  std::vector<std::uint32_t> bin_start(tile_count + 1, 0);
  for (std::size_t t = 0; t < low.triangle_count(); ++t) {
    texel_tris[t] = setup_texel_triangle(low.corner_uv(t, 0), low.corner_uv(t, 1), low.corner_uv(t, 2), W, H);
    const TexelTriangle& tt = texel_tris[t];
    if (!tt.valid() || tt.xmax < tt.xmin || tt.ymax < tt.ymin) continue;
    for (int ty = tt.ymin / tile_side; ty <= tt.ymax / tile_side; ++ty)
      for (int tx = tt.xmin / tile_side; tx <= tt.xmax / tile_side; ++tx) ++bin_start[std::size_t(ty) * tiles_x + tx + 1];
  }
  for (std::size_t i = 0; i < tile_count; ++i) bin_start[i + 1] += bin_start[i];
  std::vector<std::uint32_t> bin_tris(bin_start[tile_count]);
  {
    std::vector<std::uint32_t> fill(bin_start.begin(), bin_start.end() - 1);
    for (std::size_t t = 0; t < low.triangle_count(); ++t) {
      const TexelTriangle& tt = texel_tris[t];
      if (!tt.valid() || tt.xmax < tt.xmin || tt.ymax < tt.ymin) continue;
      for (int ty = tt.ymin / tile_side; ty <= tt.ymax / tile_side; ++ty)
        for (int tx = tt.xmin / tile_side; tx <= tt.xmax / tile_side; ++tx)
          bin_tris[fill[std::size_t(ty) * tiles_x + tx]++] = std::uint32_t(t);
    }
  }

  output_alloc.join();
  if (output_error) std::rethrow_exception(output_error);
  const std::vector<glm::dvec2> offsets = sample_offsets(opt.samples);
  const int S = int(offsets.size());
  const bool closest = opt.policy == RayPolicy::closest;
  const int rays_per_sample = closest ? 2 : 1;

  // One cache line each: the counters change per sample, and shared lines would serialize threads.
  struct alignas(64) ThreadStats {
    std::uint64_t rays = 0, hits = 0, misses = 0, covered = 0, overlaps = 0, backface_skips = 0, facing_away = 0;
    Clock::duration intersect{0}, tiles{0};
    double dmin = std::numeric_limits<double>::infinity(), dmax = -std::numeric_limits<double>::infinity();
  };
  std::vector<ThreadStats> tstats(threads);
  // Hit distances summed per tile, then over tiles in order: the mean does not depend on which
  // thread took which tile.
  std::vector<double> tile_dsum(tile_count, 0.0);
  std::atomic<std::size_t> next_tile{0}, tiles_done{0};
  std::atomic<bool> cancel{false};
  std::mutex record_mutex;

  // Hits in tangent space with the per-pixel bitangent are shaded many at a time (shade_batch.h).
  const bool batched = opt.space == NormalSpace::tangent && opt.bitangent == BitangentMode::per_pixel;
  RaySetup ray_setup;
  ray_setup.front = st.front;
  ray_setup.rear = st.rear;
  ray_setup.cage = any_cage;
  ray_setup.closest = closest;
  ray_setup.diagonal = s.diagonal;

  // The hit rule (raycast::HitRule), over the BVH's triangles as finally built.
  raycast::HitRule rule;
  rule.facing = s.bvh_facing;
  rule.corner_normals = s.bvh_normals;
  const raycast::HitRule* const hit_rule = st.backfaces_skipped ? &rule : nullptr;

  auto worker = [&](int id) {
    ThreadStats& ts = tstats[id];
    // Sample slots of a tile: sample k of tile texel (x, y) is slot (k * tile_side + y) * tile_side
    // + x, so a texel row is contiguous for the coverage kernel.
    const std::size_t tile_texels = std::size_t(tile_side) * tile_side;
    const std::size_t slot_count = tile_texels * std::size_t(S);
    const bool default_rays = !ray_setup.cage && !ray_setup.closest;
    // The covered samples in slot order, which puts each texel's samples in sample order: that
    // fixes how its values are summed. Rays and hits as arrays, the layout Embree's packets take;
    // sample r casts rays r * rays_per_sample onwards. The coverage fills slots in these same
    // arrays (with the default policy's one ray per sample, slot i's ray is ray i), and the
    // compaction closes the gaps in place: a fully covered stretch of slots stays where it is.
    raycast::RayArrays rays(slot_count * std::size_t(rays_per_sample));
    const raycast::HitBatch hits = rays.hits();
    // With two rays per sample (closest), the first leaves the low-poly outwards.
    std::vector<std::uint8_t> outward(rays_per_sample == 2 ? rays.size() : 0);
    for (std::size_t i = 0; i < outward.size(); i += 2) outward[i] = 1;
    raycast::RayBatch ray_batch = rays.rays();
    ray_batch.outward = outward.empty() ? nullptr : outward.data();
    std::vector<float> prefer_lo(any_cage ? rays.size() : 0), prefer_hi(any_cage ? rays.size() : 0);
    if (any_cage) {
      ray_batch.prefer_lo = prefer_lo.data();
      ray_batch.prefer_hi = prefer_hi.data();
    }
    std::vector<std::int32_t> sample_tri(slot_count);
    std::vector<double> sample_b(3 * slot_count);
    double* const sb[3] = {&sample_b[0], &sample_b[slot_count], &sample_b[2 * slot_count]};
    std::vector<std::uint16_t> sample_texel(slot_count);
    std::vector<std::uint8_t> sample_fallback(slot_count, 1);  // per covered sample: its ray is made one at a time
    const CoveredSamples covered{sample_tri.data(),
                                {sb[0], sb[1], sb[2]},
                                sample_texel.data(),
                                {rays.origin(0), rays.origin(1), rays.origin(2)},
                                {rays.direction(0), rays.direction(1), rays.direction(2)},
                                sample_fallback.data()};
    const SampleSlots slots{covered.tri,
                            {sb[0], sb[1], sb[2]},
                            {covered.org[0], covered.org[1], covered.org[2]},
                            {covered.dir[0], covered.dir[1], covered.dir[2]},
                            covered.ray_fallback};
    const DefaultRays default_ray_setup{default_rays ? low_tris.data() : nullptr, ray_setup.front};
    if (default_rays) {
      // Every default-policy ray starts at 0 and reaches front + rear (sample_rays' too).
      std::fill(rays.tfar(), rays.tfar() + rays.size(), ray_setup.front + ray_setup.rear);
    }
    std::vector<double> signed_base(rays.size(), double(ray_setup.front));  // per ray: distance from P to its origin along it
    // The hit that counts, per covered sample: with one ray per sample its own, read in place;
    // with two (closest), picked into these.
    std::vector<std::uint32_t> chosen(slot_count), chosen_tri(slot_count);
    std::vector<float> chosen_u(slot_count), chosen_v(slot_count);
    const ShadeSamples shade_in{sample_tri.data(),
                                {sb[0], sb[1], sb[2]},
                                rays_per_sample == 1 ? hits.triangle : chosen_tri.data(),
                                rays_per_sample == 1 ? hits.u : chosen_u.data(),
                                rays_per_sample == 1 ? hits.v : chosen_v.data()};
    std::vector<double> value(3 * slot_count);
    double* const value_c[3] = {&value[0], &value[slot_count], &value[2 * slot_count]};
    std::vector<std::uint8_t> one_at_a_time(slot_count, 1);  // per covered sample: shaded by shade_sample
    std::vector<double> acc(4 * tile_texels);  // per texel of the tile: x, y, z sums and covered samples, as arrays
    const TexelSums sums{{&acc[0], &acc[tile_texels], &acc[2 * tile_texels]}, &acc[3 * tile_texels]};
    std::vector<std::uint32_t> miss_count(tile_texels);
    for (std::size_t tile = 0, grab_end = 0; !cancel.load(std::memory_order_relaxed); ++tile) {
      if (tile == grab_end) {
        // A few consecutive tiles at a time: they lie near each other on the model, and a thread
        // that casts their rays one after another finds more of the BVH in its own caches.
        tile = next_tile.fetch_add(kTilesPerGrab);
        if (tile >= tile_count) break;
        grab_end = std::min(tile + kTilesPerGrab, tile_count);
      }
      const int tx0 = int(tile % tiles_x) * tile_side, ty0 = int(tile / tiles_x) * tile_side;
      const int tw = std::min(tile_side, W - tx0), th = std::min(tile_side, H - ty0);
      const std::uint32_t b0 = bin_start[tile], b1 = bin_start[tile + 1];
      if (b0 == b1) {
        ++tiles_done;
        continue;  // no triangle touches this tile: it costs nothing
      }
      const auto tile_start = Clock::now();
      std::fill(sample_tri.begin(), sample_tri.end(), -1);
      // Rasterize: the lowest triangle index wins a sample covered twice (overlapping islands).
      for (std::uint32_t bi = b0; bi < b1; ++bi) {
        const std::uint32_t t = bin_tris[bi];
        const TexelTriangle& tt = texel_tris[t];
        const int x0 = std::max(tt.xmin, tx0), x1 = std::min(tt.xmax, tx0 + tw - 1);
        const int y0 = std::max(tt.ymin, ty0), y1 = std::min(tt.ymax, ty0 + th - 1);
        if (x1 < x0 || y1 < y0) continue;
        for (int k = 0; k < S; ++k)
          ts.overlaps += cover_rect(tt, std::int32_t(t), x0, x1, y0, y1, offsets[k].x, offsets[k].y, default_ray_setup, slots,
                                    (std::size_t(k) * tile_side + std::size_t(y0 - ty0)) * tile_side + std::size_t(x0 - tx0), tile_side);
      }
      // The covered samples, in order, with the rays the coverage made (the default policy).
      const std::size_t sample_count = compact_samples(slots, slot_count, tile_texels, default_rays, covered);
      // The other rays one at a time: other policies, and the special cases of the default one.
      const std::size_t ray_count = sample_count * std::size_t(rays_per_sample);
      if (any_cage && !closest) {
        // Cage rays, straight into the arrays (sample_rays' own for them).
        for (std::size_t r = 0; r < sample_count; ++r) {
          const double b[3] = {sb[0][r], sb[1][r], sb[2][r]};
          const std::size_t tri = std::size_t(sample_tri[r]);
          rays.set(r, inward_ray(cage_ray(low_tris[tri], s.cage_tris[tri], b, ray_setup.diagonal), &signed_base[r], &prefer_lo[r]));
          prefer_hi[r] = std::numeric_limits<float>::infinity();
        }
      }
      for (std::size_t r = 0; r < sample_count && !(any_cage && !closest); ++r) {
        if (!sample_fallback[r]) continue;
        raycast::Ray one[2];
        const double b[3] = {sb[0][r], sb[1][r], sb[2][r]};
        float lo[2], hi[2];
        const int n = sample_rays(s, std::size_t(sample_tri[r]), b, ray_setup, one, &signed_base[r * rays_per_sample], lo, hi);
        for (int j = 0; j < n; ++j) {
          const std::size_t i = r * rays_per_sample + std::size_t(j);
          rays.set(i, one[j]);
          if (any_cage) prefer_lo[i] = lo[j], prefer_hi[i] = hi[j];
        }
      }
      if (ray_count) {
        const auto cast_start = Clock::now();
        scene->intersect(ray_batch, hits, ray_count, hit_rule);
        ts.intersect += Clock::now() - cast_start;
        if (hit_rule)
          for (std::size_t r = 0; r < ray_count; ++r) ts.backface_skips += (hits.flags[r] & raycast::hit_passed_backface) != 0;
      }
      if (opt.record_rays) {
        std::lock_guard<std::mutex> lock(record_mutex);
        for (std::size_t r = 0; r < ray_count; ++r) opt.record_rays->push_back(rays.ray(r));
      }
      ts.rays += ray_count;
      // Shade: the high-poly normal at the hit, in the low-poly's tangent frame at P. First, in
      // sample order, which ray's hit counts and the hit statistics; then the common case (tangent
      // space, per-pixel bitangent) for all samples at once; then, one at a time, the misses and
      // the cases the batch leaves out; last, each sample's value into its texel.
      std::fill(acc.begin(), acc.end(), 0.0);
      std::fill(miss_count.begin(), miss_count.end(), 0u);
      std::size_t tile_hits = 0;
      // In registers for the tile: the stores below could alias the thread's counters.
      double dsum = 0.0, dmin = ts.dmin, dmax = ts.dmax;
      for (std::size_t r = 0; r < sample_count; ++r) {
        double dist = 0.0;
        const std::size_t h = chosen_hit(hits, r * rays_per_sample, signed_base.data(), closest, &dist);
        if (rays_per_sample != 1) {
          chosen[r] = std::uint32_t(h);
          chosen_tri[r] = hits.triangle[h];
          chosen_u[r] = hits.u[h];
          chosen_v[r] = hits.v[h];
        }
        if (hits.triangle[h] != raycast::no_hit) {
          if (hit_rule) ts.facing_away += (hits.flags[h] & raycast::hit_normal_disagrees) != 0;
          // The hit triangles' corner normals are scattered over the high-poly: ask for them all
          // before shading needs the first, so the cache misses overlap.
          const char* line = reinterpret_cast<const char*>(&s.bvh_normals[3 * std::size_t(hits.triangle[h])]);
          __builtin_prefetch(line);
          __builtin_prefetch(line + sizeof(glm::vec3) * 3 - 1);
          ++tile_hits;
          dmin = std::min(dmin, dist);
          dmax = std::max(dmax, dist);
          dsum += dist;
        } else {
          ++miss_count[sample_texel[r]];
        }
      }
      ts.covered += sample_count;
      ts.hits += tile_hits;
      ts.misses += sample_count - tile_hits;
      ts.dmin = dmin;
      ts.dmax = dmax;
      tile_dsum[tile] = dsum;
      if (batched && sample_count)
        encode_hits_per_pixel(low_tris.data(), s.bvh_normals, shade_in, sample_count, value_c, one_at_a_time.data());
      for (std::size_t r = 0; r < sample_count; ++r) {
        if (!one_at_a_time[r]) continue;
        const double b[3] = {sb[0][r], sb[1][r], sb[2][r]};
        const glm::dvec3 v = shade_sample(s, std::size_t(sample_tri[r]), b, rays.hit(rays_per_sample == 1 ? r : chosen[r]), opt);
        for (int c = 0; c < 3; ++c) value_c[c][r] = v[c];
      }
      accumulate_samples(value_c, sample_texel.data(), sample_count, sums);
      if (!disagree.empty())
        for (int y = 0; y < th; ++y)
          for (int x = 0; x < tw; ++x) {
            const std::size_t i = std::size_t(y) * tile_side + std::size_t(x);
            const double n = sums.count[i];
            const double len2 = sums.sum[0][i] * sums.sum[0][i] + sums.sum[1][i] * sums.sum[1][i] + sums.sum[2][i] * sums.sum[2][i];
            if (n > 1.0 && len2 < kSuspectAgreement * kSuspectAgreement * n * n)
              disagree[std::size_t(ty0 + y) * W + std::size_t(tx0 + x)] = 1;
          }
      // Texels: renormalized mean of their covered samples.
      const bool flip_y = opt.space == NormalSpace::tangent && opt.green_down;
      for (int y = 0; y < th; ++y) {
        const std::size_t first = std::size_t(y) * tile_side, gi = std::size_t(ty0 + y) * W + std::size_t(tx0);
        write_texel_row(sums, first, tw, flip_y, kSnap, result.map.at(tx0, ty0 + y), &result.coverage[gi]);
        if (opt.miss_mask)
          for (int x = 0; x < tw; ++x)
            if (sums.count[first + x] > 0.0)
              result.miss_mask.pixels[gi + x] = float(miss_count[first + x]) / float(sums.count[first + x]);
      }
      ts.tiles += Clock::now() - tile_start;
      ++tiles_done;
    }
  };

  {
    // Progress every 100 ms; the last worker to finish wakes the wait at once, so the stage does not
    // end up to 100 ms after its work.
    std::mutex done_mutex;
    std::condition_variable done_cv;
    int running = threads;
    std::vector<std::thread> pool;
    for (int i = 0; i < threads; ++i)
      pool.emplace_back([&, i] {
        worker(i);
        std::lock_guard<std::mutex> lock(done_mutex);
        if (--running == 0) done_cv.notify_all();
      });
    if (opt.progress) {
      std::unique_lock<std::mutex> lock(done_mutex);
      while (running > 0 && !cancel.load()) {
        lock.unlock();
        if (!opt.progress(double(tiles_done.load()) / double(tile_count))) cancel = true;
        lock.lock();
        done_cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return running == 0; });
      }
    }
    for (auto& t : pool) t.join();
    if (cancel) throw Cancelled();
    if (opt.progress) opt.progress(1.0);
  }
  ThreadStats total;
  for (const ThreadStats& ts : tstats) {
    total.rays += ts.rays;
    total.hits += ts.hits;
    total.misses += ts.misses;
    total.covered += ts.covered;
    total.overlaps += ts.overlaps;
    total.backface_skips += ts.backface_skips;
    total.facing_away += ts.facing_away;
    st.thread_seconds_intersect += std::chrono::duration<double>(ts.intersect).count();
    st.thread_seconds_tiles += std::chrono::duration<double>(ts.tiles).count();
    total.dmin = std::min(total.dmin, ts.dmin);
    total.dmax = std::max(total.dmax, ts.dmax);
  }
  st.rays = total.rays;
  st.hits = total.hits;
  st.misses = total.misses;
  st.samples_covered = total.covered;
  st.overlapping_samples = total.overlaps;
  st.backface_skips = total.backface_skips;
  st.hits_facing_away = total.facing_away;
  if (total.hits) {
    st.hit_distance_min = total.dmin;
    st.hit_distance_max = total.dmax;
    double dsum = 0.0;
    for (double d : tile_dsum) dsum += d;
    st.hit_distance_mean = dsum / double(total.hits);
  }
  st.texels_total = std::size_t(W) * H;
  for (std::uint8_t c : result.coverage) st.texels_covered += c;
  st.coverage = double(st.texels_covered) / double(st.texels_total);
  st.seconds_trace = seconds_since(t0);
  st.cpu_seconds_trace = process_cpu_seconds() - cpu0;

  // Padding. Background (never reached by padding) stays the flat normal.
  t0 = Clock::now();
  const float flat[3] = {0.5f, 0.5f, opt.space == NormalSpace::tangent ? 1.0f : 0.5f};
  for (std::size_t i = 0; i < result.coverage.size(); ++i)
    if (!result.coverage[i])
      for (int c = 0; c < 3; ++c) result.map.pixels[3 * i + c] = flat[c];
  if (opt.space == NormalSpace::tangent)
    for (std::size_t i = 0; i < result.coverage.size(); ++i) st.texels_facing_away += result.coverage[i] && result.map.pixels[3 * i + 2] < 0.5f;
  find_suspects(opt, disagree, result);
  st.texels_padded = pad_islands(result.map, result.coverage, opt.padding, threads);
  st.seconds_padding = seconds_since(t0);
  return result;
}

// ---- Re-baking chosen texels (for the error estimate, error_estimate.h) ----
// The bake's own preparation, rays and shading (prepare, sample_rays, chosen_hit, shade_sample)
// for a list of texels; tests/test_error_estimate.cpp checks both agree texel for texel.
std::vector<glm::dvec3> bake_texel_values(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt,
                                          const BakeResult& baked, const std::vector<std::uint32_t>& texels, int samples) {
  const BakeStats& st = baked.stats;
  std::vector<glm::dvec3> out(texels.size(), glm::dvec3(0.0));
  if (texels.empty() || low.triangle_count() == 0 || high.triangle_count() == 0 || !low.has_uvs()) return out;
  const int threads = opt.threads > 0 ? opt.threads : std::max(1, int(std::thread::hardware_concurrency()));
  const int W = opt.width, H = opt.height;
  BakeStats scratch;
  Prepared s = prepare(low, high, cage, scratch);
  if (!cage && !baked.cage_positions.empty()) attach_cage(s, baked.cage_positions, low.position_index);  // the bake's automatic cage
  const bool any_cage = !s.cage_tris.empty();
  if (any_cage) set_cage_reach(s, low, st.rear, baked.vertex_rear, baked.vertex_search);
  if (st.high_facing == BakeStats::HighFacing::inverted) turn_inverted_high(s, scratch.high_normals_computed);
  // Few rays: a quick BVH build pays off more than a fast one to trace. All triangles: culling
  // leaves the hits unchanged.
  raycast::Scene scene(&s.high_pos[0].x, s.high_pos.size(), high.position_index.data(), high.triangle_count(),
                       raycast::BuildQuality::low, opt.threads);
  raycast::HitRule rule;
  rule.facing = s.high_facing.data();
  rule.corner_normals = s.high_corner_normals.data();
  const raycast::HitRule* const hit_rule = st.backfaces_skipped ? &rule : nullptr;
  RaySetup ray_setup;
  ray_setup.front = st.front;
  ray_setup.rear = st.rear;
  ray_setup.cage = any_cage;
  ray_setup.closest = opt.policy == RayPolicy::closest;
  ray_setup.diagonal = s.diagonal;
  const int rays_per_sample = ray_setup.closest ? 2 : 1;

  // Low-poly triangles binned to the tiles that hold a requested texel.
  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  std::vector<std::int32_t> tile_slot(std::size_t(tiles_x) * tiles_y, -1);
  std::int32_t used_tiles = 0;
  for (std::uint32_t t : texels) {
    const std::size_t tile = std::size_t((t / W) / kTile) * tiles_x + (t % W) / kTile;
    if (tile_slot[tile] < 0) tile_slot[tile] = used_tiles++;
  }
  std::vector<TexelTriangle> texel_tris(low.triangle_count());
  std::vector<std::vector<std::uint32_t>> bins(static_cast<std::size_t>(used_tiles));
  for (std::size_t t = 0; t < low.triangle_count(); ++t) {
    texel_tris[t] = setup_texel_triangle(low.corner_uv(t, 0), low.corner_uv(t, 1), low.corner_uv(t, 2), W, H);
    const TexelTriangle& tt = texel_tris[t];
    if (!tt.valid() || tt.xmax < tt.xmin || tt.ymax < tt.ymin) continue;
    for (int ty = tt.ymin / kTile; ty <= tt.ymax / kTile; ++ty)
      for (int tx = tt.xmin / kTile; tx <= tt.xmax / kTile; ++tx) {
        const std::int32_t slot = tile_slot[std::size_t(ty) * tiles_x + tx];
        if (slot >= 0) bins[std::size_t(slot)].push_back(std::uint32_t(t));  // ascending: the lowest index wins
      }
  }

  const std::vector<glm::dvec2> offsets = sample_offsets(samples);
  std::vector<std::uint8_t> covered(texels.size(), 0);  // each entry written by one thread only
  std::atomic<std::size_t> next{0};
  run_parallel(threads, [&](int) {
    struct Sample {
      std::size_t texel;  // index into `texels`
      std::uint32_t tri;
      double b[3];
    };
    std::vector<Sample> work;
    constexpr std::size_t kChunk = 64;
    // Sized for a chunk's most samples (each texel has at most one per offset); each chunk fills
    // the first work.size() * rays_per_sample rays.
    raycast::RayArrays arrays(kChunk * offsets.size() * std::size_t(rays_per_sample));
    const raycast::HitBatch hits = arrays.hits();
    std::vector<std::uint8_t> outward(rays_per_sample == 2 ? arrays.size() : 0);
    for (std::size_t i = 0; i < outward.size(); i += 2) outward[i] = 1;
    raycast::RayBatch ray_batch = arrays.rays();
    ray_batch.outward = outward.empty() ? nullptr : outward.data();
    std::vector<float> prefer_lo(arrays.size()), prefer_hi(arrays.size());
    ray_batch.prefer_lo = prefer_lo.data();
    ray_batch.prefer_hi = prefer_hi.data();
    std::vector<double> signed_base(arrays.size());
    for (std::size_t i0; (i0 = next.fetch_add(kChunk)) < texels.size();) {
      const std::size_t i1 = std::min(texels.size(), i0 + kChunk);
      work.clear();
      for (std::size_t i = i0; i < i1; ++i) {
        const int x = int(texels[i] % W), y = int(texels[i] / W);
        const auto& bin = bins[std::size_t(tile_slot[std::size_t(y / kTile) * tiles_x + x / kTile])];
        for (const glm::dvec2& o : offsets)
          for (std::uint32_t t : bin) {
            Sample sm{i, t, {0, 0, 0}};
            if (!covers(texel_tris[t], sample_point(x, y, o.x, o.y), sm.b)) continue;
            work.push_back(sm);
            break;
          }
      }
      for (std::size_t r = 0; r < work.size(); ++r) {
        raycast::Ray one[2];
        float lo[2], hi[2];
        const int n = sample_rays(s, work[r].tri, work[r].b, ray_setup, one, &signed_base[r * rays_per_sample], lo, hi);
        for (int j = 0; j < n; ++j) {
          const std::size_t i = r * rays_per_sample + std::size_t(j);
          arrays.set(i, one[j]);
          prefer_lo[i] = lo[j];
          prefer_hi[i] = hi[j];
        }
      }
      const std::size_t ray_count = work.size() * std::size_t(rays_per_sample);
      if (ray_count) scene.intersect(ray_batch, hits, ray_count, hit_rule);
      for (std::size_t r = 0; r < work.size(); ++r) {
        double dist = 0.0;
        const std::size_t h = chosen_hit(hits, r * rays_per_sample, signed_base.data(), ray_setup.closest, &dist);
        out[work[r].texel] += shade_sample(s, work[r].tri, work[r].b, arrays.hit(h), opt);
        covered[work[r].texel] = 1;
      }
      for (std::size_t i = i0; i < i1; ++i) {
        if (!covered[i]) continue;
        const double len = glm::length(out[i]);
        out[i] = len > 0.0 ? out[i] * (1.0 / len) : glm::dvec3(0, 0, 1);
        if (opt.space == NormalSpace::tangent && opt.green_down) out[i].y = -out[i].y;
      }
    }
  });
  return out;
}
// ---- end of re-baking chosen texels ----

}  // namespace nmbake
