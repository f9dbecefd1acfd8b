#include "pipeline/trace.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

#include "pipeline/adaptive_levels.h"
#include "pipeline/texel_maps.h"
#include "pipeline/trace_stats.h"
#include "pipeline/workers.h"
#include "trace/shade_batch.h"
#include "trace/tile_kernels.h"

namespace nmbake {

namespace {

constexpr std::size_t kTilesPerGrab = 4;  // consecutive tiles a trace thread takes at once
// Tangent components this close to zero are written as exactly 0: a flat result is then
// (128,128,255) and not a coin flip between 127 and 128 decided by float noise.
constexpr double kSnap = 1e-6;

// What every thread of the trace reads, and the state they share.
struct Shared {
  Shared(const Prepared& s_, const HighScene& scene_, const TileBins& bins_, const RaySetup& setup_, const BakeOptions& opt_,
         const TraceTargets& out_, int threads)
      : s(s_),
        scene(scene_),
        bins(bins_),
        setup(setup_),
        opt(opt_),
        out(out_),
        offsets(opt_.adaptive ? gauss_legendre_offsets() : sample_offsets(opt_.samples)),
        levels(refine_levels(opt_)),
        rays_per_sample(setup_.closest ? 2 : 1),
        batched(opt_.space == NormalSpace::tangent && opt_.bitangent == BitangentMode::per_pixel),
        per_object(s_.low_objects > 1 || s_.high_objects > 1),
        stats(std::size_t(threads)) {
    if (per_object)
      for (ThreadStats& ts : stats) {
        ts.low_samples.assign(s.low_objects, 0);
        ts.low_hits.assign(s.low_objects, 0);
        ts.high_hits.assign(s.high_objects, 0);
      }
  }
  const Prepared& s;
  const HighScene& scene;
  const TileBins& bins;
  const RaySetup& setup;
  const BakeOptions& opt;
  const TraceTargets& out;
  std::vector<glm::dvec2> offsets;  // every texel's samples (adaptive: the first 4)
  std::vector<RefineLevel> levels;  // adaptive: the passes after the first; else empty
  int rays_per_sample = 1;
  bool batched = false;     // tangent space, per-pixel bitangent: shade_batch.h shades most samples
  bool per_object = false;  // several objects: hits counted per object
  const raycast::HitRule* hit_rule = nullptr;
  bool prefer = false;              // the rule looks at the rays' preferred parts (back faces skipped)
  RayGroups groups;                 // with --match: per low-poly triangle and BVH triangle
  const MapInputs* maps = nullptr;  // the extra maps (TraceTargets::maps), or null: none
  std::vector<ThreadStats> stats;
  // Hit distances summed per tile, then over tiles in order: the mean does not depend on which
  // thread took which tile.
  std::vector<double> tile_dsum;
  std::atomic<std::size_t> next_tile{0}, tiles_done{0};
  std::atomic<bool> cancel{false};
};

// One thread's buffers and its walk over the tiles it takes. Sample slots of a tile: sample k of
// tile texel (x, y) is slot (y * side + x) * samples + k, a texel's samples side by side
// (cover_rect_samples). The covered samples are compacted in slot order, which puts each texel's
// samples together in sample order: that fixes how its values are summed, and a packet of rays is
// a texel's samples (or, with one sample, a row of texels), which Embree traces faster than rays
// spread over texels. Rays and hits are arrays, the layout Embree's packets take; sample r casts
// rays r * rays_per_sample onwards. The coverage fills slots in these same arrays (with the default
// policy's one ray per sample, slot i's ray is ray i), and the compaction closes the gaps in place:
// a fully covered stretch of slots stays where it is.
class TileTracer {
 public:
  TileTracer(Shared& sh, int id)
      : sh_(sh),
        ts_(sh.stats[std::size_t(id)]),
        side_(sh.bins.side),
        tile_texels_(std::size_t(side_) * std::size_t(side_)),
        slot_count_(tile_texels_ * std::max(sh.offsets.size(), sh.levels.empty() ? 0 : sh.levels.back().offsets.size())),
        kernel_rays_(!sh.setup.closest),
        rays_(slot_count_ * std::size_t(sh.rays_per_sample)),
        hits_(rays_.hits()),
        sample_tri_(slot_count_),
        sample_b_(3 * slot_count_),
        sample_texel_(slot_count_),
        sample_fallback_(slot_count_, 1),
        signed_base_(rays_.size(), double(sh.setup.front)),
        chosen_(slot_count_),
        chosen_tri_(slot_count_),
        chosen_u_(slot_count_),
        chosen_v_(slot_count_),
        value_(3 * slot_count_),
        one_at_a_time_(slot_count_, 1),
        acc_(4 * tile_texels_),
        miss_count_(tile_texels_),
        refine_(sh.levels.empty() ? 0 : tile_texels_) {
    for (int c = 0; c < 3; ++c) {
      sb_[c] = &sample_b_[std::size_t(c) * slot_count_];
      value_c_[c] = &value_[std::size_t(c) * slot_count_];
      sums_.sum[c] = &acc_[std::size_t(c) * tile_texels_];
    }
    sums_.count = &acc_[3 * tile_texels_];
    // With two rays per sample (closest), the first leaves the low-poly outwards.
    if (sh.rays_per_sample == 2) {
      outward_.assign(rays_.size(), 0);
      for (std::size_t i = 0; i < outward_.size(); i += 2) outward_[i] = 1;
    }
    batch_ = rays_.rays();
    batch_.outward = outward_.empty() ? nullptr : outward_.data();
    batch_.coherent = true;  // a tile's samples in rows of texels, sample by sample
    if (sh.setup.cage) {
      prefer_lo_.assign(rays_.size(), 0.0f);
      prefer_hi_.assign(rays_.size(), std::numeric_limits<float>::infinity());  // inward rays' (sample_rays)
      if (sh.prefer) {
        batch_.prefer_lo = prefer_lo_.data();
        batch_.prefer_hi = prefer_hi_.data();
      }
    }
    if (sh.groups.active()) {
      ray_group_.assign(rays_.size(), 0);
      batch_.group = ray_group_.data();
    }
    // Every default-policy ray without a cage starts at 0 and reaches front + rear (sample_rays'
    // too); a cage's rays have each their own reach, made with them.
    if (kernel_rays_ && !sh.setup.cage) std::fill(rays_.tfar(), rays_.tfar() + rays_.size(), sh.setup.front + sh.setup.rear);
    if (sh.maps) {
      maps_ = std::make_unique<TexelMaps>(*sh.maps, tile_texels_);
      sample_dist_.resize(slot_count_);
    }
  }

