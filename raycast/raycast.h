// Ray casting against a triangle mesh: the only code that talks to Embree.
//
// Scene owns an Embree device and scene (RAII, non-copyable); Embree errors become
// std::runtime_error, except running out of memory, which is OutOfMemory (a std::bad_alloc). Positions are copied into Embree's
// own buffers, so the caller's arrays may go away after construction. Hit barycentrics follow Embree: the hit point is (1 - u -
// v) * p0 + u * p1 + v * p2 for triangle (p0, p1, p2).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <vector>

#include <glm/glm.hpp>

namespace nmbake::raycast {

struct Ray {
  glm::vec3 origin{0.0f};
  float tnear = 0.0f;
  glm::vec3 direction{0.0f, 0.0f, 1.0f};  // need not be unit; t is in units of |direction|
  float tfar = std::numeric_limits<float>::infinity();
};

constexpr std::uint32_t no_hit = 0xffffffffu;

struct Hit {
  std::uint32_t triangle = no_hit;  // index of the triangle hit, or no_hit
  float t = 0.0f;                   // ray parameter of the hit
  float u = 0.0f, v = 0.0f;         // barycentrics of corners 1 and 2
  bool hit() const { return triangle != no_hit; }
};

// Many rays as a structure of arrays (each array `count` long), the layout Embree's packets use,
// so a batch goes to Embree a packet (8 or 16 rays: Scene::packet_width) at a time without
// rearranging each ray's fields.
struct RayBatch {
  const float *org_x, *org_y, *org_z;
  const float *dir_x, *dir_y, *dir_z;  // need not be unit; t is in units of |direction|
  const float *tnear, *tfar;
  // For a HitRule: per ray, 1 when the ray leaves the low-poly outwards (the low-poly's outside
  // lies along +direction), 0 when it travels inwards (outside along -direction, the usual ray
  // from a cage). Null: every ray travels inwards.
  const std::uint8_t* outward = nullptr;
  // For a HitRule: per ray, the part of it where hits are looked for first, prefer_lo <= t <=
  // prefer_hi (null: 0, and infinity): a hit outside it is taken only when none lies inside, and
  // then the one nearest to it (the part of a ray beyond a cage that a neighbouring part limits).
  const float* prefer_lo = nullptr;
  const float* prefer_hi = nullptr;
  // For a HitRule with groups: per ray, its group (HitRule::group).
  const std::uint32_t* group = nullptr;
  // Consecutive rays are near each other and go the same way (neighbouring texels of a bake):
  // Embree then traces each packet together (RTC_INTERSECT_CONTEXT_FLAG_COHERENT), which
  // on the bake's rays takes about 0.6 of the time; the hits are the same.
  bool coherent = false;
  // When not null, the order to cast the rays in (a permutation of 0 .. count - 1, Scene::intersect's
  // count): packets are made of rays order[0..W-1], order[W..2W-1], ... (W: Scene::packet_width);
  // each ray's hit still goes to its own index. (For making packets of near rays without moving
  // the rays.)
  const std::uint32_t* order = nullptr;
};
// Their hits, the same way: triangle[i] is no_hit for a miss (t, u, v then unspecified).
struct HitBatch {
  std::uint32_t* triangle;
  float *t, *u, *v;
  // With a HitRule, when not null: per ray, the HitFlags of its hit.
  std::uint8_t* flags = nullptr;
};

// Which hits a ray takes (Scene::intersect with a rule). Without a rule the first hit along the
// ray counts, whatever it is.
//
// A triangle's front is the side its vertex normals point to (the sign of facing[t]: + the side of
// cross(p1 - p0, p2 - p0), - the other), so a triangle wound against its neighbours is judged by
// its normals. A hit is on a back face when that front faces away from the low-poly's outside
// (RayBatch::outward): on a closed high-poly that is the inside of some part, never the surface
// the ray looks for. With skip_backfaces such hits are passed over and the ray takes the next one.
// With corner_normals, a front-face hit whose interpolated normal points away from the low-poly's
// outside (dot <= 0: it would bake as a texel facing into the surface, as grazing hits on the
// side of another part do) is taken only when the ray finds no other: then the first of those.
// The magnitude m of facing[t] (1 to 127) bounds how far the triangle's corner normals lean from
// its face: the sine of the largest angle between one and the face's normal is at most
// (m - 1) / 126 (127: unknown, or past 90 degrees). An interpolated normal leans no farther, so
// for a face nearer the outside than that the normals are not read.
// In order: a front-face hit inside the ray's preferred part (RayBatch::prefer_lo/hi), the first
// along the ray; else one outside it, the nearest to it; else one whose normal points away. Of
// hits at one distance (a ray through an edge) the lower triangle index is taken.
// With group (per triangle) a ray sees only the triangles of its own group (RayBatch::group; a
// single ray's is 0 unless given): the others are not there for it, as if in another scene.
struct HitRule {
  const std::int8_t* facing = nullptr;  // per triangle, as above; null: +127 for all
  bool skip_backfaces = true;
  const glm::vec3* corner_normals = nullptr;  // 3 per triangle (any length), or null: no normal test
  const std::uint32_t* group = nullptr;       // per triangle, or null: one group
};

// facing[t] for a triangle whose normals point to the side `sign` (+1 or -1) of its winding and
// lean from its face by at most an angle of sine `lean` (>= 1 or not finite: unknown).
inline std::int8_t facing_code(int sign, double lean) {
  const double m = lean >= 0.0 && lean < 1.0 ? 1.0 + std::ceil(126.0 * lean) : 127.0;
  const int code = int(std::min(m, 127.0));
  return std::int8_t(sign < 0 ? -code : code);
}

// HitBatch::flags bits.
enum HitFlags : std::uint8_t {
  hit_passed_backface = 1,    // the first surface along the ray was a back face, passed over
  hit_normal_disagrees = 2,   // the hit taken is one whose normal points away (no other was found)
  hit_outside_preferred = 4,  // the hit taken lies outside the ray's preferred part (none inside)
};

// Rays held as arrays, with room for their hits: the arrays for Scene::intersect(RayBatch,
// HitBatch). Filled ray by ray, or copied from Ray structs.
class RayArrays {
 public:
  explicit RayArrays(std::size_t count);  // `count` rays, all fields 0, no hits
  RayArrays(const Ray* rays, std::size_t count);
  std::size_t size() const { return count_; }
  // Inline: the bake sets each of its rays through it.
  void set(std::size_t i, const Ray& r) {
    const float v[8] = {r.origin.x, r.origin.y, r.origin.z, r.direction.x, r.direction.y, r.direction.z, r.tnear, r.tfar};
    for (std::size_t k = 0; k < 8; ++k) fields_[k * count_ + i] = v[k];
  }
  Ray ray(std::size_t i) const {
    const auto f = [&](std::size_t k) { return fields_[k * count_ + i]; };
    return {{f(0), f(1), f(2)}, f(6), {f(3), f(4), f(5)}, f(7)};
  }
  Hit hit(std::size_t i) const {  // after Scene::intersect
    return {triangle_[i], fields_[8 * count_ + i], fields_[9 * count_ + i], fields_[10 * count_ + i]};
  }
  // The ray fields as writable arrays, for filling many rays in place: origin and direction
  // components c = 0, 1, 2, tnear and tfar.
  float* origin(int c) { return fields_.data() + std::size_t(c) * count_; }
  float* direction(int c) { return fields_.data() + std::size_t(3 + c) * count_; }
  float* tnear() { return fields_.data() + 6 * count_; }
  float* tfar() { return fields_.data() + 7 * count_; }
  // The rays and hits from ray `first` on.
  RayBatch rays(std::size_t first = 0) const;
  HitBatch hits(std::size_t first = 0);
  std::uint8_t flags(std::size_t i) const { return flags_[i]; }  // HitFlags of ray i after a call under a rule

