#include "raycast.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>

namespace nmbake::raycast {

namespace {

// Embree's allocation failures (its own, and std::bad_alloc it caught) become OutOfMemory, which
// the programs report as out of memory (exit 4); anything else is a runtime_error.
void throw_on_error(void* /*user*/, RTCError code, const char* message) {
  if (code == RTC_ERROR_OUT_OF_MEMORY) throw OutOfMemory();
  throw std::runtime_error(std::string("embree: error ") + std::to_string(int(code)) + ": " + (message ? message : ""));
}

RTCBuildQuality to_embree(BuildQuality q) {
  switch (q) {
    case BuildQuality::low: return RTC_BUILD_QUALITY_LOW;
    case BuildQuality::high: return RTC_BUILD_QUALITY_HIGH;
    default: return RTC_BUILD_QUALITY_MEDIUM;
  }
}

// Embree reports errors through the callback; after a failed call the callback has already thrown,
// but device creation happens before any callback exists, so check it by hand.
void check_device(RTCDevice device) {
  if (!device && rtcGetDeviceError(nullptr) == RTC_ERROR_OUT_OF_MEMORY) throw OutOfMemory();
  if (!device)
    throw std::runtime_error("embree: cannot create a device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
}

// One ray for rtcIntersect1, with no hit yet; its id (a packet lane for the filter) is 0.
RTCRayHit ray_hit(const Ray& ray) {
  RTCRayHit rh;
  rh.ray.org_x = ray.origin.x;
  rh.ray.org_y = ray.origin.y;
  rh.ray.org_z = ray.origin.z;
  rh.ray.tnear = ray.tnear;
  rh.ray.dir_x = ray.direction.x;
  rh.ray.dir_y = ray.direction.y;
  rh.ray.dir_z = ray.direction.z;
  rh.ray.time = 0.0f;
  rh.ray.tfar = ray.tfar;
  rh.ray.mask = 0xffffffffu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}

// The widest packet Scene::intersect casts (Scene::packet_width).
constexpr int kMaxPacket = 16;

// The context a call under a HitRule hands Embree: its filter finds the rule and the per-ray
// state of the packet being traced here. A ray's id is its lane in the packet.
struct RuleContext {
  RTCIntersectContext context;  // first: the filter receives a pointer to it
  const HitRule* rule = nullptr;
  std::uint8_t outward[kMaxPacket] = {};
  float prefer_lo[kMaxPacket], prefer_hi[kMaxPacket];  // the preferred part of each ray
  std::uint32_t group[kMaxPacket];                     // each ray's group (HitRule::group)
  float backface_t[kMaxPacket];                        // nearest back face passed over
  // The hit accepted so far: of hits at one distance (a ray through an edge), the lower triangle
  // index is kept, whichever Embree met first, so the hit does not depend on the BVH's shape.
  float accepted_t[kMaxPacket];
  std::uint32_t accepted_prim[kMaxPacket];
  // Hits kept for want of a better one: [0] the front-face hit outside the preferred part nearest
  // to it (key: that distance), [1] the first hit whose normal disagrees (key: t).
  struct Kept {
    float key, t, u, v;
    std::uint32_t prim;
  } kept[2][kMaxPacket];
  // Whether the filter passed a back face or kept a hit since the lanes were last reset: without,
  // backface_t and kept are as reset, and finish has nothing to do (most packets of a bake).
  bool marked = false;

  explicit RuleContext(const HitRule* r) : rule(r) {
    rtcInitIntersectContext(&context);
    context.filter = r ? &filter : nullptr;
    constexpr float inf = std::numeric_limits<float>::infinity();
    for (int k = 0; k < kMaxPacket; ++k) {
      prefer_lo[k] = 0.0f;
      prefer_hi[k] = inf;
      group[k] = 0;
      backface_t[k] = inf;
      for (auto& kk : kept) kk[k] = {inf, 0.0f, 0.0f, 0.0f, no_hit};
    }
  }
  // The per-lane state of the filter, for the next packet (of `lanes` rays); the rays' own fields
  // (outward, prefer_lo/hi, group) are the caller's.
  void reset_lanes(int lanes) {
    constexpr float inf = std::numeric_limits<float>::infinity();
    for (int k = 0; k < lanes; ++k) {
      accepted_t[k] = inf;
      accepted_prim[k] = no_hit;
    }
    if (!marked) return;
    for (int k = 0; k < lanes; ++k) {
      backface_t[k] = inf;
      for (auto& kk : kept) kk[k] = {inf, 0.0f, 0.0f, 0.0f, no_hit};
    }
    marked = false;
  }
  // Keeps the hit when its key is smaller (equal keys: the lower triangle index, whatever order
  // Embree found them in).
  void keep(Kept& k, float key, float t, float u, float v, std::uint32_t prim) {
    marked = true;
    if (key < k.key || (key == k.key && prim < k.prim)) k = {key, t, u, v, prim};
  }

  // Called by Embree for every hit it finds within the ray's current range, in no particular
  // order, possibly more than once for one triangle (spatial splits); the hit's distance is in
  // the ray's tfar. A rejected hit (valid = 0) leaves the range as it was.
  static void filter(const RTCFilterFunctionNArguments* args) {
    RuleContext& rc = *reinterpret_cast<RuleContext*>(args->context);
    const unsigned n = args->N;
    if (n > 32) {
      for (unsigned i = 0; i < n; ++i)
        if (args->valid[i] == -1) filter_lane<0>(args, rc, i);
      return;
    }
    // The valid lanes as bits, without a branch per lane: a packet's call has a few valid lanes
    // in no pattern, and a test per lane mispredicted about as often as it ran.
    std::uint32_t lanes = 0;
    for (unsigned i = 0; i < n; ++i) lanes |= std::uint32_t(args->valid[i] == -1) << i;
    if (n == 16) {  // the bake's packets: the fields' offsets known at compile time
      for (; lanes; lanes &= lanes - 1) filter_lane<16>(args, rc, unsigned(__builtin_ctz(lanes)));
      return;
    }
    for (; lanes; lanes &= lanes - 1) filter_lane<0>(args, rc, unsigned(__builtin_ctz(lanes)));
  }

  // One valid lane of a filter call: the rule, as HitRule says.
  // kN: the call's N when known (16), else 0 (args->N).
  template <unsigned kN>
  [[gnu::always_inline]] static inline void filter_lane(const RTCFilterFunctionNArguments* args, RuleContext& rc, unsigned i) {
    const HitRule& rule = *rc.rule;
    const unsigned n = kN ? kN : args->N;
    {
      const unsigned lane = RTCRayN_id(args->ray, n, i) & unsigned(kMaxPacket - 1);
      const std::uint32_t prim = RTCHitN_primID(args->hit, n, i);
      if (rule.group && rule.group[prim] != rc.group[lane]) {  // not in this ray's scene
        args->valid[i] = 0;
        return;
      }
      // The low-poly's outside: -direction for inward rays, +direction for outward ones.
      const float side = rc.outward[lane] ? 1.0f : -1.0f;
      const glm::vec3 out(side * RTCRayN_dir_x(args->ray, n, i), side * RTCRayN_dir_y(args->ray, n, i),
                          side * RTCRayN_dir_z(args->ray, n, i));
      const glm::vec3 ng(RTCHitN_Ng_x(args->hit, n, i), RTCHitN_Ng_y(args->hit, n, i), RTCHitN_Ng_z(args->hit, n, i));
      const float t = RTCRayN_tfar(args->ray, n, i);
      const int code = rule.facing ? rule.facing[prim] : 127;
      const float front = code < 0 ? -glm::dot(ng, out) : glm::dot(ng, out);
      if (front < 0.0f && rule.skip_backfaces) {
        rc.backface_t[lane] = std::min(rc.backface_t[lane], t);
        rc.marked = true;
        args->valid[i] = 0;
        return;
      }
      const float u = RTCHitN_u(args->hit, n, i), v = RTCHitN_v(args->hit, n, i);
      // The normals are read only when they could point away: the face is no nearer the outside
      // than they lean from it (HitRule).
      const int m = code < 0 ? -code : code;
      const float lean = float(m - 1) * (1.0f / 126.0f);
      if (rule.corner_normals &&
          (m >= 127 || front <= 0.0f || front * front <= lean * lean * glm::dot(ng, ng) * glm::dot(out, out))) {
        const glm::vec3* c = rule.corner_normals + 3 * std::size_t(prim);
        const glm::vec3 nh = (1.0f - u - v) * c[0] + u * c[1] + v * c[2];
        if (!(glm::dot(nh, out) > 0.0f)) {
          rc.keep(rc.kept[1][lane], t, t, u, v, prim);
          args->valid[i] = 0;
          return;
        }
      }
      if (t < rc.prefer_lo[lane] || t > rc.prefer_hi[lane]) {
        rc.keep(rc.kept[0][lane], t < rc.prefer_lo[lane] ? rc.prefer_lo[lane] - t : t - rc.prefer_hi[lane], t, u, v, prim);
        args->valid[i] = 0;
        return;
      }
      if (t == rc.accepted_t[lane] && prim > rc.accepted_prim[lane]) {
        args->valid[i] = 0;
        return;
      }
      rc.accepted_t[lane] = t;
      rc.accepted_prim[lane] = prim;
    }
  }

  // Lane k's result after the call, from Embree's hit (prim, t, u, v; prim no_hit for none):
  // Embree's hit, else the fallback; its flags.
  std::uint8_t finish(int k, std::uint32_t& prim, float& t, float& u, float& v) const {
    std::uint8_t flags = 0;
    if (!marked) return flags;
    for (int j = 0; j < 2 && prim == no_hit; ++j)
      if (kept[j][k].prim != no_hit) {
        prim = kept[j][k].prim;
        t = kept[j][k].t;
        u = kept[j][k].u;
        v = kept[j][k].v;
        flags |= j == 0 ? hit_outside_preferred : hit_normal_disagrees;
      }
    if (backface_t[k] < (prim == no_hit ? std::numeric_limits<float>::infinity() : t) ||
        (prim == no_hit && backface_t[k] != std::numeric_limits<float>::infinity()))
      flags |= hit_passed_backface;
    return flags;
  }
};

// Whether the packet's K directions lie in one octant as Embree sees them. Its coherent traversal
// bounds a packet by one frustum, which assumes that, and it takes the reciprocal of a direction
// component below 1e-18 in magnitude (a zero of either sign too) as +1e18: a packet of a bake
// where normals turn through a plane, directions -0.0017 and -7e-19 along x, lost every hit
// under it (Embree 3.13). So a component counts as positive below 1e-18, by its sign above 1e-16,
// and in between (where the rounding of that threshold could decide) not at all: such a packet,
// and one whose rays straddle an axis plane, is traced as incoherent.
template <int K, typename RayHitK>
bool one_octant(const RayHitK& rh) {
  const float* d[3] = {rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z};
  for (const float* a : d) {
    int side[K];
    for (int k = 0; k < K; ++k) {
      const float m = std::fabs(a[k]);
      side[k] = m < 1e-18f ? 1 : !(m >= 1e-16f) ? 0 : a[k] > 0.0f ? 1 : -1;  // 0: undecided (or NaN)
    }
    for (int k = 0; k < K; ++k)
      if (side[k] == 0 || side[k] != side[0]) return false;
  }
  return true;
}

// The context of Scene::occluded under groups: its filter rejects the triangles of other groups.
// A ray's id is its index in the block being traced.
struct GroupContext {
  RTCIntersectContext context;  // first: the filter receives a pointer to it
  const std::uint32_t* triangle_group;
  const std::uint32_t* ray_group = nullptr;  // the block's rays' groups, or null: all 0

  explicit GroupContext(const std::uint32_t* tg) : triangle_group(tg) {
    rtcInitIntersectContext(&context);
    context.filter = tg ? &filter : nullptr;
  }
  static void filter(const RTCFilterFunctionNArguments* args) {
    const GroupContext& gc = *reinterpret_cast<const GroupContext*>(args->context);
    const unsigned n = args->N;
    for (unsigned i = 0; i < n; ++i) {
      if (args->valid[i] != -1) continue;
      const std::uint32_t group = gc.ray_group ? gc.ray_group[RTCRayN_id(args->ray, n, i)] : 0u;
      if (gc.triangle_group[RTCHitN_primID(args->hit, n, i)] != group) args->valid[i] = 0;
    }
  }
};

}  // namespace

RayArrays::RayArrays(std::size_t count) : count_(count), fields_(11 * count), triangle_(count, no_hit), flags_(count, 0) {}

RayArrays::RayArrays(const Ray* rays, std::size_t count) : RayArrays(count) {
  for (std::size_t i = 0; i < count; ++i) set(i, rays[i]);
}

RayBatch RayArrays::rays(std::size_t first) const {
  const float* f = fields_.data() + first;
  const std::size_t n = count_;
  return {f, f + n, f + 2 * n, f + 3 * n, f + 4 * n, f + 5 * n, f + 6 * n, f + 7 * n};
}

HitBatch RayArrays::hits(std::size_t first) {
  float* f = fields_.data() + first;
  const std::size_t n = count_;
  return {triangle_.data() + first, f + 8 * n, f + 9 * n, f + 10 * n, flags_.data() + first};
}

struct Scene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::size_t triangles = 0;
  // The secondary rays' BVH over the same geometry (kept here to attach it), built once on first
  // need (Scene::prepare_secondary_rays).
  RTCGeometry geometry = nullptr;
  BuildQuality quality = BuildQuality::medium;
  RTCScene secondary = nullptr;
  std::once_flag secondary_once;
  int packet = 8;  // Scene::packet_width