  // trace_texels: texels[order[i]] for first[k] <= i < first[k + 1] lie in one tile, traced alone
  // (as a refining pass traces its marked ones) for each k taken from the shared counter.
  void run_texels(const std::vector<std::uint32_t>& texels, const std::vector<std::size_t>& order,
                  const std::vector<std::size_t>& first, std::vector<glm::dvec3>& out) {
    std::vector<std::uint8_t> only(tile_texels_, 0);
    const std::uint32_t w = std::uint32_t(sh_.opt.width);
    for (std::size_t k; !sh_.cancel.load(std::memory_order_relaxed) && (k = sh_.next_tile.fetch_add(1)) + 1 < first.size();) {
      const std::uint32_t one = texels[order[first[k]]];
      const std::size_t tile = sh_.bins.tile_of(int(one % w), int(one / w));
      const TileRect rect = rect_of(tile);
      const auto at = [&](std::size_t i) {  // in the tile
        return std::size_t(int(texels[order[i]] / w) - rect.y0) * std::size_t(side_) +
               std::size_t(int(texels[order[i]] % w) - rect.x0);
      };
      for (std::size_t i = first[k]; i < first[k + 1]; ++i) only[at(i)] = 1;
      trace_pass(tile, rect, sh_.offsets, only.data());
      for (std::size_t i = first[k]; i < first[k + 1]; ++i) {
        const std::size_t j = at(i);
        only[j] = 0;
        glm::dvec3 v(sums_.sum[0][j], sums_.sum[1][j], sums_.sum[2][j]);
        const double len = glm::length(v);
        v = len > 0.0 ? v * (1.0 / len) : glm::dvec3(0, 0, 1);
        if (sh_.opt.space == NormalSpace::tangent && sh_.opt.green_down) v.y = -v.y;
        if (sums_.count[j] > 0.0) out[order[i]] = v;
      }
    }
  }