 private:
  std::size_t count_;
  std::vector<float> fields_;  // 8 ray fields, then the hits' t, u, v: count_ each
  std::vector<std::uint32_t> triangle_;
  std::vector<std::uint8_t> flags_;
};

// Embree could not allocate (RTC_ERROR_OUT_OF_MEMORY, from any call, the BVH build included).
struct OutOfMemory : std::bad_alloc {
  const char* what() const noexcept override { return "embree: out of memory"; }
};

enum class BuildQuality { low, medium, high };

// Options of Scene::occluded.
struct SecondaryRayOptions {
  // Per triangle, its group (as HitRule::group), or null: one group. With groups, ray i sees only
  // the triangles of group RayBatch::group[i] (every ray group 0 when RayBatch::group is null).
  const std::uint32_t* group = nullptr;
};

class Scene {
 public:
  // positions: vertex_count xyz triples; indices: triangle_count index triples. Copied, unless
  // share_buffers: Embree then reads both in place, so they must outlive the Scene and stay
  // unchanged, and 4 bytes past the last vertex must be readable (Embree loads 16 bytes at a time).
  Scene(const float* positions, std::size_t vertex_count, const std::uint32_t* indices, std::size_t triangle_count,
        BuildQuality quality = BuildQuality::medium, int threads = 0 /* 0 = all cores */, bool share_buffers = false);
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  // First hit in (tnear, tfar), or no hit. Thread-safe.
  Hit intersect(const Ray& ray) const;
  // `count` independent rays, traced in packets of packet_width() (rays need not be coherent;
  // RayBatch::coherent when they are). Thread-safe.
  void intersect(const Ray* rays, Hit* hits, std::size_t count, bool coherent = false) const;
  // The same for rays and hits held as arrays, optionally under a HitRule (whose arrays are
  // indexed by the triangles given at construction). Thread-safe.
  void intersect(const RayBatch& rays, const HitBatch& hits, std::size_t count, const HitRule* rule = nullptr) const;
  // Single rays under a rule (`outward` as in RayBatch); `flags` receives the HitFlags when not null.
  Hit intersect(const Ray& ray, const HitRule& rule, bool outward = false, std::uint8_t* flags = nullptr, float prefer_lo = 0.0f,
                float prefer_hi = std::numeric_limits<float>::infinity(), std::uint32_t group = 0) const;

