#include "pipeline/texel_maps.h"

#include <algorithm>
#include <cmath>

#include "core/hemisphere.h"
#include "core/tangent_frames.h"
#include "raycast.h"

namespace nmbake {

namespace {

constexpr std::size_t kRayBatch = 4096;  // secondary rays cast together
constexpr std::size_t kAhead = 8;        // samples ahead whose hit data is fetched early

// Secondary rays (AO's, thickness's): a texel's rays of one kind are numbered in the order its
// samples cast them; ray j is point j / R of chain j % R (R chains, below), each chain its own
// Owen-scrambled Sobol sequence (core/hemisphere.h scrambled_sobol2, seeded by texel, chain and
// kind). Within a chain the directions are stratified (a visibility integral's error falls much
// faster than with independent rays); the chains are independent, so the spread of their means
// gives the texel's standard error honestly (the binomial formula would over-state a stratified
// estimate's). Splitting a texel's rays in more chains costs stratification (the error of R chains
// of n / R points grows as R^0.25): a fixed count takes 4 chains (the spread's 3 degrees of freedom
// make each texel's standard error rough, but right on average); --ao-rays auto takes 8, since it
// stops on each texel's own estimate, and with 4 too many texels stop on an estimate that came out
// low by chance (measured on the accuracy bench: the noise 1.3 to 1.45 times the reported standard
// error with 4 chains, 1.1 to 1.2 with 8).
constexpr int kFixedChains = 4, kAutoChains = 8, kMaxChains = 8;
static_assert(kFixedChains == 4 && kAutoChains == 8, "queue_rays deals a texel's rays to its chains by mask and shift");
// --ao-rays auto: the first round's rays per texel (4 per chain), and the rate at which a texel's
// stratified error falls with its rays n (about n^-0.7 on the accuracy bench's sculpts, 64 to 1024
// rays): a later round adds the rays that would bring the texel's error to E at that rate, at
// least half as many as it has.
constexpr int kAutoFirstRays = 32;
constexpr double kAutoErrorExponent = 0.7;

// What a covered texel whose samples all miss gets: open, thick, flat, on the low-poly surface
// (height 0, position the low-poly point), no colour, no ID.
constexpr double kMissAo = 1.0, kMissThickness = 1.0;

// Slots of a texel's sums, each `width` doubles per texel.
enum Slot {
  s_object_normal,  // 3: sum of unit normals, every sample (a miss: the low-poly's)
  s_bent,           // 3: sum of unit bent normals in the output space, every sample
  s_height,         // 1: sum of hit distances
  s_position,       // 3: sum of hit points (a miss: the low-poly point, kept apart below)
  s_curvature,      // 1
  s_color,          // 3
  s_ao,             // 2 + 2 kMaxChains: unoccluded rays, rays; per chain its unoccluded rays, rays
  s_thickness,      // 2 + 2 kMaxChains: sum of min(t, D) / D, rays; per chain its sum, rays
  s_object_id,      // 1: the index taken
  s_material_id,    // 1
  s_hits,           // 1: samples that hit
  s_samples,        // 1: samples
  s_miss_position,  // 3: sum of low-poly points of the samples that miss
  kSlots
};
constexpr int kSlotWidth[kSlots] = {3, 3, 1, 3, 1, 3, 2 + 2 * kMaxChains, 2 + 2 * kMaxChains, 1, 1, 1, 1, 3};

Slot slot_of(MapKind k) {
  switch (k) {
    case MapKind::object_normal: return s_object_normal;
    case MapKind::bent_normal: return s_bent;
    case MapKind::height: return s_height;
    case MapKind::position: return s_position;
    case MapKind::curvature: return s_curvature;
    case MapKind::vertex_color: return s_color;
    case MapKind::ao: return s_ao;
    case MapKind::thickness: return s_thickness;
    case MapKind::object_id: return s_object_id;
    case MapKind::material_id: return s_material_id;
    default: return kSlots;
  }
}

// Secondary rays queued for one cast: per ray its sample and chain, and with match groups its group.
struct RayQueue {
  raycast::RayArrays rays{kRayBatch};
  std::vector<std::uint32_t> sample = std::vector<std::uint32_t>(kRayBatch), group;
  std::vector<std::uint8_t> chain = std::vector<std::uint8_t>(kRayBatch);
  std::vector<std::uint8_t> occluded = std::vector<std::uint8_t>(kRayBatch);
  std::size_t n = 0;
};

// The most frequent of ids[0..n) (ties: the smallest); -1 when n is 0.
double most_frequent(std::vector<std::int64_t>& ids) {
  if (ids.empty()) return -1.0;
  std::sort(ids.begin(), ids.end());
  std::int64_t best = ids[0];
  std::size_t best_run = 0;
  for (std::size_t i = 0; i < ids.size();) {
    std::size_t j = i;
    while (j < ids.size() && ids[j] == ids[i]) ++j;
    if (j - i > best_run) best = ids[i], best_run = j - i;
    i = j;
  }
  return double(best);
}

// The standard error of a texel's value (its rays' total over their count) from its chains, given
// as kMaxChains pairs (chains without rays: not counted) (sum of the values, rays): the spread of the chains' means over sqrt of
// their number. 0 with fewer than two chains that have rays (one ray has no spread to measure). `resolution`: no less than that
// of chains whose means cannot be finer than one ray in m (the variance of rounding to a whole ray, 1/6 on average over where the
// truth falls between two counts, over m^2): stratified chains often agree exactly, which does not make them exact.
double chain_standard_error(const double* pairs, bool resolution = false) {
  double sum = 0.0, rays = 0.0, chains = 0.0;
  for (int c = 0; c < kMaxChains; ++c)
    if (pairs[2 * c + 1] > 0.0) sum += pairs[2 * c], rays += pairs[2 * c + 1], chains += 1.0;
  if (chains < 2.0) return 0.0;
  const double mean = sum / rays, m = rays / chains;
  double sq = 0.0;
  for (int c = 0; c < kMaxChains; ++c)
    if (pairs[2 * c + 1] > 0.0) {
      const double d = pairs[2 * c] / pairs[2 * c + 1] - mean;
      sq += d * d;
    }
  const double var = sq / (chains - 1.0);
  return std::sqrt((resolution ? std::max(var, 1.0 / (6.0 * m * m)) : var) / chains);
}

}  // namespace

MapTargets allocate_map_targets(const MapOptions& maps, int width, int height) {
  MapTargets out;
  for (MapKind k : maps.maps)
    out.raw.push_back(k == MapKind::normal ? Image() : Image(width, height, map_image_channels(k), 0.0f));
  if (maps.wants(MapKind::ao)) out.ao_error = Image(width, height, 1, 0.0f);
  if (maps.wants(MapKind::thickness)) out.thickness_error = Image(width, height, 1, 0.0f);
  if (maps.ao_rays_auto && (maps.wants(MapKind::ao) || maps.wants(MapKind::bent_normal)))
    out.ao_rays = Image(width, height, 1, 0.0f);
  if (maps.ao_rays_auto && maps.wants(MapKind::thickness)) out.thickness_rays = Image(width, height, 1, 0.0f);
  return out;
}

struct TexelMaps::Impl {
  const MapInputs& in;
  std::size_t texels;
  int offset[kSlots];  // first double of each slot in a texel's sums, -1: not kept
  int stride = 0;      // doubles per texel
  std::vector<double> sums, kept;
  bool rays_ao = false, rays_thickness = false, ids = false;
  // Per sample of the pass: the hit's unit normal and the sum of its open AO directions.
  std::vector<glm::dvec3> hit_normal, bent_sum;
  std::vector<std::int64_t> object_id, material_id;
  RayQueue queue[2];  // AO's (occlusion only), thickness's (first hits)
  // Per sample of the pass, what its secondary rays start from: the hit point, the geometric
  // normal on the hit normal's side, the match group; per kind (0: AO's, 1: thickness's) the rays
  // cast so far, and per chain (kMaxChains a sample) the sum of its rays' values (AO: open rays;
  // thickness: min(t, D) / D) and its rays. With MapOptions::ao_independent_rays, per sample and
  // kind its random stream (keyed by texel and sample).
  std::vector<glm::dvec3> hit_point, hit_face;
  std::vector<std::uint32_t> ray_group;
  std::vector<std::uint32_t> rays_cast[2];
  std::vector<double> chain_sum[2];
  std::vector<std::uint32_t> chain_rays[2];
  std::vector<SampleStream> stream[2];
  const std::uint16_t* sample_texel = nullptr;  // the pass's samples' tile texels
  // Per tile texel and kind: its chains' seeds (kMaxChains pairs: the two axes') and the rays it
  // has numbered; the chains a texel's rays are dealt to (kFixedChains or kAutoChains, powers of 2).
  std::vector<OwenSeed> texel_seed[2];
  std::vector<std::uint32_t> texel_next[2];
  int chains = kFixedChains;
  // --ao-rays auto, per tile texel: its hit samples, rays, chains' sums (kMaxChains pairs, as
  // chain_standard_error reads them), and the rays each of its hit samples gets in the next round.
  std::vector<std::uint32_t> texel_hits, texel_more;
  std::vector<double> texel_rays, texel_chains;
  std::vector<std::uint32_t> seen;
  std::vector<std::int64_t> vote;
  std::vector<std::uint32_t> start, order, fill;   // the ID vote's counting sort
  bool needs_point = false, needs_normal = false;  // the hit's point / normal is read