  void run() {
    const std::size_t tile_count = sh_.bins.count();
    for (std::size_t tile = 0, grab_end = 0; !sh_.cancel.load(std::memory_order_relaxed); ++tile) {
      if (tile == grab_end) {
        // A few consecutive tiles at a time: they lie near each other on the model, and a thread
        // that casts their rays one after another finds more of the BVH in its own caches.
        tile = sh_.next_tile.fetch_add(kTilesPerGrab);
        if (tile >= tile_count) break;
        grab_end = std::min(tile + kTilesPerGrab, tile_count);
      }
      if (sh_.bins.start[tile] != sh_.bins.start[tile + 1]) trace_tile(tile);  // else no triangle touches it
      ++sh_.tiles_done;
    }
  }

 private:
  struct TileRect {
    int x0, y0, w, h;  // first texel, and size (tiles at the map's right and bottom edges are cut)
  };
  TileRect rect_of(std::size_t tile) const {
    const int x0 = int(tile % std::size_t(sh_.bins.tiles_x)) * side_, y0 = int(tile / std::size_t(sh_.bins.tiles_x)) * side_;
    return {x0, y0, std::min(side_, sh_.opt.width - x0), std::min(side_, sh_.opt.height - y0)};
  }

  void trace_tile(std::size_t tile) {
    const TileRect rect = rect_of(tile);
    pass_level_ = 0;
    sh_.tile_dsum[tile] = trace_pass(tile, rect, sh_.offsets, nullptr);
    std::size_t last_full = sh_.offsets.size();  // samples a texel of the last pass has when fully covered
    for (std::size_t level = 0; level < sh_.levels.size(); ++level) {
      if (!mark_refined(sh_.levels[level], level == 0, double(last_full))) break;
      // The marked texels again with every sample of the level; the others keep their sums so far.
      first_acc_ = acc_;
      first_miss_ = miss_count_;
      if (maps_) maps_->keep();
      pass_level_ = int(level) + 1;
      sh_.tile_dsum[tile] += trace_pass(tile, rect, sh_.levels[level].offsets, refine_.data());
      if (maps_) maps_->restore_unrefined(refine_.data());
      for (std::size_t i = 0; i < tile_texels_; ++i) {
        if (refine_[i]) continue;
        for (int c = 0; c < 4; ++c) acc_[std::size_t(c) * tile_texels_ + i] = first_acc_[std::size_t(c) * tile_texels_ + i];
        miss_count_[i] = first_miss_[i];
      }
      last_full = sh_.levels[level].offsets.size();
    }
    write_texels(rect);
  }

  // One pass over the tile with these sample offsets (only the texels `only` marks, when given):
  // cover, make and cast the rays, count the hits, shade into sums_. Returns the sum of hit distances.
  double trace_pass(std::size_t tile, const TileRect& rect, const std::vector<glm::dvec2>& offsets, const std::uint8_t* only) {
    const std::size_t sample_count = cover_tile(tile, rect, offsets, only);
    const std::size_t ray_count = sample_count * std::size_t(sh_.rays_per_sample);
    make_rays(sample_count);
    if (sh_.groups.active()) set_groups(sample_count);
    if (ray_count) {
      sh_.scene.scene->intersect(batch_, hits_, ray_count, sh_.hit_rule);
      for (const auto& [i, tnear] : unmatched_) rays_.tnear()[i] = tnear;
      if (sh_.hit_rule)
        for (std::size_t r = 0; r < ray_count; ++r) ts_.backface_skips += (hits_.flags[r] & raycast::hit_passed_backface) != 0;
    }
    ts_.rays += ray_count;
    const double dsum = count_hits(sample_count);
    shade(sample_count);
    if (maps_) {
      const bool one_ray = sh_.rays_per_sample == 1;
      maps_->shade(
          {sample_tri_.data(), sb_, sample_texel_.data(), one_ray ? hits_.triangle : chosen_tri_.data(),
           one_ray ? hits_.u : chosen_u_.data(), one_ray ? hits_.v : chosen_v_.data(), sample_dist_.data(), sample_count},
          rect.x0, rect.y0, side_, sh_.opt.width, pass_level_, offsets.size());
    }
    return dsum;
  }