  // Releasing must not throw: an error callback that throws from here (a destructor, maybe while
  // a failed build unwinds) is std::terminate; under ulimit -v a release after a failed
  // rtcCommitScene did exactly that (exit 134).
  ~Impl() {
    if (device) rtcSetDeviceErrorFunction(device, nullptr, nullptr);
    if (secondary) rtcReleaseScene(secondary);
    if (scene) rtcReleaseScene(scene);
    if (geometry) rtcReleaseGeometry(geometry);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

void build(Scene::Impl& impl, const float* positions, std::size_t vertex_count, const std::uint32_t* indices,
           std::size_t triangle_count, BuildQuality quality, int threads, bool share) {
  // Huge pages for Embree's blocks (the BVH's nodes and build arrays): where the kernel gives them
  // only when asked (transparent_hugepage "madvise"), 4 KiB page faults were much of the build's time
  // and did not shrink with threads (baker/cli/large_pages.cpp does the same for nmbake's arrays).
  std::string config = "hugepages=1";
  if (threads > 0) config += ",threads=" + std::to_string(threads);
  impl.device = rtcNewDevice(config.c_str());
  check_device(impl.device);
  rtcSetDeviceErrorFunction(impl.device, throw_on_error, nullptr);
  impl.triangles = triangle_count;

  // Packets of 16 where Embree traces them natively (AVX-512): a texel's 16 samples in one packet,
  // which on the bake's 16-sample rays takes about 0.85 of the time of two packets of 8 (Zen 5).
  // Elsewhere Embree would split them, so 8.
  impl.packet = rtcGetDeviceProperty(impl.device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) ? 16 : 8;

  impl.scene = rtcNewScene(impl.device);
  // Robust: coincident and touching triangles must not lose hits to fast approximations. Context
  // filters: the calls under a HitRule pass theirs (the others pass none and pay nothing for it).
  // A low-quality build is what few rays against many triangles take (the bake's
  // bvh_quality_for): there memory and build time count more than trace speed, so the BVH is
  // compact too (its leaves keep triangle indices, not precomputed edges): less memory and a
  // faster build for a slower trace, and the same hits.
  const int compact = quality == BuildQuality::low ? RTC_SCENE_FLAG_COMPACT : 0;
  rtcSetSceneFlags(impl.scene, RTCSceneFlags(RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION | compact));
  rtcSetSceneBuildQuality(impl.scene, to_embree(quality));

  RTCGeometry geom = rtcNewGeometry(impl.device, RTC_GEOMETRY_TYPE_TRIANGLE);
  rtcSetGeometryBuildQuality(geom, to_embree(quality));
  if (share) {
    // In place: 18 bytes per triangle of a typical mesh not copied (and not faulted in).
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, positions, 0, 3 * sizeof(float), vertex_count);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices, 0, 3 * sizeof(std::uint32_t),
                               triangle_count);
  } else {
    // Embree reads vertices with 16-byte loads: its own buffers carry the padding it needs.
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertex_count));
    std::memcpy(vb, positions, vertex_count * 3 * sizeof(float));
    auto* ib = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), triangle_count));
    std::memcpy(ib, indices, triangle_count * 3 * sizeof(std::uint32_t));
  }
  rtcCommitGeometry(geom);
  rtcAttachGeometry(impl.scene, geom);
  impl.geometry = geom;  // the reference rtcNewGeometry gave, released with the Impl
  impl.quality = quality;
  rtcCommitScene(impl.scene);
}