  // The secondary rays of a bake's texel maps: many rays from each of many nearby points, in all
  // directions (ambient occlusion, bent normals, thickness).
  //
  // They are traced in a BVH of their own over the same triangles, built without Embree's robust
  // mode, whose fast node and triangle tests trace AO's rays 1.35 to 1.45 times as fast
  // (bench_occlusion). Its triangle test is not watertight: a ray aimed exactly at an edge or a
  // vertex two triangles share may pass between them (on a grid, rays through its vertices and
  // edge midpoints: about one in sixteen), where the primary rays' robust BVH never lets one
  // through. For a Monte Carlo estimate from dozens of random rays a texel such rays have measure
  // zero: the bake's AO map of the 1M-triangle sculpt at 1024^2, 64 rays (67M rays), came out the
  // same in every texel through either BVH.
  //
  // prepare_secondary_rays builds that BVH (the first call; later ones return at once; thread-safe,
  // a failure throws and the next call tries again); occluded calls it itself, so a caller calls it
  // only to build it at a time of its choosing (the bake: in its BVH stage).
  void prepare_secondary_rays() const;

  // Occlusion (ambient occlusion, bent normals), traced as incoherent streams, the fastest way
  // given thousands of rays a call (a tile's worth; bench_occlusion): occluded[i] = 1 when some
  // triangle of ray i's group, of either facing, crosses the ray at a t with tnear < t < tfar,
  // else 0 (t in units of |direction|). Ties: a ray that meets a triangle only on its boundary (an
  // edge or corner, shared or not, or the rim of a mesh with holes), or at t within rounding of
  // tnear or tfar, may go either way. A ray with tnear > tfar is not occluded. Of RayBatch only the eight
  // ray arrays and `group` are read (`coherent`, `order`, `outward` and the preferred part are
  // not). `occluded`: `count` bytes. Thread-safe.
  void occluded(const RayBatch& rays, std::uint8_t* occluded, std::size_t count, const SecondaryRayOptions& options = {}) const;
  // Thickness: per ray the first triangle of its group, of either facing, that crosses it at a t
  // with tnear < t < tfar (the same ties), as intersect(RayBatch, ...) without a rule gives it, in
  // the secondary rays' BVH; a miss (triangle no_hit) stands for tfar (thickness's min(distance, D)
  // with tfar = D); flags, when not null, 0. Of RayBatch the same fields as occluded are read.
  // Thread-safe.
  void first_hits(const RayBatch& rays, const HitBatch& hits, std::size_t count, const SecondaryRayOptions& options = {}) const;

  std::size_t triangle_count() const;

  // How many rays intersect(RayBatch, ...) hands Embree at once: 16 where Embree traces packets
  // of 16 natively (an AVX-512 CPU), else 8. Under a HitRule the hits do not depend on it, except
  // for a ray through a vertex or edge exactly: Embree's 8- and 16-wide triangle tests may report
  // different ones of the triangles meeting there (the same point, the same t), and along a mesh's
  // rim one may miss. Without a rule, of two triangles at one distance the packet's traversal
  // decides. set_packet_width (8 or 16; not while another thread traces) is for tests and
  // benchmarks: 16 on a CPU without native packets of 16 is correct but slow (Embree splits them).
  int packet_width() const;
  void set_packet_width(int width);

  struct Impl;  // Embree's device and scene (raycast.cpp)

 private:
  std::unique_ptr<Impl> impl_;
};

// Brute-force reference: tests every triangle with a Moller-Trumbore test in double precision. For tests
// only (O(n) per ray).
class ReferenceIntersector {
 public:
  ReferenceIntersector(const float* positions, std::size_t vertex_count, const std::uint32_t* indices,
                       std::size_t triangle_count);
  Hit intersect(const Ray& ray) const;

 private:
  const float* positions_;
  std::size_t vertex_count_;
  const std::uint32_t* indices_;
  std::size_t triangle_count_;
};

}  // namespace nmbake::raycast