  // Adaptive sampling: marks in refine_, among the texels the last pass baked (every covered one
  // after the first pass, else those refine_ marks), those whose samples disagree (one lies farther
  // than the level's angle from their mean, some miss and some hit) or, where the level says, that
  // not all of them cover (an island's edge). Returns whether any is marked.
  bool mark_refined(const RefineLevel& level, bool first, double full) {
    const double cos_max = level.cos_max;
    for (std::size_t i = 0; i < tile_texels_; ++i) {
      const double n = sums_.count[i];
      const bool baked = n > 0.0 && (first || refine_[i]);
      if (first && baked) ++ts_.base_texels;
      refine_[i] = baked ? 2 : 0;  // 2: in the last pass, not (yet) marked
      if (baked && ((level.partial && n < full) || (miss_count_[i] > 0 && double(miss_count_[i]) < n))) refine_[i] = 1;
    }
    for (std::size_t r = 0; r < last_sample_count_; ++r) {
      const std::size_t i = sample_texel_[r];
      if (refine_[i] != 2) continue;
      const double m[3] = {sums_.sum[0][i], sums_.sum[1][i], sums_.sum[2][i]};
      const double v[3] = {value_c_[0][r], value_c_[1][r], value_c_[2][r]};
      const double dot = m[0] * v[0] + m[1] * v[1] + m[2] * v[2];
      const double mm = m[0] * m[0] + m[1] * m[1] + m[2] * m[2], vv = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
      // cos(angle) < cos_max, without a division or a square root: dot < cos_max * |m| |v|.
      if (dot <= 0.0 ? mm > 0.0 || vv > 0.0 : dot * dot < cos_max * cos_max * mm * vv) refine_[i] = 1;
    }
    std::size_t marked = 0;
    for (std::uint8_t& f : refine_) {
      f = f == 1;
      marked += f;
    }
    if (first) {
      ts_.base_texels -= marked;
      ts_.refined_texels += marked;
    } else {
      ts_.refined_texels -= marked;
      ts_.deep_texels += marked;
    }
    return marked > 0;
  }