// The secondary rays' scene: the same geometry without RTC_SCENE_FLAG_ROBUST, so Embree takes its
// fast node and triangle tests (bench_occlusion: 1.35 to 1.45 times the rays per second on AO's
// rays). Its test is not watertight: a ray aimed exactly at an edge or vertex two triangles share
// may pass between them. For the primary rays, one texel each, that would be a texel lost; for
// AO's and thickness's, dozens of random rays a texel, it is a ray of zero measure (the bake's AO
// maps through either scene came out identical: raycast.h).
void build_secondary(Scene::Impl& impl) {
  RTCScene fast = rtcNewScene(impl.device);
  try {
    rtcSetSceneFlags(fast, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
    rtcSetSceneBuildQuality(fast, to_embree(impl.quality));
    rtcAttachGeometry(fast, impl.geometry);
    rtcCommitScene(fast);
  } catch (...) {
    rtcReleaseScene(fast);
    throw;
  }
  impl.secondary = fast;
}

}  // namespace

Scene::Scene(const float* positions, std::size_t vertex_count, const std::uint32_t* indices, std::size_t triangle_count,
             BuildQuality quality, int threads, bool share_buffers)
    : impl_(std::make_unique<Impl>()) {
  try {
    build(*impl_, positions, vertex_count, indices, triangle_count, quality, threads, share_buffers);
  } catch (const std::bad_alloc&) {
    // Out of memory in a build: the device and scene are left unreleased (the process is about to
    // report it and exit). Releasing them after a failed parallel build ended in std::terminate
    // inside Embree under ulimit -v (exit 134).
    impl_->scene = nullptr;
    impl_->geometry = nullptr;
    impl_->device = nullptr;
    throw;
  }
}