  Impl(const MapInputs& in_, std::size_t tile_texels) : in(in_), texels(tile_texels) {
    std::fill(offset, offset + kSlots, -1);
    const auto use = [&](Slot s) {
      if (offset[s] >= 0) return;
      offset[s] = stride;
      stride += kSlotWidth[s];
    };
    for (MapKind k : in.maps->maps) {
      const Slot s = slot_of(k);
      if (s == kSlots) continue;
      use(s);
      if (k == MapKind::position) use(s_miss_position);
    }
    if (in.maps->wants(MapKind::bent_normal)) use(s_ao);  // the rays a texel's bent normal spent
    use(s_hits);
    use(s_samples);
    sums.assign(std::size_t(stride) * texels, 0.0);
    rays_ao = in.maps->wants(MapKind::ao) || in.maps->wants(MapKind::bent_normal);
    rays_thickness = in.maps->wants(MapKind::thickness);
    ids = in.maps->wants(MapKind::object_id) || in.maps->wants(MapKind::material_id);
    chains = in.maps->ao_rays_auto ? kAutoChains : kFixedChains;
    needs_point = has(s_position) || rays_ao || rays_thickness;
    needs_normal = has(s_object_normal) || has(s_bent) || rays_ao || rays_thickness;
    if (in.groups && in.groups->active())
      for (RayQueue& q : queue) q.group.resize(kRayBatch);
  }

