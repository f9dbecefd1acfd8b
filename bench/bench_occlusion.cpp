// bench_occlusion: the occlusion rays of an ambient-occlusion bake, traced by the simplest bare
// Embree loop (rtcOccluded1 per ray, in a scene of its own) and by raycast::Scene::occluded, with
// rays per second and their ratio; --variants adds the other ways Embree 3 takes such rays (packets
// of 8 and 16, streams, octant-sorted packets), which chose Scene::occluded's.
//
// The rays: points on the high-poly in runs of neighbouring triangles (the triangles sorted along
// a Morton curve of their centroids, a run of them taken whole: as a tile of the bake's texels
// lands on the high-poly), one point per triangle, and from each point N cosine-weighted
// directions about its interpolated normal, tfar = the AO distance: ray i * N + k is point i's
// k-th ray, the order the bake casts them in. Single-threaded by default (rays per second of one
// core); the lanes of the comparison run interleaved, the best of the rounds kept.
//
// --from-bake SIZE: the rays of the bake itself instead. The 1M-triangle pair (the sculpt's low.obj
// onto its high-poly subdivided) is baked at SIZE^2, 1 sample, by the library: the normal map alone,
// then normal + ao with --rays rays per texel, each the best of the rounds, so that the AO's share
// of the trace stage is their difference; then normal + position + object-normal give each covered
// texel's hit point and interpolated high-poly normal, and from them as many AO rays per texel as
// the bake casts, of the same distribution (texel-keyed random streams, cosine-weighted about the
// normal, tfar the bake's AO distance; the start offset along the interpolated normal, where the bake
// takes the face's), in texel order. Not the bake's own directions: those are stratified chains
// (texel_maps.h); the occlusion work per ray is the same. The bare loop, rtcOccluded1 per ray on a default Embree scene of the
// high-poly, traces them on the same threads; only the Embree calls are timed (the rays are made per chunk outside the clock).
// Prints both times and their ratio.
//
// usage: bench_occlusion [--sculpt DIR] [--subdivide N] [--points P] [--rays N] [--distance F]
//                        [--rounds R] [--threads T] [--chunk C] [--variants] [--from-bake SIZE]
#include <embree3/rtcore.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <numeric>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "bench_support.h"
#include "core/hemisphere.h"
#include "core/parallel.h"
#include "io/mesh_io.h"
#include "pipeline/bake.h"
#include "raycast.h"
#include "tests/build_paths.h"

using namespace nmbake;
using nmbake::bench::Clock;
using nmbake::bench::since;

namespace {

struct Args {
  std::string sculpt = std::string(nmbake::build::shared_data_dir()) + "/sculpts/suz_L4";
  int subdivide = 1;  // suz_L4 (251,904 triangles) once: 1,007,616
  std::size_t points = 32768;
  int rays = 64;
  double distance = 0.1;  // of the high-poly's bounding-box diagonal
  int rounds = 3;
  int threads = 1;
  bool variants = false;
  int from_bake = 0;         // map side of the bake whose AO rays are traced; 0: the synthetic rays
  std::size_t chunk = 4096;  // rays per call (64 points' rays)
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    auto value = [&]() -> const char* {
      if (i + 1 >= argc) throw std::runtime_error(s + " needs a value");
      return argv[++i];
    };
    if (s == "--sculpt") a.sculpt = value();
    else if (s == "--subdivide") a.subdivide = std::atoi(value());
    else if (s == "--points") a.points = std::size_t(std::atoll(value()));
    else if (s == "--rays") a.rays = std::atoi(value());
    else if (s == "--distance") a.distance = std::atof(value());
    else if (s == "--rounds") a.rounds = std::atoi(value());
    else if (s == "--threads") a.threads = std::max(1, std::atoi(value()));
    else if (s == "--variants") a.variants = true;
    else if (s == "--from-bake") a.from_bake = std::atoi(value());
    else if (s == "--chunk") a.chunk = std::size_t(std::atoll(value()));
    else throw std::runtime_error("unknown argument " + s);
  }
  return a;
}

// The rays as arrays (the layout of raycast::RayBatch).
struct Rays {
  std::vector<float> ox, oy, oz, dx, dy, dz, tnear, tfar;
  std::size_t size() const { return ox.size(); }
  raycast::RayBatch batch(std::size_t first) const {
    return {ox.data() + first, oy.data() + first, oz.data() + first,    dx.data() + first,
            dy.data() + first, dz.data() + first, tnear.data() + first, tfar.data() + first};
  }
};