Scene::~Scene() = default;

std::size_t Scene::triangle_count() const { return impl_->triangles; }

int Scene::packet_width() const { return impl_->packet; }

void Scene::set_packet_width(int width) {
  if (width != 8 && width != 16) throw std::invalid_argument("raycast: packet width must be 8 or 16");
  impl_->packet = width;
}

void Scene::prepare_secondary_rays() const {
  Impl& impl = *impl_;
  std::call_once(impl.secondary_once, [&impl] { build_secondary(impl); });
}

Hit Scene::intersect(const Ray& ray) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit rh = ray_hit(ray);
  rtcIntersect1(impl_->scene, &context, &rh);
  Hit h;
  if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
    h.triangle = rh.hit.primID;
    h.t = rh.ray.tfar;
    h.u = rh.hit.u;
    h.v = rh.hit.v;
  }
  return h;
}

Hit Scene::intersect(const Ray& ray, const HitRule& rule, bool outward, std::uint8_t* flags, float prefer_lo, float prefer_hi,
                     std::uint32_t group) const {
  RuleContext rc(&rule);
  rc.reset_lanes(1);  // accepted_t, accepted_prim
  rc.group[0] = group;
  rc.outward[0] = outward;
  rc.prefer_lo[0] = prefer_lo;
  rc.prefer_hi[0] = prefer_hi;
  RTCRayHit rh = ray_hit(ray);
  rtcIntersect1(impl_->scene, &rc.context, &rh);
  Hit h;
  std::uint32_t prim = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? rh.hit.primID : no_hit;
  float t = rh.ray.tfar, u = rh.hit.u, v = rh.hit.v;
  const std::uint8_t f = rc.finish(0, prim, t, u, v);
  if (flags) *flags = f;
  if (prim != no_hit) h = {prim, t, u, v};
  return h;
}

