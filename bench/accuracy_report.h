// The accuracy bench's results and what it writes from them: accuracy.csv, accuracy.md (or
// hard_assets.md when only the hard assets ran), accuracy.png, and the --check verdict; with the
// machine, date and commit the files name.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "accuracy_error.h"
#include "accuracy_hard_assets.h"
#include "bench_support.h"

namespace nmbake::bench {

// One bake of one scene at one size and sample count, measured at one bit depth.
struct AccuracyRow {
  std::string scene, reference;
  int size = 0, samples = 0, bits = 32;  // bits: 32 = the float map, else rounded as an 8/16-bit writer does
  ErrorStats err;
  std::uint64_t rays = 0, misses = 0;
  double prepare = 0, bvh = 0, distances = 0, trace = 0, padding = 0, total = 0;  // seconds (BakeStats, total: wall)
  double reference_seconds = 0;                                                   // building the reference (not part of the bake)
  double appearance = -1;                                                         // nmview RMSE, < 0: not measured
  // --samples auto (samples is then the refined count): its --max-error and the share of covered
  // texels refined.
  bool adaptive = false;
  double max_error = 0, deep_factor = 0, refined = 0, deep = 0;  // refined: at `samples` or more; deep: at 4x
  // "16", or for adaptive "auto 1deg (12.3% at 16)".
  std::string sampling() const;
};

// Everything a run measured.
struct AccuracyResults {
  std::vector<AccuracyRow> rows;
  std::vector<std::string> notes;                 // one line per scene (description, reference)
  std::map<std::string, double> floor8, floor16;  // per analytic scene: quantisation floor, degrees, mean over its sizes
  double appearance_seconds = 0;                  // in nmview runs
  std::vector<HardAssetRow> hard_rows;
  std::vector<std::string> hard_notes;
  double hard_seconds = 0;
};

// What the written files say about the run itself.
struct RunInfo {
  std::string command;        // the command line as given
  std::string date, commit;   // utc_now(), git_commit()
  std::string load_at_start;  // load_average() when the run began
  double seconds = 0;         // the whole run, wall
  bool nmview = false;        // appearance figures were measured
};

// `s` quoted for the shell. fmt, command_output and load_average: bench_support.h.
std::string shell_quote(const std::string& s);

std::string cpu_model();   // /proc/cpuinfo's model name, or "unknown"
std::string git_commit();  // git describe of the source tree, or "unknown (not a git checkout)"
std::string utc_now();     // "YYYY-MM-DD HH:MM UTC"

// `out`/accuracy.csv (when there are rows), `out`/hard_assets.csv (when the hard assets ran),
// `out`/accuracy.md or hard_assets.md, and `out`/accuracy.png drawn with the TTF `font`. Returns the
// Markdown file's name. Throws OutputError when a file cannot be written.
std::string write_accuracy_files(const std::string& out, const AccuracyResults& results, const RunInfo& info,
                                 const std::string& font);

// --check: true when every analytic scene's float error at the last setting is below a quarter of
// the first's (and above zero); prints the verdict to stderr.
bool check_error_falls(const std::vector<AccuracyRow>& rows);

}  // namespace nmbake::bench