  double* at(std::size_t texel, Slot s) { return &sums[texel * std::size_t(stride) + std::size_t(offset[s])]; }
  const double* at(std::size_t texel, Slot s) const { return &sums[texel * std::size_t(stride) + std::size_t(offset[s])]; }
  bool has(Slot s) const { return offset[s] >= 0; }

  std::uint32_t source_tri(std::uint32_t t) const { return in.source ? in.source[t] : t; }

  // Queues `count` more rays of kind `k` (0: AO's, over the hit normal's hemisphere; 1: thickness's,
  // over the inverted normal's) from sample r, continuing its texel's numbering (chains and points).
  void queue_rays(int k, std::size_t r, std::size_t count) {
    const bool thick = k == 1;
    RayQueue& q = queue[k];
    const glm::dvec3 axis = thick ? -hit_normal[r] : hit_normal[r];
    const glm::vec3 org(hit_point[r] + (thick ? -in.epsilon : in.epsilon) * hit_face[r]);
    const float tfar = float(thick ? in.thickness_distance : in.ao_distance);
    glm::dvec3 bt, bb, bn;  // the basis about the axis, once for the sample's rays
    orthonormal_basis(axis, bt, bb, bn);
    const std::size_t i = sample_texel[r];
    std::uint32_t& next = texel_next[k][i];
    const std::uint32_t chain_mask = std::uint32_t(chains - 1);
    const int chain_shift = chains == 8 ? 3 : 2;
    const OwenSeed* seeds = &texel_seed[k][i * kMaxChains * 2];
    std::uint32_t* sample_chain_rays = &chain_rays[k][r * kMaxChains];
    // In runs of up to kGenerate rays: their points first, then their directions, each loop short
    // and free of calls, so that the processor overlaps the rays' long chains of arithmetic.
    constexpr std::size_t kGenerate = 64;
    double u1[kGenerate], u2[kGenerate];
    float dx[kGenerate], dy[kGenerate], dz[kGenerate];
    std::uint32_t point[kGenerate];
    std::uint8_t point_chain[kGenerate];
    for (std::size_t done = 0; done < count;) {
      const std::size_t m = std::min(kGenerate, count - done);
      for (std::size_t j = 0; j < m; ++j) {
        const std::uint32_t n = next + std::uint32_t(j);
        point[j] = n >> chain_shift;
        point_chain[j] = std::uint8_t(n & chain_mask);
      }
      if (in.maps->ao_independent_rays) {
        for (std::size_t j = 0; j < m; ++j) {
          const glm::dvec2 u = stream[k][r].next2();
          u1[j] = u.x, u2[j] = u.y;
        }
      } else {
        scrambled_sobol2_many(point, point_chain, seeds, m, u1, u2);
      }
      cosine_directions(bt, bb, bn, u1, u2, m, dx, dy, dz);
      for (std::size_t j = 0; j < m; ++j) {
        const std::uint8_t chain = point_chain[j];
        q.rays.set(q.n, raycast::Ray{org, 0.0f, glm::vec3(dx[j], dy[j], dz[j]), tfar});
        q.sample[q.n] = std::uint32_t(r);
        q.chain[q.n] = chain;
        ++sample_chain_rays[chain];
        if (!q.group.empty()) q.group[q.n] = ray_group[r];
        if (++q.n == kRayBatch) flush(k);
      }
      next += std::uint32_t(m);
      done += m;
    }
    rays_cast[k][r] += std::uint32_t(count);
  }

