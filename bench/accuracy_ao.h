// The accuracy bench's AO rows (issue 35): the AO map's error against the rays it casts, on the
// sculpts. Per scene, a 4096-ray reference AO per texel (rays independent of the rows',
// MapOptions::ray_seed), then fixed 8, 16, ..., 1024 rays per texel, fixed 64 and 256 independent
// random rays (MapOptions::ao_independent_rays: the release before stratified chains, the issue's
// baseline) and --ao-rays auto at each --max-ao-error given, every bake with the same primary hits
// (1 sample per texel, no padding). Measured over the covered texels: RMS and 95th percentile of
// |AO - reference|, the standard error the bake reports (mean, RMS, and the measured noise over it),
// the rays per texel it spent, and its time. Writes ao.csv, ao.md, ao.png.
#pragma once

#include <string>
#include <vector>

#include "accuracy_report.h"
#include "accuracy_scenes.h"

namespace nmbake::bench {

constexpr int kAoReferenceRays = 4096;

struct AoRow {
  std::string scene;
  int size = 0;
  bool automatic = false;                  // --ao-rays auto (then max_ao_error), else `rays` fixed
  bool independent = false;                // fixed `rays` as the release before stratified chains: independent random rays
  int rays = 0;                            // fixed rays per texel
  double max_ao_error = 0.0;               // auto's threshold
  double rays_mean = 0.0, rays_max = 0.0;  // rays per covered texel spent
  double seconds = 0.0;                    // the bake, wall
  double cpu_seconds = 0.0;                // the bake, CPU time of the process (every thread)
  double trace_seconds = 0.0;              // the bake's trace stage (primary rays and the AO's), wall
  double rms = 0.0, p95 = 0.0;             // |AO - reference| over the covered texels
  double mean_se = 0.0;                    // the standard error the bake reports, mean over the covered texels
  double rms_se = 0.0;                     // its root mean square
  // The measured noise over the reported: sqrt(rms^2 - the reference's own rms_se^2) / rms_se.
  double noise_ratio = 0.0;
  std::string label() const;  // "256", "256 random" or "auto 0.02"
};

struct AoResults {
  std::vector<AoRow> rows;
  std::vector<std::string> notes;  // per scene: what it is, the reference's time and own standard error
};

// The rows of one scene at `size` texels a side with `threads` threads: fixed 8 to 1024 rays and
// auto at each of `max_errors`. Progress on stderr.
void run_ao_rows(const AccuracyScene& sc, int size, const std::vector<double>& max_errors, int threads, AoResults& out);

// `out`/ao.csv, ao.md (the table, and per scene auto against fixed 256, random and stratified: time and error ratios)
// and ao.png (RMS error against CPU seconds, log-log). Throws OutputError when a file cannot be written.
void write_ao_files(const std::string& out, const AoResults& results, const RunInfo& info, const std::string& font);

}  // namespace nmbake::bench