std::uint32_t spread_bits(std::uint32_t x) {  // 10 bits to every third of 30
  x &= 0x3ff;
  x = (x | (x << 16)) & 0x030000ff;
  x = (x | (x << 8)) & 0x0300f00f;
  x = (x | (x << 4)) & 0x030c30c3;
  x = (x | (x << 2)) & 0x09249249;
  return x;
}

// Points in runs of Morton-neighbouring triangles, N directions from each (inverted: about the
// inverted normal, from just under the surface, as thickness casts them).
Rays make_rays(const Mesh& m, const Args& args, bool inverted, double& diagonal) {
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  diagonal = double(glm::length(hi - lo));
  const std::size_t tris = m.triangle_count();
  std::vector<std::pair<std::uint32_t, std::uint32_t>> code(tris);
  for (std::size_t t = 0; t < tris; ++t) {
    const glm::vec3 c = (m.corner_position(t, 0) + m.corner_position(t, 1) + m.corner_position(t, 2)) / 3.0f;
    const glm::vec3 q = (c - lo) / glm::max(hi - lo, glm::vec3(1e-30f)) * 1023.0f;
    code[t] = {spread_bits(std::uint32_t(q.x)) | spread_bits(std::uint32_t(q.y)) << 1 | spread_bits(std::uint32_t(q.z)) << 2,
               std::uint32_t(t)};
  }
  std::sort(code.begin(), code.end());
  // Runs of 4096 triangles at even spacing along the curve.
  const std::size_t run = std::min<std::size_t>(4096, args.points), runs = (args.points + run - 1) / run;
  const std::size_t count = std::min(args.points, tris);
  Rays r;
  const std::size_t n = count * std::size_t(args.rays);
  for (auto* v : {&r.ox, &r.oy, &r.oz, &r.dx, &r.dy, &r.dz, &r.tnear, &r.tfar}) v->resize(n);
  const float eps = float(1e-6 * diagonal), tfar = float(args.distance * diagonal);
  for (std::size_t i = 0; i < count; ++i) {
    const std::size_t start = (i / run) * (tris / runs);
    const std::uint32_t t = code[std::min(tris - 1, start + i % run)].second;
    SampleStream s(sample_key(i, 0, 7));
    double b1 = s.next(), b2 = s.next();
    if (b1 + b2 > 1.0) b1 = 1.0 - b1, b2 = 1.0 - b2;
    const float w1 = float(b1), w2 = float(b2), w0 = 1.0f - w1 - w2;
    const glm::vec3 p = w0 * m.corner_position(t, 0) + w1 * m.corner_position(t, 1) + w2 * m.corner_position(t, 2);
    glm::vec3 nrm = w0 * m.corner_normal(t, 0) + w1 * m.corner_normal(t, 1) + w2 * m.corner_normal(t, 2);
    nrm = inverted ? -glm::normalize(nrm) : glm::normalize(nrm);
    const glm::vec3 o = p + eps * nrm;
    for (int k = 0; k < args.rays; ++k) {
      const std::size_t j = i * std::size_t(args.rays) + std::size_t(k);
      SampleStream d(sample_key(i, std::uint64_t(k), 1));
      const double u1 = d.next();
      const glm::vec3 dir = cosine_direction(nrm, u1, d.next());
      r.ox[j] = o.x, r.oy[j] = o.y, r.oz[j] = o.z;
      r.dx[j] = dir.x, r.dy[j] = dir.y, r.dz[j] = dir.z;
      r.tnear[j] = 0.0f, r.tfar[j] = tfar;
    }
  }
  return r;
}

// An Embree scene of its own for the bare loops.
struct BareScene {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  BareScene(const Mesh& m, RTCSceneFlags flags) {
    device = rtcNewDevice(nullptr);
    if (!device) throw std::runtime_error("embree: no device");
    scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, flags);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), m.positions.size()));
    std::memcpy(vb, m.positions.data(), m.positions.size() * 3 * sizeof(float));
    auto* ib = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), m.triangle_count()));
    std::memcpy(ib, m.position_index.data(), m.position_index.size() * sizeof(std::uint32_t));
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
  }
  ~BareScene() {
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
  }
  BareScene(const BareScene&) = delete;
  BareScene& operator=(const BareScene&) = delete;
};