  // --ao-rays auto: rounds of more rays of kind `k` for the texels whose standard error (from the
  // spread of their chains) is still above MapOptions::max_ao_error, until none is (or has
  // ao_rays_max rays), shared by its hit samples. Everything is
  // per texel, so the rounds do not depend on the tiling's threads.
  void cast_rounds(int k, const Samples& smp) {
    const MapOptions& mo = *in.maps;
    const double cap = double(mo.ao_rays_max);
    const std::size_t n = smp.count;
    for (;;) {
      texel_hits.assign(texels, 0);
      texel_rays.assign(texels, 0.0);
      texel_chains.assign(texels * 2 * kMaxChains, 0.0);
      texel_more.assign(texels, 0);
      for (std::size_t r = 0; r < n; ++r) {
        if (smp.hit_tri[r] == raycast::no_hit) continue;
        const std::size_t i = smp.texel[r];
        ++texel_hits[i];
        texel_rays[i] += double(rays_cast[k][r]);
        for (int c = 0; c < chains; ++c) {
          texel_chains[(i * kMaxChains + std::size_t(c)) * 2] += chain_sum[k][r * kMaxChains + std::size_t(c)];
          texel_chains[(i * kMaxChains + std::size_t(c)) * 2 + 1] += double(chain_rays[k][r * kMaxChains + std::size_t(c)]);
        }
      }
      bool more = false;
      for (std::size_t i = 0; i < texels; ++i) {
        const double rays = texel_rays[i], hits = double(texel_hits[i]);
        if (hits == 0.0 || rays >= cap) continue;
        const double se = chain_standard_error(&texel_chains[i * 2 * kMaxChains], true);
        if (se <= mo.max_ao_error) continue;
        // The rays that would bring it to E, at least half again, in whole rounds of its chains per
        // hit sample (so that its chains stay equal), at most the cap.
        const double want = std::max(0.5 * rays, rays * std::pow(se / mo.max_ao_error, 1.0 / kAutoErrorExponent) - rays);
        const double c = double(chains);
        const double per = std::min(c * std::ceil(want / hits / c), std::floor((cap - rays) / hits));
        if (per < 1.0) continue;
        texel_more[i] = std::uint32_t(per);
        more = true;
      }
      if (!more) return;
      for (std::size_t r = 0; r < n; ++r)
        if (smp.hit_tri[r] != raycast::no_hit && texel_more[smp.texel[r]]) queue_rays(k, r, texel_more[smp.texel[r]]);
      flush(k);
    }
  }

