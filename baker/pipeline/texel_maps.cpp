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

// --ao-rays auto: the first round's rays per texel, the fewest a later round adds, and the rays of
// each outcome (open, occluded) its stopping rule adds to a texel's AO count (Laplace's rule of
// succession; on the bench's sculpts 1 spent its rays better than 0 or 0.5, and 2 about as well:
// bench/accuracy_ao.h).
constexpr int kAutoFirstRays = 32;
constexpr int kAutoRoundRays = 16;
constexpr double kAutoPrior = 1.0;

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
  s_ao,             // 2: unoccluded rays, rays
  s_thickness,      // 3: sum of min(t, D) / D, sum of its squares, rays
  s_object_id,      // 1: the index taken
  s_material_id,    // 1
  s_hits,           // 1: samples that hit
  s_samples,        // 1: samples
  s_miss_position,  // 3: sum of low-poly points of the samples that miss
  kSlots
};
constexpr int kSlotWidth[kSlots] = {3, 3, 1, 3, 1, 3, 2, 3, 1, 1, 1, 1, 3};

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

// Secondary rays queued for one cast: per ray its sample, and with match groups its group.
struct RayQueue {
  raycast::RayArrays rays{kRayBatch};
  std::vector<std::uint32_t> sample = std::vector<std::uint32_t>(kRayBatch), group;
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

}  // namespace

