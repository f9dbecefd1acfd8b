#include "bake.h"

#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <fstream>
#include <limits>
#include <mutex>
#include <sstream>
#include <thread>

#include "normals.h"
#include "padding.h"
#include "rasterize.h"
#include "raycast.h"

namespace nmbake {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

constexpr int kTile = 16;            // texels per tile side
// Tangent components this close to zero are written as exactly 0: a flat result is then
// (128,128,255) and not a coin flip between 127 and 128 decided by float noise.
constexpr double kSnap = 1e-6;

std::uint64_t available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  std::uint64_t value = 0;
  std::string unit;
  while (in >> key >> value >> unit)
    if (key == "MemAvailable:") return value * 1024;
  return std::numeric_limits<std::uint64_t>::max();
}

// What the trace loop reads of one low-poly triangle, in one place: re-centred corner positions,
// ray normals, and the tangent frame's corner normals and tangents.
struct LowTriangle {
  glm::vec3 p[3], ray_n[3], n[3];
  glm::vec4 t[3];
};

// The scene in re-centred float coordinates, flat arrays for the hot loop.
struct Prepared {
  glm::dvec3 centre{0.0};
  double diagonal = 0.0;
  std::vector<glm::vec3> low_pos, cage_pos, high_pos;
  std::vector<glm::vec3> ray_normal;  // per low-poly position: mean of its corners' normals
  std::vector<glm::vec3> high_corner_normals;  // 3 per high-poly triangle: one cache line per hit
  TangentFrames frames;
};

void grow_box(glm::dvec3& lo, glm::dvec3& hi, const std::vector<glm::vec3>& pts) {
  for (const glm::vec3& p : pts) {
    lo = glm::min(lo, glm::dvec3(p));
    hi = glm::max(hi, glm::dvec3(p));
  }
}

std::vector<glm::vec3> recentre(const std::vector<glm::vec3>& pts, const glm::dvec3& c) {
  std::vector<glm::vec3> out(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) out[i] = glm::vec3(glm::dvec3(pts[i]) - c);
  return out;
}

// Ray normals: one per position, the normalized mean of the distinct normals its corners use, so
// split normals (hard edges) open no gaps between the rays of neighbouring faces.
std::vector<glm::vec3> position_averaged_normals(const Mesh& low, const TangentFrames& frames) {
  const std::size_t np = low.positions.size();
  // A position whose corners all use one normal keeps it bit for bit; one with several gets the
  // normalized mean over its corners (a normal shared by more faces weighs more).
  std::vector<glm::vec3> out(np, glm::vec3(0, 0, 1));
  std::vector<std::uint8_t> state(np, 0);  // 0 unseen, 1 one normal so far, 2 several
  for (std::size_t c = 0; c < low.position_index.size(); ++c) {
    const std::uint32_t p = low.position_index[c];
    if (state[p] == 0) {
      state[p] = 1;
      out[p] = frames.normal[c];
    } else if (frames.normal[c] != out[p]) {
      state[p] = 2;
    }
  }
  std::vector<glm::dvec3> sum(np, glm::dvec3(0.0));
  for (std::size_t c = 0; c < low.position_index.size(); ++c)
    if (state[low.position_index[c]] == 2) sum[low.position_index[c]] += glm::dvec3(frames.normal[c]);
  for (std::size_t p = 0; p < np; ++p) {
    const double len = glm::length(sum[p]);
    if (state[p] == 2 && len > 1e-12) out[p] = glm::vec3(sum[p] / len);
  }
  return out;
}

double quantile(std::vector<float>& v, double q) {
  if (v.empty()) return 0.0;
  const std::size_t k = std::min(v.size() - 1, std::size_t(q * double(v.size() - 1)));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

template <typename Fn>
void run_parallel(int threads, Fn&& worker) {
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(worker, i);
  worker(0);
  for (auto& t : pool) t.join();
}

}  // namespace

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