  // Casts queue `k`'s rays (0: AO's, occlusion; 1: thickness's, first hits of either facing) and
  // adds their results to their samples, in queue order.
  void flush(int k) {
    RayQueue& q = queue[k];
    if (q.n == 0) return;
    raycast::RayBatch batch = q.rays.rays();
    batch.group = q.group.empty() ? nullptr : q.group.data();
    const std::uint32_t* groups =
        in.groups && in.groups->active() && !in.maps->ao_occluders_all ? in.groups->high.data() : nullptr;
    if (k == 0) {
      raycast::SecondaryRayOptions so;
      so.group = groups;
      in.scene->scene->occluded(batch, q.occluded.data(), q.n, so);
      // Without a branch on the verdict, which a processor cannot predict (adding 0 leaves a sum's
      // bits as they are); the open directions only for a bent-normal map.
      for (std::size_t i = 0; i < q.n; ++i)
        chain_sum[0][std::size_t(q.sample[i]) * kMaxChains + q.chain[i]] += q.occluded[i] ? 0.0 : 1.0;
      if (has(s_bent))
        for (std::size_t i = 0; i < q.n; ++i)
          if (!q.occluded[i])
            bent_sum[q.sample[i]] += glm::dvec3(q.rays.direction(0)[i], q.rays.direction(1)[i], q.rays.direction(2)[i]);
    } else {
      raycast::SecondaryRayOptions so;
      so.group = groups;
      in.scene->scene->first_hits(batch, q.rays.hits(), q.n, so);
      for (std::size_t i = 0; i < q.n; ++i) {
        const std::size_t r = q.sample[i];
        const raycast::Hit h = q.rays.hit(i);
        chain_sum[1][r * kMaxChains + q.chain[i]] += h.hit() ? std::min(1.0, double(h.t) / in.thickness_distance) : 1.0;
      }
    }
    q.n = 0;
  }
};

TexelMaps::TexelMaps(const MapInputs& in, std::size_t tile_texels) : impl_(std::make_unique<Impl>(in, tile_texels)) {}
TexelMaps::~TexelMaps() = default;

void TexelMaps::keep() { impl_->kept = impl_->sums; }

void TexelMaps::restore_unrefined(const std::uint8_t* refine) {
  Impl& m = *impl_;
  const std::size_t w = std::size_t(m.stride);
  for (std::size_t i = 0; i < m.texels; ++i)
    if (!refine[i])
      std::copy(m.kept.begin() + std::ptrdiff_t(i * w), m.kept.begin() + std::ptrdiff_t((i + 1) * w),
                m.sums.begin() + std::ptrdiff_t(i * w));
}

void TexelMaps::shade(const Samples& smp, int tile_x0, int tile_y0, int side, int width, int level, std::size_t per_texel) {
  Impl& m = *impl_;
  const MapInputs& in = m.in;
  const Prepared& s = *in.s;
  const HighScene& sc = *in.scene;
  const std::size_t n = smp.count;
  std::fill(m.sums.begin(), m.sums.end(), 0.0);
  const bool rays = m.rays_ao || m.rays_thickness;
  if (rays) {  // the secondary rays' per-sample state and sums, only where a map casts them
    m.hit_normal.assign(n, glm::dvec3(0.0));
    m.bent_sum.assign(n, glm::dvec3(0.0));
    m.hit_point.assign(n, glm::dvec3(0.0));
    m.hit_face.assign(n, glm::dvec3(0.0));
    m.ray_group.assign(n, 0);
    m.sample_texel = smp.texel;
    for (int k = 0; k < 2; ++k) {
      m.rays_cast[k].assign(n, 0);
      m.chain_sum[k].assign(n * kMaxChains, 0.0);
      m.chain_rays[k].assign(n * kMaxChains, 0);
      if (in.maps->ao_independent_rays) m.stream[k].assign(n, SampleStream(0));
      m.texel_seed[k].resize(m.texels * kMaxChains * 2);
      m.texel_next[k].assign(m.texels, 0);
    }
  }
  if (m.ids) m.object_id.assign(n, -1), m.material_id.assign(n, -1);
  m.seen.assign(m.texels, 0);
  // Fixed: ao_rays per texel; auto: its first round.
  const int rays_per_texel = in.maps->ao_rays_auto ? std::min(kAutoFirstRays, in.maps->ao_rays_max) : in.maps->ao_rays;
  const std::size_t per_sample = std::max<std::size_t>(1, (std::size_t(rays_per_texel) + per_texel - 1) / per_texel);

  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = smp.texel[r];
    const std::size_t tri = std::size_t(smp.low_tri[r]);
    const double b[3] = {smp.b[0][r], smp.b[1][r], smp.b[2][r]};
    const std::uint32_t appearance = m.seen[i]++;
    *m.at(i, s_samples) += 1.0;
    const LowTriangle& lt = s.low_tris[tri];
    const auto low_normal = [&] {
      const glm::dvec3 ln = b[0] * lt.n[0] + b[1] * lt.n[1] + b[2] * lt.n[2];
      const double l = glm::length(ln);
      return l > 0.0 ? ln / l : glm::dvec3(0, 0, 1);
    };
    if (r + kAhead < n && smp.hit_tri[r + kAhead] != raycast::no_hit) {  // the hit's data, scattered over the mesh
      const std::size_t ahead = smp.hit_tri[r + kAhead];
      __builtin_prefetch(&sc.index[3 * ahead]);
      if (in.object) __builtin_prefetch(&in.object[ahead]);
      if (!in.material.empty()) __builtin_prefetch(&in.material[ahead]);
    }
    const std::uint32_t ht = smp.hit_tri[r];
    if (ht == raycast::no_hit) {
      if (m.has(s_object_normal)) {
        const glm::dvec3 ln = low_normal();
        for (int c = 0; c < 3; ++c) m.at(i, s_object_normal)[c] += ln[c];
      }
      if (m.has(s_miss_position)) {
        const glm::dvec3 low_p = b[0] * lt.p[0] + b[1] * lt.p[1] + b[2] * lt.p[2];
        for (int c = 0; c < 3; ++c) m.at(i, s_miss_position)[c] += low_p[c];
      }
      continue;
    }
    // The hit: point and normal interpolated with its barycentrics (each only where a map reads
    // it); the face normal where the corner normals cancel.
    const double w[3] = {1.0 - double(smp.u[r]) - double(smp.v[r]), double(smp.u[r]), double(smp.v[r])};
    const std::uint32_t* corner = &sc.index[3 * std::size_t(ht)];
    glm::dvec3 q[3], x(0.0), nh(0.0), face(0.0);
    if (m.needs_point) {
      for (int c = 0; c < 3; ++c) {
        q[c] = glm::dvec3(sc.positions[corner[c]]);
        x += w[c] * q[c];
      }
      face = glm::cross(q[1] - q[0], q[2] - q[0]);
    }
    if (m.needs_normal) {
      for (int c = 0; c < 3; ++c) nh += w[c] * glm::dvec3(sc.normals[3 * std::size_t(ht) + std::size_t(c)]);
      double len = glm::length(nh);
      if (!(len > 1e-12)) {
        for (int c = 0; c < 3; ++c) q[c] = glm::dvec3(sc.positions[corner[c]]);
        nh = glm::cross(q[1] - q[0], q[2] - q[0]), len = glm::length(nh);
      }
      nh = len > 0.0 ? nh / len : low_normal();
    }
    if (rays) m.hit_normal[r] = nh;
    *m.at(i, s_hits) += 1.0;
    if (m.has(s_object_normal))
      for (int c = 0; c < 3; ++c) m.at(i, s_object_normal)[c] += nh[c];
    if (m.has(s_height)) *m.at(i, s_height) += smp.dist[r];
    if (m.has(s_position))
      for (int c = 0; c < 3; ++c) m.at(i, s_position)[c] += x[c];
    const std::uint32_t src = m.source_tri(ht);
    if (m.has(s_curvature)) {
      double k = 0.0;
      for (int c = 0; c < 3; ++c) k += w[c] * double(in.curvature[corner[c]]);
      *m.at(i, s_curvature) += k;
    }
    if (m.has(s_color) && in.high->has_colors())
      for (int c = 0; c < 3; ++c) {
        const glm::dvec3 col(in.high->corner_color(src, c));
        for (int k = 0; k < 3; ++k) m.at(i, s_color)[k] += w[c] * col[k];
      }
    if (m.ids) {
      m.object_id[r] = in.object ? std::int64_t(in.object[ht]) : 0;
      m.material_id[r] = in.material.empty() ? 0 : std::int64_t(in.material[ht]);
    }
    // Secondary rays from just off the surface, on the side the rays go to.
    if (!rays) continue;
    const double face_len = glm::length(face);
    glm::dvec3 ng = face_len > 0.0 ? face / face_len : nh;
    if (glm::dot(ng, nh) < 0.0) ng = -ng;
    const std::size_t texel = std::size_t(tile_y0 + int(i / std::size_t(side))) * std::size_t(width) +
                              std::size_t(tile_x0 + int(i % std::size_t(side)));
    m.hit_point[r] = x;
    m.hit_face[r] = ng;
    m.ray_group[r] = m.queue[0].group.empty() ? 0u : in.groups->low[tri];
    for (int kind = 0; kind < 2; ++kind) {
      if (kind == 1 ? !m.rays_thickness : !m.rays_ao) continue;
      const std::uint64_t map_key = std::uint64_t(kind) + (in.maps->ray_seed << 8);
      if (in.maps->ao_independent_rays)
        m.stream[kind][r] = SampleStream(sample_key(texel, std::uint64_t(level) << 32 | appearance, map_key));
      // The texel's chains: one key per texel, pass and kind (the chains' seeds follow from it).
      if (m.texel_next[kind][i] == 0) {
        const std::uint64_t key = sample_key(texel, (std::uint64_t(level) << 32) | 0xffffffffu, map_key);
        for (int c = 0; c < m.chains; ++c) {
          std::uint64_t sx, sy;
          scramble_seeds(key + std::uint64_t(c) * 0x9e3779b97f4a7c15ull, sx, sy);
          m.texel_seed[kind][(i * kMaxChains + std::size_t(c)) * 2] = owen_seed(sx);
          m.texel_seed[kind][(i * kMaxChains + std::size_t(c)) * 2 + 1] = owen_seed(sy);
        }
      }
      m.queue_rays(kind, r, per_sample);
    }
  }
  m.flush(0);
  m.flush(1);
  if (in.maps->ao_rays_auto) {
    if (m.rays_ao) m.cast_rounds(0, smp);
    if (m.rays_thickness) m.cast_rounds(1, smp);
  }