MapTargets allocate_map_targets(const MapOptions& maps, int width, int height) {
  MapTargets out;
  for (MapKind k : maps.maps) out.raw.push_back(k == MapKind::normal ? Image() : Image(width, height, map_channels(k), 0.0f));
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
  // Per sample of the pass: the hit's unit normal, and the secondary rays' sums.
  std::vector<glm::dvec3> hit_normal, bent_sum;
  std::vector<std::uint32_t> open_rays;
  std::vector<std::int64_t> object_id, material_id;
  RayQueue queue[2];  // AO's (occlusion only), thickness's (first hits)
  std::vector<double> thick_sum, thick_sq;
  // Per sample of the pass, what its secondary rays start from: the hit point, the geometric
  // normal on the hit normal's side, the match group; per kind (0: AO's, 1: thickness's) its
  // random stream (keyed by texel and sample) and the rays cast so far.
  std::vector<glm::dvec3> hit_point, hit_face;
  std::vector<std::uint32_t> ray_group;
  std::vector<SampleStream> stream[2];
  std::vector<std::uint32_t> rays_cast[2];
  // --ao-rays auto, per tile texel: its hit samples, rays, sums of their values (and squares), and
  // the rays each of its hit samples gets in the next round.
  std::vector<std::uint32_t> texel_hits, texel_more;
  std::vector<double> texel_rays, texel_sum, texel_sq;
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
  // over the inverted normal's) from sample r, continuing its stream: the first rays of a sample are
  // the same whatever the rounds that follow.
  void queue_rays(int k, std::size_t r, std::size_t count) {
    const bool thick = k == 1;
    RayQueue& q = queue[k];
    const glm::dvec3 axis = thick ? -hit_normal[r] : hit_normal[r];
    const glm::dvec3 org = hit_point[r] + (thick ? -in.epsilon : in.epsilon) * hit_face[r];
    SampleStream& st = stream[k][r];
    for (std::size_t j = 0; j < count; ++j) {
      const double u1 = st.next(), u2 = st.next();
      const glm::dvec3 d = cosine_direction(axis, u1, u2);
      raycast::Ray ray;
      ray.origin = glm::vec3(org);
      ray.direction = glm::vec3(d);
      ray.tnear = 0.0f;
      ray.tfar = float(thick ? in.thickness_distance : in.ao_distance);
      q.rays.set(q.n, ray);
      q.sample[q.n] = std::uint32_t(r);
      if (!q.group.empty()) q.group[q.n] = ray_group[r];
      if (++q.n == kRayBatch) flush(k);
    }
    rays_cast[k][r] += std::uint32_t(count);
  }

  // --ao-rays auto: rounds of more rays of kind `k` for the texels whose standard error is still
  // above MapOptions::max_ao_error, until none is (or has ao_rays_max rays). A texel's samples
  // share its round's rays; everything is per texel, so the rounds do not depend on the tiling's
  // threads.
  void cast_rounds(int k, const Samples& smp) {
    const MapOptions& mo = *in.maps;
    const double e2 = mo.max_ao_error * mo.max_ao_error;
    const double cap = double(mo.ao_rays_max);
    const std::size_t n = smp.count;
    for (;;) {
      texel_hits.assign(texels, 0);
      texel_rays.assign(texels, 0.0);
      texel_sum.assign(texels, 0.0);
      texel_sq.assign(texels, 0.0);
      texel_more.assign(texels, 0);
      for (std::size_t r = 0; r < n; ++r) {
        if (smp.hit_tri[r] == raycast::no_hit) continue;
        const std::size_t i = smp.texel[r];
        ++texel_hits[i];
        texel_rays[i] += double(rays_cast[k][r]);
        texel_sum[i] += k == 0 ? double(open_rays[r]) : thick_sum[r];
        if (k == 1) texel_sq[i] += thick_sq[r];
      }
      bool more = false;
      for (std::size_t i = 0; i < texels; ++i) {
        const double rays = texel_rays[i], hits = double(texel_hits[i]);
        if (hits == 0.0 || rays >= cap) continue;
        double var;  // of one ray's value
        if (k == 0) {
          // The open share with kAutoPrior rays of each outcome added: a texel whose first rays
          // all agree is not taken for certain (32 open rays leave p = 0.97 quite likely).
          const double p = (texel_sum[i] + kAutoPrior) / (rays + 2.0 * kAutoPrior);
          var = p * (1.0 - p) * rays / std::max(1.0, rays - 1.0);
        } else {
          const double mean = texel_sum[i] / rays;
          var = rays > 1.0 ? std::max(0.0, (texel_sq[i] - rays * mean * mean) / (rays - 1.0)) : 0.0;
        }
        if (var <= e2 * rays) continue;  // standard error sqrt(var / rays) at most E
        // The rays that would bring it to E, at least a round's worth, at most the cap.
        const double want = std::min(cap - rays, std::max(double(kAutoRoundRays), std::ceil(var / e2 - rays)));
        const double per = std::min(std::ceil(want / hits), std::floor((cap - rays) / hits));
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
      for (std::size_t i = 0; i < q.n; ++i) {
        if (q.occluded[i]) continue;
        const std::size_t r = q.sample[i];
        ++open_rays[r];
        bent_sum[r] += glm::dvec3(q.rays.direction(0)[i], q.rays.direction(1)[i], q.rays.direction(2)[i]);
      }
    } else {
      raycast::HitRule rule;
      rule.skip_backfaces = false;
      rule.group = groups;
      in.scene->scene->intersect(batch, q.rays.hits(), q.n, groups ? &rule : nullptr);
      for (std::size_t i = 0; i < q.n; ++i) {
        const std::size_t r = q.sample[i];
        const raycast::Hit h = q.rays.hit(i);
        const double d = h.hit() ? std::min(1.0, double(h.t) / in.thickness_distance) : 1.0;
        thick_sum[r] += d;
        thick_sq[r] += d * d;
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
    m.open_rays.assign(n, 0);
    m.thick_sum.assign(n, 0.0);
    m.thick_sq.assign(n, 0.0);
    m.hit_point.assign(n, glm::dvec3(0.0));
    m.hit_face.assign(n, glm::dvec3(0.0));
    m.ray_group.assign(n, 0);
    for (int k = 0; k < 2; ++k) {
      m.stream[k].assign(n, SampleStream(0));
      m.rays_cast[k].assign(n, 0);
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
      m.stream[kind][r] = SampleStream(
          sample_key(texel, std::uint64_t(level) << 32 | appearance, std::uint64_t(kind) + (in.maps->ray_seed << 8)));
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
    if (m.has(s_ao) && hit) {
      m.at(i, s_ao)[0] += double(m.open_rays[r]);
      m.at(i, s_ao)[1] += double(m.rays_cast[0][r]);
    }
    if (m.has(s_thickness) && hit) {
      m.at(i, s_thickness)[0] += m.thick_sum[r];
      m.at(i, s_thickness)[1] += m.thick_sq[r];
      m.at(i, s_thickness)[2] += double(m.rays_cast[1][r]);  // every ray queued is cast
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

  // The ID maps: per texel the index most of its hit samples take. Samples grouped by texel, in
  // sample order (a counting sort, once for both maps); a texel of one sample takes its index.
  if (m.ids) {
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
  const MapOptions& maps = *m.in.maps;
  const bool flip_y = m.in.space == NormalSpace::tangent && m.in.green_down;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(side) + std::size_t(x);
      const double samples = *m.at(i, s_samples);
      if (samples <= 0.0) continue;
      const double hits = *m.at(i, s_hits);
      const std::size_t g = std::size_t(y0 + y) * std::size_t(width) + std::size_t(x0 + x);
      for (std::size_t k = 0; k < maps.maps.size(); ++k) {
        const MapKind kind = maps.maps[k];
        if (kind == MapKind::normal) continue;
        const Slot slot = slot_of(kind);
        if (slot == kSlots) continue;
        Image& img = out.raw[k];
        float* px = &img.pixels[g * std::size_t(img.channels)];
        const double* v = m.at(i, slot);
        switch (kind) {
          case MapKind::object_normal:
          case MapKind::bent_normal: {
            const double len = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            glm::dvec3 n = len > 0.0 ? glm::dvec3(v[0], v[1], v[2]) / len : glm::dvec3(0, 0, 1);
            if (kind == MapKind::bent_normal && flip_y) n.y = -n.y;
            for (int c = 0; c < 3; ++c) px[c] = float(n[c]);
            break;
          }
          case MapKind::height:
          case MapKind::curvature: px[0] = float(hits > 0.0 ? v[0] / hits : 0.0); break;
          case MapKind::position: {
            const double* miss = m.at(i, s_miss_position);
            for (int c = 0; c < 3; ++c) px[c] = float(hits > 0.0 ? v[c] / hits : miss[c] / samples);
            break;
          }
          case MapKind::vertex_color:
            for (int c = 0; c < 3; ++c) px[c] = float(hits > 0.0 ? v[c] / hits : 0.0);
            break;
          case MapKind::ao: {
            const double rays = v[1], p = rays > 0.0 ? v[0] / rays : kMissAo;
            px[0] = float(p);
            out.ao_error.pixels[g] = float(rays > 1.0 ? std::sqrt(p * (1.0 - p) / (rays - 1.0)) : 0.0);
            break;
          }
          case MapKind::thickness: {
            const double rays = v[2], mean = rays > 0.0 ? v[0] / rays : kMissThickness;
            px[0] = float(mean);
            const double var = rays > 1.0 ? std::max(0.0, (v[1] - rays * mean * mean) / (rays - 1.0)) : 0.0;
            out.thickness_error.pixels[g] = float(rays > 1.0 ? std::sqrt(var / rays) : 0.0);
            break;
          }
          case MapKind::object_id:
          case MapKind::material_id:
            for (int c = 0; c < 3; ++c) px[c] = float(v[0]);
            break;
          default: break;
        }
      }
      if (!out.ao_rays.pixels.empty()) out.ao_rays.pixels[g] = float(m.at(i, s_ao)[1]);
      if (!out.thickness_rays.pixels.empty()) out.thickness_rays.pixels[g] = float(m.at(i, s_thickness)[2]);
    }
}

}  // namespace nmbake