std::uint64_t estimate_bake_bytes(const BakeOptions& o) {
  const std::uint64_t texels = std::uint64_t(std::max(o.width, 0)) * std::uint64_t(std::max(o.height, 0));
  // map (3 floats) + coverage (1 byte) + padding transform (double + int) + optional miss mask.
  std::uint64_t per_texel = 12 + 1 + (o.padding > 0 ? 12 : 0) + (o.miss_mask ? 4 : 0);
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
    const std::uint64_t avail = available_memory_bytes();
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
  Prepared s;
  s.frames = compute_tangent_frames(low);
  st.degenerate_uv_triangles = s.frames.degenerate_uv_triangles;
  st.degenerate_3d_triangles = s.frames.degenerate_3d_triangles;
  st.corners_without_tangent = s.frames.corners_without_tangent;
  {
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    grow_box(lo, hi, low.positions);
    grow_box(lo, hi, high.positions);
    if (cage) grow_box(lo, hi, cage->positions);
    s.centre = 0.5 * (lo + hi);
    st.centre = s.centre;
    s.diagonal = glm::length(hi - lo);
    if (!(s.diagonal > 0.0)) s.diagonal = 1.0;
  }
  s.low_pos = recentre(low.positions, s.centre);
  s.high_pos = recentre(high.positions, s.centre);
  if (cage) s.cage_pos = recentre(cage->positions, s.centre);
  s.ray_normal = position_averaged_normals(low, s.frames);
  {
    std::vector<glm::vec3> computed;
    if (!high.has_normals()) {
      computed = compute_vertex_normals(high);
      st.high_normals_computed = true;
    }
    const std::vector<glm::vec3>& normals = high.has_normals() ? high.normals : computed;
    const std::vector<std::uint32_t>& index = high.has_normals() ? high.normal_index : high.position_index;
    s.high_corner_normals.resize(index.size());
    for (std::size_t c = 0; c < index.size(); ++c) s.high_corner_normals[c] = normals[index[c]];
  }
  for (std::size_t t = 0; t < low.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      const glm::vec2 uv = low.corner_uv(t, c);
      if (uv.x < 0.0f || uv.x > 1.0f || uv.y < 0.0f || uv.y > 1.0f) {
        ++st.uv_outside_triangles;
        break;
      }
    }
  st.seconds_prepare = seconds_since(t0);

  // BVH over the high-poly.
  t0 = Clock::now();
  raycast::Scene scene(&s.high_pos[0].x, s.high_pos.size(), high.position_index.data(), high.triangle_count(),
                       raycast::BuildQuality::medium, opt.threads);
  st.seconds_bvh = seconds_since(t0);

  std::vector<LowTriangle> low_tris(low.triangle_count());
  for (std::size_t t = 0; t < low.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t pi = low.position_index[3 * t + c];
      low_tris[t].p[c] = s.low_pos[pi];
      low_tris[t].ray_n[c] = s.ray_normal[pi];
      low_tris[t].n[c] = s.frames.normal[3 * t + c];
      low_tris[t].t[c] = s.frames.tangent[3 * t + c];
    }
  auto low_point = [&](std::size_t tri, const double b[3]) {
    const LowTriangle& lt = low_tris[tri];
    return b[0] * glm::dvec3(lt.p[0]) + b[1] * glm::dvec3(lt.p[1]) + b[2] * glm::dvec3(lt.p[2]);
  };
  auto low_ray_normal = [&](std::size_t tri, const double b[3]) {
    const LowTriangle& lt = low_tris[tri];
    const glm::dvec3 n = b[0] * glm::dvec3(lt.ray_n[0]) + b[1] * glm::dvec3(lt.ray_n[1]) + b[2] * glm::dvec3(lt.ray_n[2]);
    const double len2 = glm::dot(n, n);
    if (len2 > 1e-24) return n / std::sqrt(len2);
    // Opposite corner normals cancel: fall back to the face normal.
    const glm::dvec3 f = glm::cross(glm::dvec3(lt.p[1]) - glm::dvec3(lt.p[0]), glm::dvec3(lt.p[2]) - glm::dvec3(lt.p[0]));
    const double fl = glm::length(f);
    return fl > 0.0 ? f / fl : glm::dvec3(0, 0, 1);
  };

  // Ray distances: given, or measured by probing along the ray normals from points on the low-poly.
  t0 = Clock::now();
  st.front = opt.front;
  st.rear = opt.rear;
  if (!cage && (opt.front < 0.0f || opt.rear < 0.0f)) {
    st.auto_distances = true;
    const double reach = 0.1 * s.diagonal;  // farther than this is another part of the model
    const std::size_t tris = low.triangle_count();
    const std::size_t stride = std::max<std::size_t>(1, tris / 50000);
    static const double probe_bary[4][3] = {{1 / 3.0, 1 / 3.0, 1 / 3.0}, {4 / 6.0, 1 / 6.0, 1 / 6.0},
                                            {1 / 6.0, 4 / 6.0, 1 / 6.0}, {1 / 6.0, 1 / 6.0, 4 / 6.0}};
    std::vector<raycast::Ray> rays;
    for (std::size_t t = 0; t < tris; t += stride)
      for (const auto& b : probe_bary) {
        const glm::dvec3 p = low_point(t, b), n = low_ray_normal(t, b);
        rays.push_back({glm::vec3(p), 0.0f, glm::vec3(n), float(reach)});
        rays.push_back({glm::vec3(p), 0.0f, glm::vec3(-n), float(reach)});
      }
    std::vector<raycast::Hit> hits(rays.size());
    const std::size_t pairs = rays.size() / 2;
    std::atomic<std::size_t> next{0};
    run_parallel(threads, [&](int) {
      for (std::size_t i; (i = next.fetch_add(4096)) < pairs;) {
        const std::size_t n = std::min<std::size_t>(4096, pairs - i);
        scene.intersect(&rays[2 * i], &hits[2 * i], 2 * n);
      }
    });
    std::vector<float> outside, inside;
    for (std::size_t i = 0; i < pairs; ++i) {
      const raycast::Hit& o = hits[2 * i];
      const raycast::Hit& in = hits[2 * i + 1];
      if (o.hit() && (!in.hit() || o.t <= in.t))
        outside.push_back(o.t);
      else if (in.hit())
        inside.push_back(in.t);
    }
    // Cover all but the farthest 0.1% of probes, with a 25% margin and a floor for coincident meshes.
    const double floor_dist = 1e-4 * s.diagonal;
    const double front = 1.25 * quantile(outside, 0.999) + floor_dist;
    const double rear = 1.25 * quantile(inside, 0.999) + floor_dist;
    if (opt.front < 0.0f) st.front = float(front);
    if (opt.rear < 0.0f) st.rear = float(rear);
    std::size_t beyond = 0;
    for (float d : outside) beyond += d > st.front;
    for (float d : inside) beyond += d > st.rear;
    st.auto_probe_beyond = pairs ? double(beyond) / double(pairs) : 0.0;
  }
  if (cage) {
    if (st.front < 0.0f) st.front = 0.0f;
    if (st.rear < 0.0f) st.rear = float(1e-4 * s.diagonal);
  }
  st.seconds_distances = seconds_since(t0);

  // Trace: tiles of texels, each rasterized against the triangles binned to it, rays in packets.
  t0 = Clock::now();
  const double cpu0 = process_cpu_seconds();
  const int W = opt.width, H = opt.height;
  const int tiles_x = (W + kTile - 1) / kTile, tiles_y = (H + kTile - 1) / kTile;
  const std::size_t tile_count = std::size_t(tiles_x) * tiles_y;
  std::vector<TexelTriangle> texel_tris(low.triangle_count());
  std::vector<std::uint32_t> bin_start(tile_count + 1, 0);
  for (std::size_t t = 0; t < low.triangle_count(); ++t) {
    texel_tris[t] = setup_texel_triangle(low.corner_uv(t, 0), low.corner_uv(t, 1), low.corner_uv(t, 2), W, H);
    const TexelTriangle& tt = texel_tris[t];
    if (!tt.valid() || tt.xmax < tt.xmin || tt.ymax < tt.ymin) continue;
    for (int ty = tt.ymin / kTile; ty <= tt.ymax / kTile; ++ty)
      for (int tx = tt.xmin / kTile; tx <= tt.xmax / kTile; ++tx) ++bin_start[std::size_t(ty) * tiles_x + tx + 1];
  }
  for (std::size_t i = 0; i < tile_count; ++i) bin_start[i + 1] += bin_start[i];
  std::vector<std::uint32_t> bin_tris(bin_start[tile_count]);
  {
    std::vector<std::uint32_t> fill(bin_start.begin(), bin_start.end() - 1);
    for (std::size_t t = 0; t < low.triangle_count(); ++t) {
      const TexelTriangle& tt = texel_tris[t];
      if (!tt.valid() || tt.xmax < tt.xmin || tt.ymax < tt.ymin) continue;
      for (int ty = tt.ymin / kTile; ty <= tt.ymax / kTile; ++ty)
        for (int tx = tt.xmin / kTile; tx <= tt.xmax / kTile; ++tx)
          bin_tris[fill[std::size_t(ty) * tiles_x + tx]++] = std::uint32_t(t);
    }
  }

  result.map = Image(W, H, 3, 0.0f);
  result.coverage.assign(std::size_t(W) * H, 0);
  if (opt.miss_mask) result.miss_mask = Image(W, H, 1, 0.0f);
  const std::vector<glm::dvec2> offsets = sample_offsets(opt.samples);
  const int S = int(offsets.size());
  const bool closest = opt.policy == RayPolicy::closest && !cage;
  const int rays_per_sample = closest ? 2 : 1;

  // One cache line each: the counters change per sample, and shared lines would serialize threads.
  struct alignas(64) ThreadStats {
    std::uint64_t rays = 0, hits = 0, misses = 0, covered = 0, overlaps = 0;
    double dmin = std::numeric_limits<double>::infinity(), dmax = -std::numeric_limits<double>::infinity(), dsum = 0.0;
  };
  std::vector<ThreadStats> tstats(threads);
  std::atomic<std::size_t> next_tile{0}, tiles_done{0};
  std::atomic<bool> cancel{false};
  std::mutex record_mutex;

  auto worker = [&](int id) {
    ThreadStats& ts = tstats[id];
    struct Slot {
      std::int32_t tri;
      double b[3];
    };
    std::vector<Slot> slots(std::size_t(kTile) * kTile * S);
    std::vector<raycast::Ray> rays;
    std::vector<raycast::Hit> hits;
    std::vector<std::uint32_t> slot_of_ray;
    std::vector<double> signed_base;  // per ray: distance from P to the ray origin along the ray
    std::vector<glm::dvec4> acc(std::size_t(kTile) * kTile);  // xyz sum, w = covered samples
    std::vector<std::uint32_t> miss_count(std::size_t(kTile) * kTile);
    for (std::size_t tile; !cancel.load(std::memory_order_relaxed) && (tile = next_tile.fetch_add(1)) < tile_count;) {
      const int tx0 = int(tile % tiles_x) * kTile, ty0 = int(tile / tiles_x) * kTile;
      const int tw = std::min(kTile, W - tx0), th = std::min(kTile, H - ty0);
      const std::uint32_t b0 = bin_start[tile], b1 = bin_start[tile + 1];
      if (b0 == b1) {
        ++tiles_done;
        continue;  // no triangle touches this tile: it costs nothing
      }
      for (Slot& sl : slots) sl.tri = -1;
      // Rasterize: the lowest triangle index wins a sample covered twice (overlapping islands).
      for (std::uint32_t bi = b0; bi < b1; ++bi) {
        const std::uint32_t t = bin_tris[bi];
        const TexelTriangle& tt = texel_tris[t];
        const int x0 = std::max(tt.xmin, tx0), x1 = std::min(tt.xmax, tx0 + tw - 1);
        const int y0 = std::max(tt.ymin, ty0), y1 = std::min(tt.ymax, ty0 + th - 1);
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x)
            for (int k = 0; k < S; ++k) {
              double b[3];
              if (!covers(tt, sample_point(x, y, offsets[k].x, offsets[k].y), b)) continue;
              Slot& sl = slots[(std::size_t(y - ty0) * kTile + (x - tx0)) * S + k];
              if (sl.tri >= 0) {
                ++ts.overlaps;
                continue;
              }
              sl.tri = std::int32_t(t);
              sl.b[0] = b[0];
              sl.b[1] = b[1];
              sl.b[2] = b[2];
            }
      }
      // Rays for the covered samples.
      rays.clear();
      slot_of_ray.clear();
      signed_base.clear();
      for (std::uint32_t si = 0; si < slots.size(); ++si) {
        const Slot& sl = slots[si];
        if (sl.tri < 0) continue;
        const glm::dvec3 p = low_point(std::size_t(sl.tri), sl.b);
        const glm::dvec3 n = low_ray_normal(std::size_t(sl.tri), sl.b);
        if (cage) {
          glm::dvec3 pc(0.0);
          for (int c = 0; c < 3; ++c) pc += sl.b[c] * glm::dvec3(s.cage_pos[low.position_index[3 * sl.tri + c]]);
          glm::dvec3 d = p - pc;
          double len = glm::length(d);
          // A cage point on the low-poly gives no direction: use the ray normal from P + front*N.
          if (!(len > 1e-9 * s.diagonal)) {
            d = -n;
            len = 0.0;
            pc = p;
          } else {
            d /= len;
          }
          rays.push_back({glm::vec3(pc), 0.0f, glm::vec3(d), float(len + st.rear)});
          signed_base.push_back(len);
        } else if (closest) {
          rays.push_back({glm::vec3(p), 0.0f, glm::vec3(n), st.front});
          signed_base.push_back(0.0);
          rays.push_back({glm::vec3(p), 0.0f, glm::vec3(-n), st.rear});
          signed_base.push_back(0.0);
        } else {
          rays.push_back({glm::vec3(p + double(st.front) * n), 0.0f, glm::vec3(-n), st.front + st.rear});
          signed_base.push_back(st.front);
        }
        slot_of_ray.push_back(si);
      }
      hits.resize(rays.size());
      if (!rays.empty()) scene.intersect(rays.data(), hits.data(), rays.size());
      if (opt.record_rays) {
        std::lock_guard<std::mutex> lock(record_mutex);
        opt.record_rays->insert(opt.record_rays->end(), rays.begin(), rays.end());
      }
      ts.rays += rays.size();
      // Shade: the high-poly normal at the hit, in the low-poly's tangent frame at P.
      std::fill(acc.begin(), acc.end(), glm::dvec4(0.0));
      std::fill(miss_count.begin(), miss_count.end(), 0u);
      for (std::size_t r = 0; r < slot_of_ray.size(); ++r) {
        const std::uint32_t si = slot_of_ray[r];
        const Slot& sl = slots[si];
        const std::size_t texel = si / S;
        const raycast::Hit* h = &hits[r * rays_per_sample];
        double dist = 0.0;
        if (closest) {
          const raycast::Hit& out = hits[2 * r];
          const raycast::Hit& in = hits[2 * r + 1];
          if (out.hit() && (!in.hit() || out.t <= in.t)) {
            h = &out;
            dist = out.t;
          } else {
            h = &in;
            dist = -double(in.t);
          }
        } else {
          dist = signed_base[r] - h->t;
        }
        const PixelFrame frame = interpolate_frame(low_tris[sl.tri].n, low_tris[sl.tri].t, sl.b, opt.bitangent);
        glm::dvec3 value;
        ++ts.covered;
        if (h->hit()) {
          ++ts.hits;
          ts.dmin = std::min(ts.dmin, dist);
          ts.dmax = std::max(ts.dmax, dist);
          ts.dsum += dist;
          const std::size_t ht = h->triangle;
          const double w[3] = {1.0 - double(h->u) - double(h->v), double(h->u), double(h->v)};
          glm::dvec3 nh(0.0);
          for (int c = 0; c < 3; ++c) nh += w[c] * glm::dvec3(s.high_corner_normals[3 * ht + c]);
          double len = glm::length(nh);
          if (!(len > 1e-12)) {
            const glm::dvec3 q0(s.high_pos[high.position_index[3 * ht]]), q1(s.high_pos[high.position_index[3 * ht + 1]]),
                q2(s.high_pos[high.position_index[3 * ht + 2]]);
            nh = glm::cross(q1 - q0, q2 - q0);
            len = glm::length(nh);
          }
          nh = len > 0.0 ? nh / len : glm::normalize(frame.n);
          value = opt.space == NormalSpace::tangent ? encode_tangent_normal(frame, nh) : nh;
        } else {
          ++ts.misses;
          ++miss_count[texel];
          const double nl = glm::length(frame.n);
          value = opt.space == NormalSpace::tangent ? glm::dvec3(0, 0, 1) : (nl > 0 ? frame.n / nl : glm::dvec3(0, 0, 1));
        }
        acc[texel] += glm::dvec4(value, 1.0);
      }
      // Texels: renormalized mean of their covered samples.
      for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x) {
          const std::size_t lt = std::size_t(y) * kTile + x;
          if (acc[lt].w == 0.0) continue;
          glm::dvec3 v(acc[lt]);
          const double len = glm::length(v);
          v = len > 0.0 ? v / len : glm::dvec3(0, 0, 1);
          if (opt.space == NormalSpace::tangent && opt.green_down) v.y = -v.y;
          for (int c = 0; c < 3; ++c)
            if (std::abs(v[c]) < kSnap) v[c] = 0.0;
          const std::size_t gi = std::size_t(ty0 + y) * W + (tx0 + x);
          float* px = result.map.at(tx0 + x, ty0 + y);
          for (int c = 0; c < 3; ++c) px[c] = float(v[c] * 0.5 + 0.5);
          result.coverage[gi] = 1;
          if (opt.miss_mask) result.miss_mask.pixels[gi] = float(miss_count[lt]) / float(acc[lt].w);
        }
      ++tiles_done;
    }
  };

  {
    std::vector<std::thread> pool;
    for (int i = 0; i < threads; ++i) pool.emplace_back(worker, i);
    if (opt.progress) {
      while (tiles_done.load() < tile_count && !cancel.load()) {
        if (!opt.progress(double(tiles_done.load()) / double(tile_count))) cancel = true;
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
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
    total.dmin = std::min(total.dmin, ts.dmin);
    total.dmax = std::max(total.dmax, ts.dmax);
    total.dsum += ts.dsum;
  }
  st.rays = total.rays;
  st.hits = total.hits;
  st.misses = total.misses;
  st.samples_covered = total.covered;
  st.overlapping_samples = total.overlaps;
  if (total.hits) {
    st.hit_distance_min = total.dmin;
    st.hit_distance_max = total.dmax;
    st.hit_distance_mean = total.dsum / double(total.hits);
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
  st.texels_padded = pad_islands(result.map, result.coverage, opt.padding);
  st.seconds_padding = seconds_since(t0);
  return result;
}

// ---- Re-baking chosen texels (for the error estimate, error_estimate.h) ----
// A copy of the trace loop's ray and shading rules for a list of texels, so that the bake's own
// loop stays untouched; tests/test_error_estimate.cpp checks that both agree texel for texel.
std::vector<glm::dvec3> bake_texel_values(const Mesh& low, const Mesh& high, const Mesh* cage, const BakeOptions& opt,
                                          const BakeStats& st, const std::vector<std::uint32_t>& texels, int samples) {
  std::vector<glm::dvec3> out(texels.size(), glm::dvec3(0.0));
  if (texels.empty() || low.triangle_count() == 0 || high.triangle_count() == 0 || !low.has_uvs()) return out;
  const int threads = opt.threads > 0 ? opt.threads : std::max(1, int(std::thread::hardware_concurrency()));
  const int W = opt.width, H = opt.height;
  const TangentFrames frames = compute_tangent_frames(low);
  const std::vector<glm::vec3> low_pos = recentre(low.positions, st.centre);
  const std::vector<glm::vec3> high_pos = recentre(high.positions, st.centre);
  const std::vector<glm::vec3> cage_pos = cage ? recentre(cage->positions, st.centre) : std::vector<glm::vec3>();
  const std::vector<glm::vec3> ray_normal = position_averaged_normals(low, frames);
  std::vector<glm::vec3> high_corner_normals;
  {
    const std::vector<glm::vec3> computed = high.has_normals() ? std::vector<glm::vec3>() : compute_vertex_normals(high);
    const std::vector<glm::vec3>& normals = high.has_normals() ? high.normals : computed;
    const std::vector<std::uint32_t>& index = high.has_normals() ? high.normal_index : high.position_index;
    high_corner_normals.resize(index.size());
    for (std::size_t c = 0; c < index.size(); ++c) high_corner_normals[c] = normals[index[c]];
  }
  double diagonal = 0.0;
  {
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    grow_box(lo, hi, low.positions);
    grow_box(lo, hi, high.positions);
    if (cage) grow_box(lo, hi, cage->positions);
    diagonal = glm::length(hi - lo);
    if (!(diagonal > 0.0)) diagonal = 1.0;
  }
  // Few rays: a quick BVH build pays off more than a fast one to trace.
  raycast::Scene scene(&high_pos[0].x, high_pos.size(), high.position_index.data(), high.triangle_count(),
                       raycast::BuildQuality::low, opt.threads);

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
  const bool closest = opt.policy == RayPolicy::closest && !cage;
  std::vector<std::uint8_t> covered(texels.size(), 0);  // each entry written by one thread only
  std::atomic<std::size_t> next{0};
  run_parallel(threads, [&](int) {
    struct Sample {
      std::size_t texel;  // index into `texels`
      std::uint32_t tri;
      double b[3];
    };
    std::vector<Sample> work;
    std::vector<raycast::Ray> rays;
    std::vector<raycast::Hit> hits;
    constexpr std::size_t kChunk = 64;
    for (std::size_t i0; (i0 = next.fetch_add(kChunk)) < texels.size();) {
      const std::size_t i1 = std::min(texels.size(), i0 + kChunk);
      work.clear();
      rays.clear();
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
      for (const Sample& sm : work) {
        glm::dvec3 p(0.0), n(0.0);
        for (int c = 0; c < 3; ++c) {
          const std::uint32_t pi = low.position_index[3 * sm.tri + c];
          p += sm.b[c] * glm::dvec3(low_pos[pi]);
          n += sm.b[c] * glm::dvec3(ray_normal[pi]);
        }
        if (glm::dot(n, n) > 1e-24) {
          n /= std::sqrt(glm::dot(n, n));
        } else {
          const glm::dvec3 p0(low_pos[low.position_index[3 * sm.tri]]), p1(low_pos[low.position_index[3 * sm.tri + 1]]),
              p2(low_pos[low.position_index[3 * sm.tri + 2]]);
          const glm::dvec3 f = glm::cross(p1 - p0, p2 - p0);
          n = glm::length(f) > 0.0 ? f / glm::length(f) : glm::dvec3(0, 0, 1);
        }
        if (cage) {
          glm::dvec3 pc(0.0);
          for (int c = 0; c < 3; ++c) pc += sm.b[c] * glm::dvec3(cage_pos[low.position_index[3 * sm.tri + c]]);
          glm::dvec3 d = p - pc;
          double len = glm::length(d);
          if (!(len > 1e-9 * diagonal)) {
            d = -n;
            len = 0.0;
            pc = p;
          } else {
            d /= len;
          }
          rays.push_back({glm::vec3(pc), 0.0f, glm::vec3(d), float(len + st.rear)});
        } else if (closest) {
          rays.push_back({glm::vec3(p), 0.0f, glm::vec3(n), st.front});
          rays.push_back({glm::vec3(p), 0.0f, glm::vec3(-n), st.rear});
        } else {
          rays.push_back({glm::vec3(p + double(st.front) * n), 0.0f, glm::vec3(-n), st.front + st.rear});
        }
      }
      hits.resize(rays.size());
      if (!rays.empty()) scene.intersect(rays.data(), hits.data(), rays.size());
      for (std::size_t r = 0; r < work.size(); ++r) {
        const Sample& sm = work[r];
        const raycast::Hit* h = &hits[closest ? 2 * r : r];
        if (closest && !(h->hit() && (!hits[2 * r + 1].hit() || h->t <= hits[2 * r + 1].t))) h = &hits[2 * r + 1];
        glm::vec3 cn[3];
        glm::vec4 ct[3];
        for (int c = 0; c < 3; ++c) {
          cn[c] = frames.normal[3 * sm.tri + c];
          ct[c] = frames.tangent[3 * sm.tri + c];
        }
        const PixelFrame frame = interpolate_frame(cn, ct, sm.b, opt.bitangent);
        glm::dvec3 value;
        if (h->hit()) {
          const std::size_t ht = h->triangle;
          const double w[3] = {1.0 - double(h->u) - double(h->v), double(h->u), double(h->v)};
          glm::dvec3 nh(0.0);
          for (int c = 0; c < 3; ++c) nh += w[c] * glm::dvec3(high_corner_normals[3 * ht + c]);
          double len = glm::length(nh);
          if (!(len > 1e-12)) {
            const glm::dvec3 q0(high_pos[high.position_index[3 * ht]]), q1(high_pos[high.position_index[3 * ht + 1]]),
                q2(high_pos[high.position_index[3 * ht + 2]]);
            nh = glm::cross(q1 - q0, q2 - q0);
            len = glm::length(nh);
          }
          nh = len > 0.0 ? nh / len : glm::normalize(frame.n);
          value = opt.space == NormalSpace::tangent ? encode_tangent_normal(frame, nh) : nh;
        } else {
          const double nl = glm::length(frame.n);
          value = opt.space == NormalSpace::tangent ? glm::dvec3(0, 0, 1) : (nl > 0 ? frame.n / nl : glm::dvec3(0, 0, 1));
        }
        out[sm.texel] += value;
        covered[sm.texel] = 1;
      }
      for (std::size_t i = i0; i < i1; ++i) {
        if (!covered[i]) continue;
        const double len = glm::length(out[i]);
        out[i] = len > 0.0 ? out[i] / len : glm::dvec3(0, 0, 1);
        if (opt.space == NormalSpace::tangent && opt.green_down) out[i].y = -out[i].y;
      }
    }
  });
  return out;
}
// ---- end of re-baking chosen texels ----

}  // namespace nmbake