  // Rasterize: the covered samples of the tile, compacted (and, for the default policy, their
  // rays). The lowest triangle index wins a sample covered twice (overlapping islands).
  std::size_t cover_tile(std::size_t tile, const TileRect& rect, const std::vector<glm::dvec2>& offsets,
                         const std::uint8_t* only) {
    const TileBins& bins = sh_.bins;
    const int tx0 = rect.x0, ty0 = rect.y0, tw = rect.w, th = rect.h;
    // Sample k of texel (x, y) is slot ((y - y_first) * side + x) * samples + k: the first pass lays
    // out every row of the tile, a refining pass only its rows y_first .. y_first + rows - 1 that
    // hold marked texels (the same samples in the same order, in fewer slots to clear and compact).
    int y_first = 0, rows = side_;
    if (only && !marked_rows(only, tw, th, y_first, rows)) return last_sample_count_ = 0;
    const std::size_t per = offsets.size(), band = std::size_t(rows) * std::size_t(side_);  // band: texels laid out
    const std::size_t slot_count = band * per;
    std::fill(sample_tri_.begin(), sample_tri_.begin() + std::ptrdiff_t(slot_count), -1);
    const bool cage = kernel_rays_ && sh_.setup.cage;
    const SampleSlots slots{sample_tri_.data(),
                            {sb_[0], sb_[1], sb_[2]},
                            {rays_.origin(0), rays_.origin(1), rays_.origin(2)},
                            {rays_.direction(0), rays_.direction(1), rays_.direction(2)},
                            sample_fallback_.data(),
                            cage ? rays_.tfar() : nullptr,
                            cage ? signed_base_.data() : nullptr,
                            cage ? prefer_lo_.data() : nullptr};
    const KernelRays kernel_rays{kernel_rays_ ? sh_.s.low_tris.data() : nullptr, sh_.setup.front,
                                 cage ? sh_.s.cage_tris.data() : nullptr, sh_.setup.diagonal};
    // A refining pass covers, row by row, only the span of the row's marked texels (span_): a
    // slot's result does not depend on the rectangle it is covered in, and the others are dropped
    // below.
    offset_x_.resize(per);
    offset_y_.resize(per);
    for (std::size_t k = 0; k < per; ++k) offset_x_[k] = offsets[k].x, offset_y_[k] = offsets[k].y;
    const auto cover = [&](const TexelTriangle& tt, std::uint32_t t, int x0, int x1, int y0, int y1) {
      const std::size_t first = (std::size_t(y0 - ty0 - y_first) * std::size_t(side_) + std::size_t(x0 - tx0)) * per;
      const std::size_t taken = per == 1
                                    ? cover_rect(tt, std::int32_t(t), x0, x1, y0, y1, offset_x_[0], offset_y_[0], kernel_rays,
                                                 slots, first, std::size_t(side_))
                                    : cover_rect_samples(tt, std::int32_t(t), x0, x1, y0, y1, offset_x_.data(), offset_y_.data(),
                                                         int(per), kernel_rays, slots, first, std::size_t(side_) * per);
      if (!only) ts_.overlaps += taken;  // a refining pass covers again what the first counted
    };
    for (std::uint32_t bi = bins.start[tile]; bi < bins.start[tile + 1]; ++bi) {
      const std::uint32_t t = bins.tris[bi];
      const TexelTriangle& tt = bins.texel_tris[t];
      const int x0 = std::max(tt.xmin, tx0), x1 = std::min(tt.xmax, tx0 + tw - 1);
      const int y0 = std::max(tt.ymin, ty0), y1 = std::min(tt.ymax, ty0 + th - 1);
      if (x1 < x0 || y1 < y0) continue;
      if (!only) {
        cover(tt, t, x0, x1, y0, y1);
        continue;
      }
      for (int y = y0; y <= y1; ++y) {
        const auto [lo, hi] = span_[std::size_t(y - ty0)];
        if (std::max(x0, tx0 + lo) <= std::min(x1, tx0 + hi)) cover(tt, t, std::max(x0, tx0 + lo), std::min(x1, tx0 + hi), y, y);
      }
    }
    if (only)  // the unmarked texels within the rows' spans
      for (int r = 0; r < rows; ++r) {
        const int y = y_first + r;
        const std::size_t row = std::size_t(r) * std::size_t(side_);
        for (int x = span_[std::size_t(y)].first; x <= span_[std::size_t(y)].second; ++x)
          if (!only[std::size_t(y) * std::size_t(side_) + std::size_t(x)])
            std::fill_n(sample_tri_.begin() + std::ptrdiff_t((row + std::size_t(x)) * per), per, -1);
      }
    const CoveredSamples covered{sample_tri_.data(),
                                 {sb_[0], sb_[1], sb_[2]},
                                 sample_texel_.data(),
                                 {slots.org[0], slots.org[1], slots.org[2]},
                                 {slots.dir[0], slots.dir[1], slots.dir[2]},
                                 sample_fallback_.data(),
                                 slots.tfar,
                                 slots.base,
                                 slots.prefer_lo};
    last_sample_count_ = compact_samples(slots, slot_count, per, kernel_rays_, covered);
    if (y_first > 0)  // texel indices within the band, made the tile's
      for (std::size_t r = 0; r < last_sample_count_; ++r) sample_texel_[r] = std::uint16_t(sample_texel_[r] + y_first * side_);
    return last_sample_count_;
  }

  // Per row of the tile, the first and last texel `only` marks (first > last: none), in span_; the
  // first and the number of rows from it to the last with a mark. Whether any is marked.
  bool marked_rows(const std::uint8_t* only, int tw, int th, int& y_first, int& rows) {
    span_.assign(std::size_t(th), {side_, -1});
    int y_last = -1;
    y_first = th;
    for (int y = 0; y < th; ++y) {
      for (int x = 0; x < tw; ++x)
        if (only[std::size_t(y) * std::size_t(side_) + std::size_t(x)])
          span_[std::size_t(y)] = {std::min(span_[std::size_t(y)].first, x), x};
      if (span_[std::size_t(y)].first <= span_[std::size_t(y)].second) y_first = std::min(y_first, y), y_last = y;
    }
    rows = y_last - y_first + 1;
    return y_last >= 0;
  }

  // The rays the coverage did not make, one at a time: the closest-hit policy's, and the cage-first
  // policy's special cases.
  void make_rays(std::size_t sample_count) {
    const RaySetup& setup = sh_.setup;
    const std::size_t per = std::size_t(sh_.rays_per_sample);
    for (std::size_t r = 0; r < sample_count; ++r) {
      if (!sample_fallback_[r]) continue;
      raycast::Ray one[2];
      const double b[3] = {sb_[0][r], sb_[1][r], sb_[2][r]};
      float lo[2], hi[2];
      const int n = sample_rays(sh_.s, std::size_t(sample_tri_[r]), b, setup, one, &signed_base_[r * per], lo, hi);
      for (int j = 0; j < n; ++j) {
        const std::size_t i = r * per + std::size_t(j);
        rays_.set(i, one[j]);
        if (setup.cage) prefer_lo_[i] = lo[j], prefer_hi_[i] = hi[j];
      }
    }
  }