RTCRay embree_ray(const Rays& r, std::size_t j, unsigned id) {
  RTCRay ray;
  ray.org_x = r.ox[j], ray.org_y = r.oy[j], ray.org_z = r.oz[j], ray.tnear = r.tnear[j];
  ray.dir_x = r.dx[j], ray.dir_y = r.dy[j], ray.dir_z = r.dz[j], ray.time = 0.0f;
  ray.tfar = r.tfar[j], ray.mask = 0xffffffffu, ray.id = id, ray.flags = 0;
  return ray;
}

// The lanes of the comparison: each occludes rays [first, first + n) into out.
using Lane = std::function<void(const Rays&, std::size_t first, std::size_t n, std::uint8_t* out)>;

// rtcOccluded1 per ray: the simplest loop.
Lane single(RTCScene scene) {
  return [scene](const Rays& r, std::size_t first, std::size_t n, std::uint8_t* out) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    for (std::size_t j = first; j < first + n; ++j) {
      RTCRay ray = embree_ray(r, j, 0);
      rtcOccluded1(scene, &ctx, &ray);
      out[j] = ray.tfar < 0.0f;
    }
  };
}

// Packets of W consecutive rays (W = 8 or 16), with the context flag given; `octants` sorts
// each point's rays by the octant of their direction first (stable), so a packet's rays share
// an origin and an octant.
template <int W, typename Packet, void (*Occluded)(const int*, RTCScene, RTCIntersectContext*, Packet*)>
Lane packets(RTCScene scene, RTCIntersectContextFlags flags, bool octants, int per_point) {
  return [=](const Rays& r, std::size_t first, std::size_t n, std::uint8_t* out) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = flags;
    alignas(64) Packet p;
    alignas(64) int valid[W];
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), std::uint32_t(first));
    if (octants) {
      for (std::size_t b = 0; b < n; b += std::size_t(per_point)) {
        const std::size_t e = std::min(n, b + std::size_t(per_point));
        auto oct = [&](std::uint32_t j) { return (r.dx[j] < 0.0f) | (r.dy[j] < 0.0f) << 1 | (r.dz[j] < 0.0f) << 2; };
        std::stable_sort(order.begin() + long(b), order.begin() + long(e),
                         [&](std::uint32_t a, std::uint32_t c) { return oct(a) < oct(c); });
      }
    }
    for (std::size_t b = 0; b < n; b += W) {
      const std::size_t m = std::min<std::size_t>(W, n - b);
      for (std::size_t k = 0; k < W; ++k) {
        const std::uint32_t j = order[b + std::min(k, m - 1)];
        valid[k] = k < m ? -1 : 0;
        p.org_x[k] = r.ox[j], p.org_y[k] = r.oy[j], p.org_z[k] = r.oz[j], p.tnear[k] = r.tnear[j];
        p.dir_x[k] = r.dx[j], p.dir_y[k] = r.dy[j], p.dir_z[k] = r.dz[j], p.time[k] = 0.0f;
        p.tfar[k] = r.tfar[j], p.mask[k] = 0xffffffffu, p.id[k] = unsigned(k), p.flags[k] = 0;
      }
      Occluded(valid, scene, &ctx, &p);
      for (std::size_t k = 0; k < m; ++k) out[order[b + k]] = p.tfar[k] < 0.0f;
    }
  };
}

// rtcOccluded1M: the chunk as one stream of RTCRay structs.
Lane stream_1m(RTCScene scene, RTCIntersectContextFlags flags) {
  return [=](const Rays& r, std::size_t first, std::size_t n, std::uint8_t* out) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = flags;
    std::vector<RTCRay> rays(n);
    for (std::size_t k = 0; k < n; ++k) rays[k] = embree_ray(r, first + k, unsigned(k));
    rtcOccluded1M(scene, &ctx, rays.data(), unsigned(n), sizeof(RTCRay));
    for (std::size_t k = 0; k < n; ++k) out[first + k] = rays[k].tfar < 0.0f;
  };
}