  // Per sample: AO, bent normal and thickness into its texel, in sample order.
  for (std::size_t r = 0; rays && r < n; ++r) {
    const std::size_t i = smp.texel[r];
    const bool hit = smp.hit_tri[r] != raycast::no_hit;
    const std::size_t tri = std::size_t(smp.low_tri[r]);
    const double b[3] = {smp.b[0][r], smp.b[1][r], smp.b[2][r]};
    for (int k = 0; k < 2 && hit; ++k) {  // every ray queued is cast
      const Slot slot = k == 0 ? s_ao : s_thickness;
      if (!m.has(slot)) continue;
      double* v = m.at(i, slot);
      for (int c = 0; c < m.chains; ++c) {
        const double sum = m.chain_sum[k][r * kMaxChains + std::size_t(c)];
        v[0] += sum;
        v[2 + 2 * c] += sum;
        v[3 + 2 * c] += double(m.chain_rays[k][r * kMaxChains + std::size_t(c)]);
      }
      v[1] += double(m.rays_cast[k][r]);
    }
    if (m.has(s_bent)) {
      const PixelFrame frame = interpolate_frame(s.low_tris[tri].n, s.low_tris[tri].t, b, in.bitangent);
      glm::dvec3 dir = hit ? m.bent_sum[r] : glm::dvec3(0.0);
      if (!(glm::dot(dir, dir) > 0.0)) dir = hit ? m.hit_normal[r] : glm::dvec3(0.0);
      glm::dvec3 v;
      if (in.space == NormalSpace::tangent)
        v = glm::dot(dir, dir) > 0.0 ? encode_tangent_normal(frame, dir) : glm::dvec3(0, 0, 1);
      else {
        if (!(glm::dot(dir, dir) > 0.0)) dir = frame.n;
        const double l = glm::length(dir);
        v = l > 0.0 ? dir / l : glm::dvec3(0, 0, 1);
      }
      for (int c = 0; c < 3; ++c) m.at(i, s_bent)[c] += v[c];
    }
  }