  // Each ray's match group; the rays of unmatched objects are cast empty (tnear past tfar, put
  // back after the cast).
  void set_groups(std::size_t sample_count) {
    const std::size_t per = std::size_t(sh_.rays_per_sample);
    unmatched_.clear();
    for (std::size_t r = 0; r < sample_count; ++r) {
      const std::uint32_t g = sh_.groups.low[std::size_t(sample_tri_[r])];
      for (std::size_t j = 0; j < per; ++j) {
        const std::size_t i = r * per + j;
        ray_group_[i] = g;
        if (g != kNoMatch) continue;
        unmatched_.emplace_back(i, rays_.tnear()[i]);
        rays_.tnear()[i] = std::numeric_limits<float>::infinity();
      }
    }
  }

  // In sample order, which ray's hit counts and the hit statistics. Returns the tile's sum of hit
  // distances.
  double count_hits(std::size_t sample_count) {
    std::fill(miss_count_.begin(), miss_count_.end(), 0u);
    std::size_t tile_hits = 0, unmatched = 0;
    // In registers for the tile: the stores below could alias the thread's counters.
    double dsum = 0.0, dmin = ts_.dmin, dmax = ts_.dmax;
    const std::size_t per = std::size_t(sh_.rays_per_sample);
    std::uint32_t last_hit = raycast::no_hit;
    for (std::size_t r = 0; r < sample_count; ++r) {
      double dist = 0.0;
      const std::size_t h = chosen_hit(hits_, r * per, signed_base_.data(), sh_.setup.closest, &dist);
      if (maps_) sample_dist_[r] = dist;
      if (per != 1) {
        chosen_[r] = std::uint32_t(h);
        chosen_tri_[r] = hits_.triangle[h];
        chosen_u_[r] = hits_.u[h];
        chosen_v_[r] = hits_.v[h];
      }
      const std::size_t tri = std::size_t(sample_tri_[r]);
      if (sh_.per_object) {
        const std::uint32_t lo = sh_.s.low_object ? sh_.s.low_object[tri] : 0u;
        ++ts_.low_samples[lo];
        if (hits_.triangle[h] != raycast::no_hit) {
          ++ts_.low_hits[lo];
          ++ts_.high_hits[sh_.scene.object ? sh_.scene.object[hits_.triangle[h]] : 0u];
        }
      }
      if (sh_.groups.active() && sh_.groups.low[tri] == kNoMatch) {
        ++unmatched;
        continue;
      }
      if (hits_.triangle[h] != raycast::no_hit) {
        if (sh_.hit_rule) ts_.facing_away += (hits_.flags[h] & raycast::hit_normal_disagrees) != 0;
        // The hit triangles' corner normals are scattered over the high-poly: ask for them all
        // before shading needs the first, so the cache misses overlap (once for a run of samples
        // on one triangle: a texel's samples mostly hit the same few).
        if (hits_.triangle[h] != last_hit) {
          last_hit = hits_.triangle[h];
          const char* line = reinterpret_cast<const char*>(&sh_.scene.normals[3 * std::size_t(last_hit)]);
          __builtin_prefetch(line);
          __builtin_prefetch(line + sizeof(glm::vec3) * 3 - 1);
        }
        ++tile_hits;
        dmin = std::min(dmin, dist);
        dmax = std::max(dmax, dist);
        dsum += dist;
      } else {
        ++miss_count_[sample_texel_[r]];
      }
    }
    ts_.covered += sample_count;
    ts_.hits += tile_hits;
    ts_.misses += sample_count - tile_hits - unmatched;
    ts_.unmatched += unmatched;
    ts_.dmin = dmin;
    ts_.dmax = dmax;
    return dsum;
  }