// rtcOccludedNp: the chunk as one stream of arrays (tfar copied: Embree writes it).
Lane stream_np(RTCScene scene, RTCIntersectContextFlags flags) {
  return [=](const Rays& r, std::size_t first, std::size_t n, std::uint8_t* out) {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = flags;
    std::vector<float> tfar(r.tfar.begin() + long(first), r.tfar.begin() + long(first + n)), time(n, 0.0f);
    std::vector<unsigned> mask(n, 0xffffffffu), id(n), fl(n, 0);
    std::iota(id.begin(), id.end(), 0u);
    RTCRayNp p;
    p.org_x = const_cast<float*>(r.ox.data() + first), p.org_y = const_cast<float*>(r.oy.data() + first);
    p.org_z = const_cast<float*>(r.oz.data() + first), p.tnear = const_cast<float*>(r.tnear.data() + first);
    p.dir_x = const_cast<float*>(r.dx.data() + first), p.dir_y = const_cast<float*>(r.dy.data() + first);
    p.dir_z = const_cast<float*>(r.dz.data() + first), p.time = time.data(), p.tfar = tfar.data();
    p.mask = mask.data(), p.id = id.data(), p.flags = fl.data();
    rtcOccludedNp(scene, &ctx, &p, unsigned(n));
    for (std::size_t k = 0; k < n; ++k) out[first + k] = tfar[k] < 0.0f;
  };
}

// raycast::Scene::occluded, with or without a group array (all in group 0: the filter's cost).
Lane api(const raycast::Scene& scene, const std::uint32_t* group, const std::uint32_t* ray_group) {
  return [&scene, group, ray_group](const Rays& r, std::size_t first, std::size_t n, std::uint8_t* out) {
    raycast::RayBatch b = r.batch(first);
    if (ray_group) b.group = ray_group + first;
    raycast::SecondaryRayOptions o;
    o.group = group;
    scene.occluded(b, out + first, n, o);
  };
}

