#include "accuracy_ao.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <thread>

#include "accuracy_plot.h"
#include "core/errors.h"
#include "pipeline/bake.h"

namespace nmbake::bench {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string AoRow::label() const {
  return automatic ? "auto " + fmt("%g", max_ao_error) : std::to_string(rays) + (independent ? " random" : "");
}

namespace {

const BakedMap& ao_of(const BakeResult& r) {
  for (const BakedMap& m : r.maps)
    if (m.kind == MapKind::ao) return m;
  throw Error(ExitCode::usage, "no AO map in the bake");
}

// The row of a bake against the reference AO, over the covered texels.
void measure_ao(const BakeResult& r, const BakeResult& ref, double ref_rms_se, AoRow& row) {
  const BakedMap& m = ao_of(r);
  const Image& a = m.image;
  const Image& b = ao_of(ref).image;
  std::vector<double> err;
  double sq = 0.0, se = 0.0, se_sq = 0.0;
  for (std::size_t i = 0; i < r.coverage.size(); ++i) {
    if (!r.coverage[i]) continue;
    const double d = std::fabs(double(a.pixels[i]) - double(b.pixels[i]));
    err.push_back(d);
    sq += d * d;
    se += double(m.error.pixels[i]);
    se_sq += double(m.error.pixels[i]) * double(m.error.pixels[i]);
  }
  if (err.empty()) return;
  const double n = double(err.size());
  row.rms = std::sqrt(sq / n);
  row.mean_se = se / n;
  row.rms_se = std::sqrt(se_sq / n);
  row.noise_ratio = row.rms_se > 0.0 ? std::sqrt(std::max(0.0, sq / n - ref_rms_se * ref_rms_se)) / row.rms_se : 0.0;
  const std::size_t k = std::min(err.size() - 1, std::size_t(std::ceil(0.95 * n)) - 1);
  std::nth_element(err.begin(), err.begin() + std::ptrdiff_t(k), err.end());
  row.p95 = err[k];
}

BakeOptions ao_options(const AccuracyScene& sc, int size, int threads) {
  BakeOptions o;
  o.width = o.height = size;
  o.front = sc.front;
  o.rear = sc.rear;
  o.samples = 1;
  o.padding = 0;
  o.threads = threads;
  o.maps.maps = {MapKind::ao};
  return o;
}

std::string csv_line(const AoRow& r) {
  return r.scene + "," + std::to_string(r.size) + "," + (r.automatic ? "auto" : std::to_string(r.rays)) + "," +
         (r.independent ? "random" : "stratified") + "," + (r.automatic ? fmt("%g", r.max_ao_error) : "") + "," +
         fmt("%.1f", r.rays_mean) + "," + fmt("%.0f", r.rays_max) + "," + fmt("%.3f", r.seconds) + "," +
         fmt("%.3f", r.cpu_seconds) + "," + fmt("%.3f", r.trace_seconds) + "," + fmt("%.5f", r.rms) + "," + fmt("%.5f", r.p95) +
         "," + fmt("%.5f", r.mean_se) + "," + fmt("%.5f", r.rms_se) + "," + fmt("%.3f", r.noise_ratio) + "\n";
}

// The fixed 256-ray row (independent random rays or stratified) of the scene and size of `r`, or null.
const AoRow* fixed256(const std::vector<AoRow>& rows, const AoRow& r, bool independent) {
  for (const AoRow& f : rows)
    if (!f.automatic && f.independent == independent && f.rays == 256 && f.scene == r.scene && f.size == r.size) return &f;
  return nullptr;
}

}  // namespace

void run_ao_rows(const AccuracyScene& sc, int size, const std::vector<double>& max_errors, int threads, AoResults& out) {
  BakeOptions ro = ao_options(sc, size, threads);
  ro.maps.ao_rays = kAoReferenceRays;
  ro.maps.ray_seed = 1;  // rays independent of the rows' (which share their first rays with each other)
  const auto t0 = Clock::now();
  const BakeResult ref = bake_normal_map(sc.low, sc.high, nullptr, ro);
  const double ref_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  AoRow ref_row;
  measure_ao(ref, ref, 0.0, ref_row);
  std::fprintf(stderr, "  %-10s %4d  reference %d rays: %.1f s, mean standard error %.5f\n", sc.name.c_str(), size,
               kAoReferenceRays, ref_seconds, ref_row.mean_se);
  out.notes.push_back("`" + sc.name + "` at " + std::to_string(size) + "^2: " + sc.description + "; reference " +
                      std::to_string(kAoReferenceRays) + " rays per texel (other random streams) in " + fmt("%.1f", ref_seconds) +
                      " s, its own mean standard error " + fmt("%.5f", ref_row.mean_se) + ".");
  std::vector<AoRow> settings;
  for (int rays = 8; rays <= 1024; rays *= 2) {
    AoRow r;
    r.rays = rays;
    settings.push_back(r);
  }
  for (int rays : {64, 256}) {
    AoRow r;
    r.rays = rays;
    r.independent = true;
    settings.push_back(r);
  }
  for (double e : max_errors) {
    AoRow r;
    r.automatic = true;
    r.max_ao_error = e;
    settings.push_back(r);
  }
  for (AoRow row : settings) {
    BakeOptions o = ao_options(sc, size, threads);
    o.maps.ao_rays = row.automatic ? kDefaultAoRays : row.rays;
    o.maps.ao_rays_auto = row.automatic;
    o.maps.ao_independent_rays = row.independent;
    if (row.automatic) o.maps.max_ao_error = row.max_ao_error;
    const auto w0 = Clock::now();
    const std::clock_t c0 = std::clock();
    const BakeResult r = bake_normal_map(sc.low, sc.high, nullptr, o);
    row.cpu_seconds = double(std::clock() - c0) / CLOCKS_PER_SEC;
    row.seconds = std::chrono::duration<double>(Clock::now() - w0).count();
    row.trace_seconds = r.stats.trace.seconds;
    row.scene = sc.name;
    row.size = size;
    const BakedMap& m = ao_of(r);
    if (row.automatic) row.rays_mean = m.rays_mean, row.rays_max = m.rays_max;
    else row.rays_mean = row.rays_max = row.rays;
    measure_ao(r, ref, ref_row.rms_se, row);
    std::fprintf(stderr,
                 "  %-10s %4d  %-10s rays %7.1f (max %4.0f)  %.2f s (cpu %.2f, trace %.2f)  rms %.5f  p95 %.5f  se %.5f (rms "
                 "%.5f, noise ratio %.3f)\n",
                 row.scene.c_str(), size, row.label().c_str(), row.rays_mean, row.rays_max, row.seconds, row.cpu_seconds,
                 row.trace_seconds, row.rms, row.p95, row.mean_se, row.rms_se, row.noise_ratio);
    out.rows.push_back(row);
  }
  for (const AoRow& r : out.rows)
    for (bool independent : {true, false}) {
      const AoRow* f = fixed256(out.rows, r, independent);
      if (!r.automatic || r.scene != sc.name || r.size != size || !f) continue;
      std::fprintf(stderr,
                   "  %-10s %4d  %s against %s: rays %.3f, cpu time %.3f, wall time %.3f, rms error %.3f, p95 error %.3f\n",
                   r.scene.c_str(), size, r.label().c_str(), f->label().c_str(), r.rays_mean / f->rays_mean,
                   r.cpu_seconds / f->cpu_seconds, r.seconds / f->seconds, r.rms / f->rms, r.p95 / f->p95);
    }
}

void write_ao_files(const std::string& out, const AoResults& res, const RunInfo& info, const std::string& font) {
  const std::string csv = (fs::path(out) / "ao.csv").string(), md = (fs::path(out) / "ao.md").string();
  {
    std::ofstream f(csv);
    f << "scene,size,rays,directions,max_ao_error,rays_mean,rays_max,seconds,cpu_seconds,trace_seconds,rms_error,p95_error,"
         "mean_standard_error,rms_standard_error,noise_ratio\n";
    for (const AoRow& r : res.rows) f << csv_line(r);
    if (!f) throw OutputError(csv + ": cannot write");
  }
  {
    std::ofstream f(md);
    f << "# AO error against rays\n\n"
      << "`" << info.command << "`, " << info.date << ", commit " << info.commit << ", " << std::thread::hardware_concurrency()
      << " cores (" << cpu_model() << "), load at start " << info.load_at_start << ", " << fmt("%.0f", info.seconds)
      << " s in all.\n\n"
      << "Each bake: 1 sample per texel, the AO map alone, errors |AO - reference| over the covered texels against a "
      << kAoReferenceRays << "-ray reference per texel (its own noise is in every row's error, in quadrature); time is the "
      << "bake's CPU time (all threads; wall and the trace stage's in ao.csv). `N` is `--ao-rays N` (each texel's rays in "
      << "4 chains of Owen-scrambled Sobol directions), `N random` the same count of independent random rays (the release "
      << "before, the issue's baseline), `auto E` is `--ao-rays auto --max-ao-error E`. Noise ratio: the measured noise "
      << "(RMS error, less the reference's own RMS standard error in quadrature) over the RMS standard error the bake "
      << "reports.\n\n";
    for (const std::string& n : res.notes) f << "- " << n << "\n";
    f << "\n| scene | size | rays | rays/texel (mean, max) | cpu s | wall s | RMS error | p95 error | mean reported SE | "
         "noise ratio |\n"
      << "|---|---|---|---|---|---|---|---|---|---|\n";
    for (const AoRow& r : res.rows)
      f << "| " << r.scene << " | " << r.size << " | " << r.label() << " | " << fmt("%.1f", r.rays_mean) << ", "
        << fmt("%.0f", r.rays_max) << " | " << fmt("%.2f", r.cpu_seconds) << " | " << fmt("%.2f", r.seconds) << " | "
        << fmt("%.5f", r.rms) << " | " << fmt("%.5f", r.p95) << " | " << fmt("%.5f", r.mean_se) << " | "
        << fmt("%.3f", r.noise_ratio) << " |\n";
    f << "\n## Auto against a fixed 256-ray bake\n\n"
      << "The rays ratio does not depend on the machine's load; the time ratios do (on a shared machine, by tens of "
      << "percent between runs).\n\n"
      << "| scene | size | auto | against | rays ratio | cpu time ratio | wall time ratio | RMS error ratio | p95 error ratio |\n"
      << "|---|---|---|---|---|---|---|---|---|\n";
    for (bool independent : {true, false})
      for (const AoRow& r : res.rows) {
        const AoRow* fx = fixed256(res.rows, r, independent);
        if (!r.automatic || !fx) continue;
        f << "| " << r.scene << " | " << r.size << " | " << r.label() << " | " << fx->label() << " | "
          << fmt("%.3f", r.rays_mean / fx->rays_mean) << " | " << fmt("%.3f", r.cpu_seconds / fx->cpu_seconds) << " | "
          << fmt("%.3f", r.seconds / fx->seconds) << " | " << fmt("%.3f", r.rms / fx->rms) << " | "
          << fmt("%.3f", r.p95 / fx->p95) << " |\n";
      }
    if (!f) throw OutputError(md + ": cannot write");
  }
  // RMS error against CPU seconds: per scene one polyline of the fixed counts and one of auto's thresholds.
  std::vector<PlotSeries> series;
  for (const AoRow& r : res.rows) {
    const std::string name = r.scene + (r.automatic ? " auto (E)" : r.independent ? " random (rays)" : " fixed (rays)");
    auto it = std::find_if(series.begin(), series.end(), [&](const PlotSeries& s) { return s.name == name; });
    if (it == series.end()) {
      series.push_back({name, {{}}, r.automatic});
      it = series.end() - 1;
    }
    it->lines[0].push_back(
        {std::max(r.cpu_seconds, 1e-3), std::max(r.rms, 1e-6), r.automatic ? fmt("%g", r.max_ao_error) : std::to_string(r.rays)});
  }
  for (PlotSeries& s : series)
    std::sort(s.lines[0].begin(), s.lines[0].end(), [](const PlotPoint& a, const PlotPoint& b) { return a.x < b.x; });
  write_log_log_plot((fs::path(out) / "ao.png").string(), "nmbake: AO RMS error against bake time, fixed rays and --ao-rays auto",
                     "bake CPU seconds (log)", "RMS error of AO against " + std::to_string(kAoReferenceRays) + " rays (log)",
                     series, {}, info.date + ", commit " + info.commit + ", " + cpu_model(), font);
}

}  // namespace nmbake::bench