  // The high-poly normal at each hit in the low-poly's frame at P: the common case (tangent space,
  // per-pixel bitangent) for all samples at once, then one at a time the misses and the cases the
  // batch leaves out; each sample's value summed into its texel.
  void shade(std::size_t sample_count) {
    const bool one_ray = sh_.rays_per_sample == 1;
    std::fill(acc_.begin(), acc_.end(), 0.0);
    if (sh_.batched && sample_count) {
      const ShadeSamples in{sample_tri_.data(),
                            {sb_[0], sb_[1], sb_[2]},
                            one_ray ? hits_.triangle : chosen_tri_.data(),
                            one_ray ? hits_.u : chosen_u_.data(),
                            one_ray ? hits_.v : chosen_v_.data()};
      encode_hits_per_pixel(sh_.s.low_tris.data(), sh_.scene.normals, in, sample_count, value_c_, one_at_a_time_.data());
    }
    for (std::size_t r = 0; r < sample_count; ++r) {
      if (!one_at_a_time_[r]) continue;
      const double b[3] = {sb_[0][r], sb_[1][r], sb_[2][r]};
      const glm::dvec3 v =
          shade_sample(sh_.s, sh_.scene, std::size_t(sample_tri_[r]), b, rays_.hit(one_ray ? r : chosen_[r]), sh_.opt);
      for (int c = 0; c < 3; ++c) value_c_[c][r] = v[c];
    }
    accumulate_samples(value_c_, sample_texel_.data(), sample_count, sums_);
  }

  // Texels: renormalized mean of their covered samples; with several samples, whether they
  // disagree; the miss mask.
  void write_texels(const TileRect& rect) {
    const int W = sh_.opt.width, tx0 = rect.x0, ty0 = rect.y0, tw = rect.w, th = rect.h;
    const TraceTargets& out = sh_.out;
    if (!out.disagree.empty())
      for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x) {
          const std::size_t i = std::size_t(y) * std::size_t(side_) + std::size_t(x);
          const double n = sums_.count[i];
          const double len2 =
              sums_.sum[0][i] * sums_.sum[0][i] + sums_.sum[1][i] * sums_.sum[1][i] + sums_.sum[2][i] * sums_.sum[2][i];
          if (n > 1.0 && len2 < kSuspectAgreement * kSuspectAgreement * n * n)
            out.disagree[std::size_t(ty0 + y) * std::size_t(W) + std::size_t(tx0 + x)] = 1;
        }
    const bool flip_y = sh_.opt.space == NormalSpace::tangent && sh_.opt.green_down;
    if (maps_) maps_->write(*out.maps, tx0, ty0, tw, th, side_, W);
    for (int y = 0; y < th; ++y) {
      const std::size_t first = std::size_t(y) * std::size_t(side_),
                        gi = std::size_t(ty0 + y) * std::size_t(W) + std::size_t(tx0);
      write_texel_row(sums_, first, tw, flip_y, kSnap, out.map.at(tx0, ty0 + y), &out.coverage[gi]);
      if (sh_.opt.miss_mask)
        for (int x = 0; x < tw; ++x)
          if (sums_.count[first + std::size_t(x)] > 0.0)
            out.miss_mask.pixels[gi + std::size_t(x)] =
                float(miss_count_[first + std::size_t(x)]) / float(sums_.count[first + std::size_t(x)]);
    }
  }