  // The ID maps: per texel the index most of its hit samples take. A pass of at most one sample a
  // texel (seen[i] <= 1) takes each sample's index as it is; otherwise the samples are grouped by
  // texel, in sample order (a counting sort, once for both maps), and a texel of one sample takes
  // its index.
  const bool single = m.ids && std::all_of(m.seen.begin(), m.seen.end(), [](std::uint32_t c) { return c <= 1; });
  if (single) {
    for (int which = 0; which < 2; ++which) {
      const Slot slot = which == 0 ? s_object_id : s_material_id;
      if (!m.has(slot)) continue;
      const std::vector<std::int64_t>& id = which == 0 ? m.object_id : m.material_id;
      for (std::size_t r = 0; r < n; ++r) *m.at(smp.texel[r], slot) = id[r] >= 0 ? double(id[r]) : -1.0;
    }
  } else if (m.ids) {
    std::vector<std::uint32_t>&start = m.start, &order = m.order, &fill = m.fill;
    start.assign(m.texels + 1, 0);
    order.resize(n);
    for (std::size_t r = 0; r < n; ++r) ++start[std::size_t(smp.texel[r]) + 1];
    for (std::size_t t = 1; t <= m.texels; ++t) start[t] += start[t - 1];
    fill.assign(start.begin(), start.end() - 1);
    for (std::size_t r = 0; r < n; ++r) order[fill[smp.texel[r]]++] = std::uint32_t(r);
    for (int which = 0; which < 2; ++which) {
      const Slot slot = which == 0 ? s_object_id : s_material_id;
      if (!m.has(slot)) continue;
      const std::vector<std::int64_t>& id = which == 0 ? m.object_id : m.material_id;
      for (std::size_t t = 0; t < m.texels; ++t) {
        const std::uint32_t first = start[t], end = start[t + 1];
        if (first == end) continue;
        if (end - first == 1) {
          *m.at(t, slot) = id[order[first]] >= 0 ? double(id[order[first]]) : -1.0;
          continue;
        }
        m.vote.clear();
        for (std::uint32_t k = first; k < end; ++k)
          if (id[order[k]] >= 0) m.vote.push_back(id[order[k]]);
        *m.at(t, slot) = most_frequent(m.vote);
      }
    }
  }
}

