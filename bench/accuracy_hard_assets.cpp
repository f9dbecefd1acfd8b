#include "accuracy_hard_assets.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "bench_support.h"
#include "pipeline/bake.h"
#include "core/errors.h"
#include "hard_asset_answers.h"
#include "hard_assets.h"

namespace nmbake::bench {

namespace {

// The low-poly with every position moved `push` along its ray normal: a uniformly inflated cage.
Mesh push_cage(const Mesh& low, double push) {
  const std::vector<glm::vec3> ray_n = low_ray_normals(low);
  Mesh cage;
  cage.source = low.source + " (pushed cage)";
  cage.position_index = low.position_index;
  cage.positions.resize(low.positions.size());
  for (std::size_t i = 0; i < low.positions.size(); ++i)
    cage.positions[i] = glm::vec3(glm::dvec3(low.positions[i]) + push * glm::dvec3(ray_n[i]));
  return cage;
}

}  // namespace

std::vector<HardAssetRow> run_hard_assets(const std::vector<int>& sizes, std::vector<std::string>& notes) {
  auto t0 = Clock::now();
  const std::vector<procedural::HardAsset> assets = procedural::hard_asset_set();
  std::fprintf(stderr, "nmbake_accuracy: hard_assets: %zu cases made in %.1f s\n", assets.size(), since(t0));
  std::vector<HardAssetRow> rows;
  for (const procedural::HardAsset& a : assets) {
    notes.push_back("`" + a.name + "`: " + std::to_string(a.high.triangle_count()) + " high-poly triangles over " +
                    std::to_string(a.low.triangle_count()) + " low-poly");
    for (int size : sizes) {
      t0 = Clock::now();
      const std::vector<procedural::KnownTexel> known = procedural::known_texels(a, size);
      std::fprintf(stderr, "  %s at %d^2: known answers for %zu texels in %.2f s\n", a.name.c_str(), size, known.size(),
                   since(t0));
      auto run = [&](const std::string& setting, const BakeOptions& o, const Mesh* cage, double push = 0.0) {
        t0 = Clock::now();
        BakeResult r = bake_normal_map(a.low, a.high, cage, o);
        const double seconds = since(t0);
        const procedural::KnownErrors e = procedural::measure_against_known(a, known, r);
        HardAssetRow row;
        row.asset = a.name;
        row.setting = setting;
        row.size = size;
        row.texels = e.texels;
        row.facing_away =
            r.stats.trace.texels_covered ? double(r.stats.pad.texels_facing_away) / double(r.stats.trace.texels_covered) : 0.0;
        row.mean_deg = e.mean_deg;
        row.over1 = e.over1;
        row.over60 = e.over60;
        row.worst_deg = e.worst_deg;
        row.misses = r.stats.trace.misses;
        row.backface_skips = r.stats.trace.backface_skips;
        row.front = cage ? push : r.stats.distances.front;  // BakeStats::Distances::front is 0 with a cage
        row.rear = r.stats.distances.rear;
        row.seconds = seconds;
        rows.push_back(row);
        std::fprintf(
            stderr,
            "  %-32s %4d %-8s facing away %6.3f%%  mean %8.4f deg  >1deg %7.3f%%  >60deg %7.3f%%  worst %6.2f  misses %6llu  "
            "front %.4g rear %.4g  %.2f s\n",
            a.name.c_str(), size, setting.c_str(), 100 * row.facing_away, row.mean_deg, 100 * row.over1, 100 * row.over60,
            row.worst_deg, (unsigned long long)row.misses, row.front, row.rear, row.seconds);
        return r;
      };
      BakeOptions o;
      o.width = o.height = size;
      const BakeResult default_bake = run("default", o, nullptr);
      const BakeStats& def = default_bake.stats;

      BakeOptions closest = o;
      closest.policy = RayPolicy::closest;
      run("closest", closest, nullptr);

      const double push = 1.25 * def.distances.vertex_front.max;
      const Mesh cage = push_cage(a.low, push);
      run("cage", o, &cage, push);

      // The old rule's distances: measured globally with back faces kept (probes do not depend on
      // the map size, so a small map measures them).
      BakeOptions measure_old = o;
      measure_old.width = measure_old.height = 64;
      measure_old.padding = 0;
      measure_old.keep_backfaces = true;
      measure_old.rear = float(def.distances.vertex_rear.max);
      const BakeStats old_distances = bake_normal_map(a.low, a.high, nullptr, measure_old).stats;
      BakeOptions old = o;
      old.keep_backfaces = true;
      old.front = old_distances.distances.front;
      old.rear = old_distances.distances.rear;
      run("old-rule", old, nullptr);
    }
  }
  return rows;
}

void write_hard_assets_csv(const std::string& path, const std::vector<HardAssetRow>& rows) {
  std::ofstream f(path);
  f << "case,size,setting,texels,facing_away_share,mean_deg,share_over_1deg,share_over_60deg,worst_deg,misses,backface_skips,"
       "front,rear,seconds\n";
  for (const HardAssetRow& r : rows)
    f << r.asset << ',' << r.size << ',' << r.setting << ',' << r.texels << ',' << fmt("%.6f", r.facing_away) << ','
      << fmt("%.6f", r.mean_deg) << ',' << fmt("%.6f", r.over1) << ',' << fmt("%.6f", r.over60) << ',' << fmt("%.4f", r.worst_deg)
      << ',' << r.misses << ',' << r.backface_skips << ',' << fmt("%.6g", r.front) << ',' << fmt("%.6g", r.rear) << ','
      << fmt("%.4f", r.seconds) << '\n';
  if (!f) throw OutputError(path + ": cannot write");
}

std::string hard_assets_markdown(const std::vector<HardAssetRow>& rows, const std::vector<std::string>& notes, double seconds) {
  std::string s = "## Hard assets: known answers (tests/procedural/hard_assets.h)\n\n";
  s += "Each case of `procedural::hard_asset_set()` baked with 1 sample per texel, the float map decoded with the low-poly "
       "frame at every covered texel centre and compared with the exact normal of the analytic surface of that texel's "
       "low-poly part where the line along the bake's own ray normal (`low_ray_normals`) crosses it "
       "(tests/procedural/hard_asset_answers.h, as tests/test_robust_hits.cpp measures; when that crossing faces against "
       "the ray, the one found from the far side). Settings: `default` (automatic cage, back "
       "faces passed over); `closest` (`--policy closest`, otherwise default); `cage` (a cage given: the low-poly with "
       "every vertex pushed along its ray normal by 1.25 x the default bake's largest per-vertex front distance, one "
       "distance for the whole model, as an artist's inflated cage; rear measured per vertex); `old-rule` (back faces "
       "kept, first hit, front and rear pinned to the scene-wide distances measured with back faces kept and the rear "
       "given as the default bake's largest per-vertex rear: the baker before the automatic cage and the back-face "
       "filter). Facing away: covered texels whose normal points into the low-poly (`texels_facing_away` / "
       "`texels_covered`). Front, rear: the largest distances the bake used (`BakeStats::Distances::front`, `rear`); for `cage` "
       "the push. "
       "Seconds: `bake_normal_map` in-process; for `cage` and `old-rule` without the bakes that "
       "measured their distances. The section took " +
       fmt("%.0f", seconds) + " s.\n\n";
  for (const std::string& n : notes) s += "- " + n + "\n";
  s += "\n| case | size | setting | facing away | mean deg | > 1 deg | > 60 deg | worst deg | misses | front | rear | seconds |\n"
       "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const HardAssetRow& r : rows)
    s += "| " + r.asset + " | " + std::to_string(r.size) + " | " + r.setting + " | " + fmt("%.3f%%", 100 * r.facing_away) +
         " | " + fmt("%.4f", r.mean_deg) + " | " + fmt("%.3f%%", 100 * r.over1) + " | " + fmt("%.3f%%", 100 * r.over60) + " | " +
         fmt("%.2f", r.worst_deg) + " | " + std::to_string(r.misses) + " | " + fmt("%.4g", r.front) + " | " +
         fmt("%.4g", r.rear) + " | " + fmt("%.3f", r.seconds) + " |\n";
  return s;
}

}  // namespace nmbake::bench