  Shared& sh_;
  ThreadStats& ts_;
  const int side_;
  const std::size_t tile_texels_, slot_count_;
  const bool kernel_rays_;  // cover_rect makes the rays (the cage-first policy)
  raycast::RayArrays rays_;
  const raycast::HitBatch hits_;
  raycast::RayBatch batch_;
  std::vector<std::uint8_t> outward_;
  std::vector<float> prefer_lo_, prefer_hi_;
  std::vector<std::uint32_t> ray_group_;                  // with --match: per ray
  std::vector<std::pair<std::size_t, float>> unmatched_;  // rays cast empty, and their tnear
  std::vector<std::int32_t> sample_tri_;
  std::vector<double> sample_b_;
  double* sb_[3];
  std::vector<std::uint16_t> sample_texel_;
  std::vector<std::uint8_t> sample_fallback_;  // per covered sample: its ray is made one at a time
  std::vector<double> signed_base_;            // per ray: distance from P to its origin along it
  // The hit that counts, per covered sample: with one ray per sample its own, read in place; with
  // two (closest), picked into these.
  std::vector<std::uint32_t> chosen_, chosen_tri_;
  std::vector<float> chosen_u_, chosen_v_;
  std::vector<double> value_;
  double* value_c_[3];
  std::vector<std::uint8_t> one_at_a_time_;  // per covered sample: shaded by shade_sample
  std::vector<double> acc_;                  // per texel of the tile: x, y, z sums and covered samples, as arrays
  TexelSums sums_;
  std::vector<std::uint32_t> miss_count_;
  std::vector<std::uint8_t> refine_;       // adaptive: per texel of the tile, baked again by the next level's pass
  std::vector<std::pair<int, int>> span_;  // adaptive: per row of the tile, its marked texels' span (marked_rows)
  std::size_t last_sample_count_ = 0;      // covered samples of the last cover_tile
  std::vector<double> first_acc_;          // adaptive: the sums so far while a refining pass runs
  std::vector<std::uint32_t> first_miss_;
  std::vector<double> offset_x_, offset_y_;  // cover_tile: the pass's sample offsets
  std::unique_ptr<TexelMaps> maps_;          // the extra maps, or null
  std::vector<double> sample_dist_;          // with maps_: per covered sample, count_hits' signed distance
  int pass_level_ = 0;                       // the pass under way: 0 the first, then the refining levels
};

// The trace's hit rule (trace_rule), its match groups and whether it looks at preferred parts;
// `rule` holds it.
void set_rule(Shared& sh, const BakeStats& st, raycast::HitRule& rule) {
  sh.groups = ray_groups(sh.s, sh.scene, sh.opt);
  sh.hit_rule = trace_rule(sh.scene, st.distances.backfaces_skipped, sh.groups, rule);
  sh.prefer = st.distances.backfaces_skipped;
}

}  // namespace

std::vector<glm::dvec3> trace_texels(const Prepared& s, const HighScene& scene, const TileBins& bins, const RaySetup& rays,
                                     const BakeOptions& opt, int threads, const BakeStats& st,
                                     const std::vector<std::uint32_t>& texels) {
  const std::uint32_t w = std::uint32_t(opt.width);
  const auto tile_of = [&](std::size_t i) { return bins.tile_of(int(texels[i] % w), int(texels[i] / w)); };
  std::vector<std::size_t> order(texels.size()), first;  // the texels tile by tile, and where each tile's begin
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return tile_of(a) < tile_of(b); });
  for (std::size_t i = 0; i <= order.size(); ++i)
    if (i == 0 || i == order.size() || tile_of(order[i]) != tile_of(order[i - 1])) first.push_back(i);
  std::vector<glm::dvec3> out(texels.size(), glm::dvec3(0.0));
  Image map;
  std::vector<std::uint8_t> coverage, disagree;
  const TraceTargets none{map, coverage, map, disagree};
  Shared sh(s, scene, bins, rays, opt, none, threads);
  raycast::HitRule rule;
  set_rule(sh, st, rule);
  run_workers(
      std::min(threads, int(first.size() - 1)), [&](int i) { TileTracer(sh, i).run_texels(texels, order, first, out); },
      sh.cancel, nullptr, [] { return 1.0; });
  return out;
}

void trace_and_shade(const Prepared& s, const HighScene& scene, const TileBins& bins, const RaySetup& rays,
                     const BakeOptions& opt, int threads, const TraceTargets& out, BakeStats& st) {
  Shared sh(s, scene, bins, rays, opt, out, threads);
  raycast::HitRule rule;
  set_rule(sh, st, rule);
  if (out.map_inputs) {
    out.map_inputs->groups = &sh.groups;
    sh.maps = out.map_inputs;
  }
  sh.tile_dsum.assign(bins.count(), 0.0);
  // Tiles are taken from a shared counter, so the tracers that start cover them all.
  run_workers(
      threads, [&sh](int i) { TileTracer(sh, i).run(); }, sh.cancel, sh.opt.progress,
      [&sh] { return double(sh.tiles_done.load()) / double(sh.bins.count()); });

  sum_thread_stats(sh.stats, sh.per_object, s.low_objects, s.high_objects, sh.tile_dsum, st);
  st.trace.texels_total = std::size_t(opt.width) * std::size_t(opt.height);
  for (std::uint8_t c : out.coverage) st.trace.texels_covered += c;
  st.trace.coverage = double(st.trace.texels_covered) / double(st.trace.texels_total);
}

}  // namespace nmbake