// One lane's pass over all rays with `threads` threads, in chunks of `chunk` rays (whole points);
// seconds of wall time.
double run_lane(const Lane& lane, const Rays& r, std::uint8_t* out, int threads, std::size_t chunk) {
  std::atomic<std::size_t> next{0};
  const auto t0 = Clock::now();
  auto work = [&] {
    for (std::size_t i; (i = next.fetch_add(chunk)) < r.size();) lane(r, i, std::min(chunk, r.size() - i), out);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  return since(t0);
}

// Thickness's rays (inverted normals, from just under the surface): the first hit's distance by
// rtcIntersect1 per ray (default scene), by Scene::intersect without a rule, under a rule that
// keeps back faces (skip_backfaces = false) and under that rule with groups (all 0), and by
// Scene::first_hits (the bake's), without and with groups. Distances
// compared to the bare loop's within 1e-5 (relative): the default scene rounds differently from
// the robust one.
void thickness(const Mesh& high, const Args& args, RTCScene bare, const raycast::Scene& scene, std::size_t chunk) {
  double diagonal = 0;
  const Rays r = make_rays(high, args, true, diagonal);
  std::vector<std::uint32_t> tri_group(high.triangle_count(), 0), ray_group(r.size(), 0);
  raycast::HitRule keep, grouped;
  keep.skip_backfaces = false;
  grouped.skip_backfaces = false;
  grouped.group = tri_group.data();
  std::vector<float> t(r.size()), u(r.size()), v(r.size());
  std::vector<std::uint32_t> tri(r.size());
  using Cast = std::function<void(std::size_t first, std::size_t n)>;
  auto with = [&](const raycast::HitRule* rule, bool groups) -> Cast {
    return [&, rule, groups](std::size_t first, std::size_t n) {
      raycast::RayBatch b = r.batch(first);
      if (groups) b.group = ray_group.data() + first;
      scene.intersect(b, {tri.data() + first, t.data() + first, u.data() + first, v.data() + first}, n, rule);
    };
  };
  struct Row {
    const char* name;
    Cast cast;
    double best;
    std::vector<float> t;
  };
  std::vector<Row> rows;
  rows.push_back({"bare: rtcIntersect1 per ray, default scene",
                  [&](std::size_t first, std::size_t n) {
                    RTCIntersectContext ctx;
                    rtcInitIntersectContext(&ctx);
                    for (std::size_t j = first; j < first + n; ++j) {
                      RTCRayHit rh;
                      rh.ray = embree_ray(r, j, 0);
                      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                      rtcIntersect1(bare, &ctx, &rh);
                      t[j] = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh.ray.tfar : -1.0f;
                    }
                  },
                  1e30,
                  {}});
  rows.push_back({"Scene::intersect, no rule", with(nullptr, false), 1e30, {}});
  rows.push_back({"Scene::intersect, HitRule{skip_backfaces = false}", with(&keep, false), 1e30, {}});
  rows.push_back({"Scene::intersect, that rule with groups (all 0)", with(&grouped, true), 1e30, {}});
  // What the bake casts (texel_maps.cpp): first_hits in the secondary rays' BVH.
  auto fast = [&](bool groups) -> Cast {
    return [&, groups](std::size_t first, std::size_t n) {
      raycast::RayBatch b = r.batch(first);
      if (groups) b.group = ray_group.data() + first;
      raycast::SecondaryRayOptions o;
      o.group = groups ? tri_group.data() : nullptr;
      scene.first_hits(b, {tri.data() + first, t.data() + first, u.data() + first, v.data() + first}, n, o);
    };
  };
  rows.push_back({"Scene::first_hits (the bake's)", fast(false), 1e30, {}});
  rows.push_back({"Scene::first_hits, groups (all 0)", fast(true), 1e30, {}});
  for (int round = 0; round < args.rounds; ++round)
    for (Row& row : rows) {
      std::atomic<std::size_t> next{0};
      const auto t0 = Clock::now();
      auto work = [&] {
        for (std::size_t i; (i = next.fetch_add(chunk)) < r.size();) row.cast(i, std::min(chunk, r.size() - i));
      };
      std::vector<std::thread> pool;
      for (int k = 1; k < args.threads; ++k) pool.emplace_back(work);
      work();
      for (auto& th : pool) th.join();
      row.best = std::min(row.best, since(t0));
      if (&row != &rows[0])
        for (std::size_t i = 0; i < r.size(); ++i) t[i] = tri[i] != raycast::no_hit ? t[i] : -1.0f;
      row.t = t;
    }
  std::size_t hit = 0;
  for (float x : rows[0].t) hit += x >= 0.0f;
  std::printf(
      "\nthickness rays (inverted normals, tfar %.3g): %.1f%% hit\n\n| lane | Mrays/s | time / bare | distances differing from "
      "bare |\n"
      "|---|---|---|---|\n",
      args.distance * diagonal, 100.0 * double(hit) / double(r.size()));
  for (const Row& row : rows) {
    std::size_t diff = 0;
    for (std::size_t i = 0; i < r.size(); ++i)
      diff += std::fabs(row.t[i] - rows[0].t[i]) > 1e-5f * std::max(1.0f, std::fabs(rows[0].t[i]));
    std::printf("| %s | %.2f | %.3f | %zu |\n", row.name, double(r.size()) / row.best * 1e-6, row.best / rows[0].best, diff);
  }
}

// --from-bake: the bake's own AO rays, the bake's AO trace against the bare loop over them.
void from_bake(const Mesh& high, const Args& args, RTCScene bare) {
  LoadOptions lo;
  lo.require_uvs = true;
  const Mesh low = load_mesh(args.sculpt + "/low.obj", lo);
  BakeOptions o;
  o.width = o.height = args.from_bake;
  o.threads = args.threads;
  o.maps.ao_rays = args.rays;
  const auto trace_seconds = [&](std::vector<MapKind> maps, BakeResult* keep) {
    o.maps.maps = std::move(maps);
    double best = 1e30;
    for (int round = 0; round < args.rounds; ++round) {
      BakeResult r = bake_normal_map(low, high, nullptr, o);
      best = std::min(best, r.stats.trace.seconds);
      if (keep && round == 0) *keep = std::move(r);
    }
    return best;
  };
  BakeResult ao;
  const double t_normal = trace_seconds({MapKind::normal}, nullptr);
  const double t_ao = trace_seconds({MapKind::normal, MapKind::ao}, &ao);
  const double distance = ao.maps.at(0).distance;
  o.maps.maps = {MapKind::normal, MapKind::position, MapKind::object_normal};
  const BakeResult hits = bake_normal_map(low, high, nullptr, o);
  const BakedMap &pos = hits.maps.at(0), &nrm = hits.maps.at(1);

  // Per covered texel: its hit point (mesh coordinates) and normal.
  std::vector<std::uint32_t> texels;
  for (std::size_t t = 0; t < hits.coverage.size(); ++t)
    if (hits.coverage[t]) texels.push_back(std::uint32_t(t));
  glm::dvec3 box_lo(1e300), box_hi(-1e300);
  for (const glm::vec3& p : high.positions) box_lo = glm::min(box_lo, glm::dvec3(p)), box_hi = glm::max(box_hi, glm::dvec3(p));
  const double eps = 1e-5 * glm::length(box_hi - box_lo);
  const glm::dvec3 lo_box = pos.box_min - high.origin, extent = pos.box_max - pos.box_min;
  const std::size_t per = std::size_t(args.rays), chunk_texels = std::max<std::size_t>(1, args.chunk / per);
  std::atomic<std::size_t> next{0}, occluded{0};
  std::vector<double> busy(std::size_t(worker_threads(args.threads)), 0.0);
  run_on_threads(int(busy.size()), [&](int id) {
    Rays r;
    for (auto* v : {&r.ox, &r.oy, &r.oz, &r.dx, &r.dy, &r.dz, &r.tnear, &r.tfar}) v->resize(chunk_texels * per);
    std::vector<std::uint8_t> out(chunk_texels * per);
    const Lane lane = single(bare);
    std::size_t hit = 0;
    for (std::size_t first; (first = next.fetch_add(chunk_texels)) < texels.size();) {
      const std::size_t n = std::min(chunk_texels, texels.size() - first);
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t t = texels[first + k];
        const float* p = &pos.image.pixels[3 * t];
        const float* c = &nrm.image.pixels[3 * t];
        const glm::dvec3 x = lo_box + glm::dvec3(p[0], p[1], p[2]) * extent;
        glm::dvec3 nh(2.0 * c[0] - 1.0, 2.0 * c[1] - 1.0, 2.0 * c[2] - 1.0);
        nh = glm::length(nh) > 0.0 ? glm::normalize(nh) : glm::dvec3(0, 0, 1);
        const glm::vec3 org(x + eps * nh);
        SampleStream stream(sample_key(t, 0, 0));
        for (std::size_t j = 0; j < per; ++j) {
          const double u1 = stream.next(), u2 = stream.next();
          const glm::vec3 d(cosine_direction(nh, u1, u2));
          const std::size_t i = k * per + j;
          r.ox[i] = org.x, r.oy[i] = org.y, r.oz[i] = org.z, r.dx[i] = d.x, r.dy[i] = d.y, r.dz[i] = d.z;
          r.tnear[i] = 0.0f, r.tfar[i] = float(distance);
        }
      }
      const auto t0 = Clock::now();
      lane(r, 0, n * per, out.data());
      busy[std::size_t(id)] += since(t0);
      for (std::size_t i = 0; i < n * per; ++i) hit += out[i];
    }
    occluded += hit;
  });
  const double t_bare = *std::max_element(busy.begin(), busy.end());
  double open = 0.0;  // the bake's own AO map over its covered texels: its share of unoccluded rays
  std::size_t covered = 0;
  for (std::size_t t = 0; t < ao.coverage.size(); ++t)
    if (ao.coverage[t]) open += double(ao.maps[0].image.pixels[t]), ++covered;
  const double rays = double(texels.size()) * double(per), t_trace = t_ao - t_normal;
  std::printf(
      "bench_occlusion --from-bake %d: %zu covered texels x %zu rays = %.0fM AO rays (tfar %.4g; occluded: %.2f%% in the bare "
      "loop, %.2f%% in the bake's AO map), %d thread(s), load %s\n\n",
      args.from_bake, texels.size(), per, rays * 1e-6, distance, 100.0 * double(occluded) / rays,
      covered ? 100.0 * (1.0 - open / double(covered)) : 0.0, int(busy.size()), bench::load_average().c_str());
  std::printf("| what | seconds | Mrays/s |\n|---|---|---|\n");
  std::printf("| bake trace stage, normal alone | %.2f | |\n", t_normal);
  std::printf("| bake trace stage, normal + ao | %.2f | |\n", t_ao);
  std::printf("| the AO's tracing in the bake (difference) | %.2f | %.2f |\n", t_trace, rays / t_trace * 1e-6);
  std::printf("| bare loop over the same rays (rtcOccluded1 per ray, Embree calls only) | %.2f | %.2f |\n", t_bare,
              rays / t_bare * 1e-6);
  std::printf("\nratio bake AO tracing / bare loop: %.3f\n", t_trace / t_bare);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Args args = parse(argc, argv);
    Mesh high = load_mesh(args.sculpt + "/high.ply");
    for (int s = 0; s < args.subdivide; ++s) high = bench::subdivide(high);
    if (args.from_bake > 0) {
      BareScene bare(high, RTC_SCENE_FLAG_NONE);
      std::printf("bench_occlusion: %s, subdivided %d: %zu triangles\n", args.sculpt.c_str(), args.subdivide,
                  high.triangle_count());
      from_bake(high, args, bare.scene);
      return 0;
    }
    double diagonal = 0;
    const Rays rays = make_rays(high, args, false, diagonal);
    std::printf(
        "bench_occlusion: %s, subdivided %d: %zu triangles; %zu rays (%zu points x %d), tfar %.3g (%.3g of the diagonal), "
        "%d thread(s), load %s\n",
        args.sculpt.c_str(), args.subdivide, high.triangle_count(), rays.size(), rays.size() / std::size_t(args.rays), args.rays,
        args.distance * diagonal, args.distance, args.threads, bench::load_average().c_str());

    BareScene bare(high, RTC_SCENE_FLAG_NONE);
    BareScene robust(high, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST));
    // raycast::Scene's own flags (the context filter for its hit rules).
    BareScene as_scene(high, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION));
    raycast::Scene scene(&high.positions[0].x, high.positions.size(), high.position_index.data(), high.triangle_count());
    std::vector<std::uint32_t> tri_group(high.triangle_count(), 0), ray_group(rays.size(), 0);

    struct Row {
      const char* name;
      Lane lane;
      double best = 1e30;
      std::vector<std::uint8_t> out;
    };
    std::vector<Row> rows;
    auto add = [&](const char* name, Lane lane) { rows.push_back({name, std::move(lane), 1e30, {}}); };
    add("bare: rtcOccluded1 per ray, default scene", single(bare.scene));
    add("Scene::occluded", api(scene, nullptr, nullptr));
    if (args.variants) {
      const auto inc = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT, coh = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      const RTCScene rs = robust.scene;
      add("Scene::occluded, groups (all 0)", api(scene, tri_group.data(), ray_group.data()));
      add("robust: rtcOccluded1 per ray", single(rs));
      add("robust: rtcOccluded8 incoherent", packets<8, RTCRay8, rtcOccluded8>(rs, inc, false, args.rays));
      add("robust: rtcOccluded8 coherent", packets<8, RTCRay8, rtcOccluded8>(rs, coh, false, args.rays));
      add("robust: rtcOccluded8 octant-sorted coherent", packets<8, RTCRay8, rtcOccluded8>(rs, coh, true, args.rays));
      add("robust: rtcOccluded8 octant-sorted incoherent", packets<8, RTCRay8, rtcOccluded8>(rs, inc, true, args.rays));
      add("robust: rtcOccluded16 incoherent", packets<16, RTCRay16, rtcOccluded16>(rs, inc, false, args.rays));
      add("robust: rtcOccluded16 octant-sorted coherent", packets<16, RTCRay16, rtcOccluded16>(rs, coh, true, args.rays));
      add("robust: rtcOccluded1M incoherent", stream_1m(rs, inc));
      add("robust: rtcOccluded1M coherent", stream_1m(rs, coh));
      add("robust: rtcOccludedNp incoherent", stream_np(rs, inc));
      add("robust: rtcOccludedNp coherent", stream_np(rs, coh));
      add("robust + context filter flag: rtcOccludedNp incoherent", stream_np(as_scene.scene, inc));
    }
    const std::size_t chunk = args.chunk;
    for (Row& row : rows) row.out.assign(rays.size(), 2);
    for (int round = 0; round < args.rounds; ++round)
      for (Row& row : rows) row.best = std::min(row.best, run_lane(row.lane, rays, row.out.data(), args.threads, chunk));

    const std::vector<std::uint8_t>& ref = rows[0].out;
    const double occluded = double(std::count(ref.begin(), ref.end(), 1)) / double(ref.size());
    std::printf("occluded: %.1f%% of the rays (bare loop)\n\n", 100.0 * occluded);
    std::printf("| lane | Mrays/s | time / bare | rays differing from bare |\n|---|---|---|---|\n");
    for (const Row& row : rows) {
      std::size_t diff = 0;
      for (std::size_t i = 0; i < ref.size(); ++i) diff += row.out[i] != ref[i];
      std::printf("| %s | %.2f | %.3f | %zu |\n", row.name, double(rays.size()) / row.best * 1e-6, row.best / rows[0].best, diff);
    }
    std::printf("\nratio Scene::occluded / bare loop: %.3f\n", rows[1].best / rows[0].best);
    if (args.variants) thickness(high, args, bare.scene, scene, chunk);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_occlusion: %s\n", e.what());
    return 1;
  }
}