void Scene::intersect(const Ray* rays, Hit* hits, std::size_t count, bool coherent) const {
  // The one packet path (below), through arrays in its layout.
  RayArrays arrays(rays, count);
  RayBatch batch = arrays.rays();
  batch.coherent = coherent;
  intersect(batch, arrays.hits(), count, nullptr);
  for (std::size_t i = 0; i < count; ++i) {
    const Hit h = arrays.hit(i);
    hits[i] = h.hit() ? h : Hit{};
  }
}

namespace {

// Scene::intersect(RayBatch, ...) in packets of K rays (RayHitK: Embree's RTCRayHitK).
template <int K, typename RayHitK>
void intersect_packets(RTCScene scene, const RayBatch& rays, const HitBatch& hits, std::size_t count, const HitRule* rule) {
  RuleContext rc(rule);
  alignas(64) RayHitK rh;
  alignas(64) int valid[K];
  // Fields no ray sets, once.
  for (int k = 0; k < K; ++k) {
    rh.ray.time[k] = 0.0f;
    rh.ray.mask[k] = 0xffffffffu;
    rh.ray.id[k] = unsigned(k);
    rh.ray.flags[k] = 0;
  }
  std::uint32_t ray[K];  // the packet's rays (a short last packet repeats its last ray)
  for (std::size_t base = 0; base < count; base += K) {
    const std::size_t n = std::min<std::size_t>(K, count - base);
    const bool in_place = n == K && !rays.order;  // rays base .. base + K - 1
    for (std::size_t k = 0; k < K; ++k) {
      const std::size_t j = base + std::min(k, n - 1);
      ray[k] = std::uint32_t(rays.order ? rays.order[j] : j);
    }
    auto fill = [&](float* to, const float* from) {
      if (in_place) {
        std::memcpy(to, from + base, K * sizeof(float));
      } else {
        for (std::size_t k = 0; k < K; ++k) to[k] = from[ray[k]];
      }
    };
    fill(rh.ray.org_x, rays.org_x);
    fill(rh.ray.org_y, rays.org_y);
    fill(rh.ray.org_z, rays.org_z);
    fill(rh.ray.dir_x, rays.dir_x);
    fill(rh.ray.dir_y, rays.dir_y);
    fill(rh.ray.dir_z, rays.dir_z);
    fill(rh.ray.tnear, rays.tnear);
    fill(rh.ray.tfar, rays.tfar);
    for (std::size_t k = 0; k < K; ++k) {
      valid[k] = k < n ? -1 : 0;
      rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
      rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    if (rule) {
      rc.reset_lanes(K);
      // The rays' own fields; those the batch leaves out keep the constructor's.
      if (rays.outward)
        for (std::size_t k = 0; k < K; ++k) rc.outward[k] = rays.outward[ray[k]];
      if (rays.prefer_lo) fill(rc.prefer_lo, rays.prefer_lo);
      if (rays.prefer_hi) fill(rc.prefer_hi, rays.prefer_hi);
      if (rays.group)
        for (std::size_t k = 0; k < K; ++k) rc.group[k] = rays.group[ray[k]];
    }
    rc.context.flags =
        rays.coherent && one_octant<K>(rh) ? RTC_INTERSECT_CONTEXT_FLAG_COHERENT : RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    if constexpr (K == 16) rtcIntersect16(valid, scene, &rc.context, &rh);
    else rtcIntersect8(valid, scene, &rc.context, &rh);
    for (std::size_t k = 0; k < K; ++k)
      rh.hit.primID[k] = rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? rh.hit.primID[k] : no_hit;
    if (rule && rc.marked) {
      for (std::size_t k = 0; k < n; ++k) {
        const std::uint8_t f = rc.finish(int(k), rh.hit.primID[k], rh.ray.tfar[k], rh.hit.u[k], rh.hit.v[k]);
        if (hits.flags) hits.flags[ray[k]] = f;
      }
    } else if (rule && hits.flags) {
      if (in_place) std::memset(hits.flags + base, 0, K);
      else
        for (std::size_t k = 0; k < n; ++k) hits.flags[ray[k]] = 0;
    }
    if (in_place) {
      std::memcpy(hits.triangle + base, rh.hit.primID, K * sizeof(std::uint32_t));
      std::memcpy(hits.t + base, rh.ray.tfar, K * sizeof(float));
      std::memcpy(hits.u + base, rh.hit.u, K * sizeof(float));
      std::memcpy(hits.v + base, rh.hit.v, K * sizeof(float));
    } else {
      for (std::size_t k = 0; k < n; ++k) {
        const std::size_t i = ray[k];
        hits.triangle[i] = rh.hit.primID[k];
        hits.t[i] = rh.ray.tfar[k];
        hits.u[i] = rh.hit.u[k];
        hits.v[i] = rh.hit.v[k];
      }
    }
  }
}

}  // namespace

void Scene::intersect(const RayBatch& rays, const HitBatch& hits, std::size_t count, const HitRule* rule) const {
  if (impl_->packet == 16) intersect_packets<16, RTCRayHit16>(impl_->scene, rays, hits, count, rule);
  else intersect_packets<8, RTCRayHit8>(impl_->scene, rays, hits, count, rule);
}

namespace {

// Ray i of `rays` as entry k of a stream block (its id k: its index for the group filter).
void set_stream_ray(RTCRay& r, const RayBatch& rays, std::size_t i, std::size_t k) {
  r.org_x = rays.org_x[i], r.org_y = rays.org_y[i], r.org_z = rays.org_z[i], r.tnear = rays.tnear[i];
  r.dir_x = rays.dir_x[i], r.dir_y = rays.dir_y[i], r.dir_z = rays.dir_z[i], r.time = 0.0f;
  r.tfar = rays.tfar[i], r.mask = 0xffffffffu, r.id = unsigned(k), r.flags = 0;
}

// The secondary rays (after building their BVH, the first time) in blocks of `block`: trace(base,
// n, context) for rays base .. base + n - 1, the context's group filter on their groups.
template <typename Trace>
void in_blocks(const Scene& scene, const RayBatch& rays, std::size_t count, std::size_t block, const SecondaryRayOptions& options,
               Trace&& trace) {
  if (count == 0) return;
  scene.prepare_secondary_rays();
  GroupContext gc(options.group);
  gc.context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  for (std::size_t base = 0; base < count; base += block) {
    gc.ray_group = rays.group ? rays.group + base : nullptr;
    trace(base, std::min(block, count - base), gc.context);
  }
}

}  // namespace

void Scene::occluded(const RayBatch& rays, std::uint8_t* occluded, std::size_t count, const SecondaryRayOptions& options) const {
  // On the secondary rays' scene, as incoherent streams of RTCRay structs (rtcOccluded1M) in
  // blocks: Embree sorts a block's rays by the octant of their direction and traces each octant's
  // rays together, which on AO's rays beat every other entry point (bench_occlusion --variants,
  // suz_L4 x4, one core: on the fast scene 1.06 times rtcOccludedNp's rays per second and 2 times
  // rtcOccluded1's; packets of 8 or 16, coherent or not, octant-sorted or not, were slower still).
  constexpr std::size_t kBlock = 1024;
  alignas(64) RTCRay block[kBlock];
  constexpr float minus_inf = -std::numeric_limits<float>::infinity();
  in_blocks(*this, rays, count, kBlock, options, [&](std::size_t base, std::size_t n, RTCIntersectContext& context) {
    for (std::size_t k = 0; k < n; ++k) set_stream_ray(block[k], rays, base + k, k);
    rtcOccluded1M(impl_->secondary, &context, block, unsigned(n), sizeof(RTCRay));
    // Embree sets tfar to -inf when occluded; a ray it skips (tnear > tfar) keeps its own.
    for (std::size_t k = 0; k < n; ++k) occluded[base + k] = block[k].tfar == minus_inf && rays.tfar[base + k] != minus_inf;
  });
}

void Scene::first_hits(const RayBatch& rays, const HitBatch& hits, std::size_t count, const SecondaryRayOptions& options) const {
  // As occluded: the secondary rays' scene, incoherent streams of RTCRayHit structs in blocks.
  constexpr std::size_t kBlock = 512;
  alignas(64) RTCRayHit block[kBlock];
  in_blocks(*this, rays, count, kBlock, options, [&](std::size_t base, std::size_t n, RTCIntersectContext& context) {
    for (std::size_t k = 0; k < n; ++k) {
      set_stream_ray(block[k].ray, rays, base + k, k);
      block[k].hit.geomID = RTC_INVALID_GEOMETRY_ID;
      block[k].hit.primID = RTC_INVALID_GEOMETRY_ID;
      block[k].hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect1M(impl_->secondary, &context, block, unsigned(n), sizeof(RTCRayHit));
    for (std::size_t k = 0; k < n; ++k) {
      const RTCRayHit& rh = block[k];
      const std::size_t i = base + k;
      const bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      hits.triangle[i] = hit ? rh.hit.primID : no_hit;
      hits.t[i] = rh.ray.tfar;
      hits.u[i] = rh.hit.u;
      hits.v[i] = rh.hit.v;
      if (hits.flags) hits.flags[i] = 0;
    }
  });
}

}  // namespace nmbake::raycast