void TexelMaps::write(MapTargets& out, int x0, int y0, int w, int h, int side, int width) const {
  const Impl& m = *impl_;
  const MapInputs& in = m.in;
  const MapOptions& maps = *in.maps;
  const bool flip_y = in.space == NormalSpace::tangent && in.green_down;
  // f(tile texel, map texel) for each of the tile's texels that have samples, a map at a time.
  const auto each = [&](auto&& f) {
    for (int y = 0; y < h; ++y) {
      const std::size_t row = std::size_t(y) * std::size_t(side), g = std::size_t(y0 + y) * std::size_t(width) + std::size_t(x0);
      for (int x = 0; x < w; ++x)
        if (*m.at(row + std::size_t(x), s_samples) > 0.0) f(row + std::size_t(x), g + std::size_t(x));
    }
  };
  for (std::size_t k = 0; k < maps.maps.size(); ++k) {
    const MapKind kind = maps.maps[k];
    const Slot slot = slot_of(kind);
    if (slot == kSlots) continue;
    Image& img = out.raw[k];
    float* const pixels = img.pixels.data();
    switch (kind) {
      case MapKind::object_normal:
      case MapKind::bent_normal:
        each([&](std::size_t i, std::size_t g) {
          const double* v = m.at(i, slot);
          const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
          glm::dvec3 n = len > 0.0 ? glm::dvec3(v[0], v[1], v[2]) / len : glm::dvec3(0, 0, 1);
          if (kind == MapKind::bent_normal && flip_y) n.y = -n.y;
          for (int c = 0; c < 3; ++c) pixels[3 * g + std::size_t(c)] = float(n[c]);
        });
        break;
      case MapKind::height:
      case MapKind::curvature:
        each([&](std::size_t i, std::size_t g) {
          const double hits = *m.at(i, s_hits);
          pixels[g] = float(hits > 0.0 ? *m.at(i, slot) / hits : 0.0);
        });
        break;
      case MapKind::position: {
        // The mean as a float, then to the box as finish_maps would (the same two roundings).
        const glm::dvec3 lo = in.position_lo, hi = in.position_hi;
        each([&](std::size_t i, std::size_t g) {
          const double *v = m.at(i, slot), *miss = m.at(i, s_miss_position);
          const double hits = *m.at(i, s_hits), samples = *m.at(i, s_samples);
          for (int c = 0; c < 3; ++c) {
            const float p = float(hits > 0.0 ? v[c] / hits : miss[c] / samples);
            pixels[3 * g + std::size_t(c)] =
                hi[c] > lo[c] ? float(std::clamp((double(p) - lo[c]) / (hi[c] - lo[c]), 0.0, 1.0)) : 0.5f;
          }
        });
        break;
      }
      case MapKind::vertex_color:
        each([&](std::size_t i, std::size_t g) {
          const double* v = m.at(i, slot);
          const double hits = *m.at(i, s_hits);
          for (int c = 0; c < 3; ++c) pixels[3 * g + std::size_t(c)] = float(hits > 0.0 ? v[c] / hits : 0.0);
        });
        break;
      case MapKind::ao:
      case MapKind::thickness: {
        Image& error = kind == MapKind::ao ? out.ao_error : out.thickness_error;
        each([&](std::size_t i, std::size_t g) {
          const double* v = m.at(i, slot);
          const double rays = v[1];
          pixels[g] = float(rays > 0.0 ? v[0] / rays : kind == MapKind::ao ? kMissAo : kMissThickness);
          error.pixels[g] = float(chain_standard_error(v + 2));
        });
        break;
      }
      case MapKind::object_id:
      case MapKind::material_id: {
        // The index (as the float it was kept as) rounded half away from zero (std::lround) without
        // a library call: a float's d + 0.5 is exact in double, so d + 0.5 < size says lround(d) <
        // size; -1 (a miss), NaN and indices out of range are 0 (black).
        const std::vector<glm::vec3>& colors = kind == MapKind::object_id ? in.object_colors : in.material_colors;
        const double size = double(colors.size());
        each([&](std::size_t i, std::size_t g) {
          const double d = double(float(*m.at(i, slot)));
          pixels[g] = d > -0.5 && d + 0.5 < size ? float(std::size_t(d + 0.5) + 1) : 0.0f;
        });
        break;
      }
      default: break;
    }
  }
  if (!out.ao_rays.pixels.empty()) each([&](std::size_t i, std::size_t g) { out.ao_rays.pixels[g] = float(m.at(i, s_ao)[1]); });
  if (!out.thickness_rays.pixels.empty())
    each([&](std::size_t i, std::size_t g) { out.thickness_rays.pixels[g] = float(m.at(i, s_thickness)[1]); });
}

}  // namespace nmbake
