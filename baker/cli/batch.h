// nmbake --batch jobs.json: many bakes in one process (README "Batch" gives the file format).
//
// The file is a JSON object: "defaults" (options every job shares) and "jobs", an array of
// objects each with "low", "highs" (an array, or "high": one file), "output" and "options". Options
// are nmbake's long options without their dashes ("size": 2048, "samples": 4, "match": "names",
// "keep-backfaces": true); a job's own override the defaults. Relative paths are relative to the
// jobs file's folder.
//
// Every job is checked before the first bake: a malformed file, an unknown option, or two jobs
// writing one output stop the batch with nothing written. Then the jobs run in order, each as
// `nmbake LOW HIGH... -o OUTPUT --OPTION VALUE...` would; a high-poly several jobs share is loaded
// once. A job that fails is reported (one line) and the others still run; the exit code is then
// that of the first failure.
//
// On a farm, --shard I/N bakes only part I of N of the jobs (shard.h gives the split) and its report
// says which; --merge-reports merges the parts' reports into the one a single process writes.
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/args.h"
#include "cli/shard.h"

namespace nmbake {

// One job of a batch: its place in the file and the command line it stands for.
struct BatchJob {
  std::size_t index = 0;          // from 1, as messages number them
  std::vector<std::string> argv;  // "nmbake", LOW, HIGH..., -o, OUTPUT, options
};

// The jobs of a batch file's text (`path` names it in messages and resolves relative paths).
// `shared` are options the batch's own command line gives every job (--threads, --quiet, ...),
// added where a job does not set them. Throws InputError for a malformed file, UsageError for a
// job that is not a command nmbake takes.
std::vector<BatchJob> parse_batch(const std::string& path, const std::string& text, const nlohmann::json& shared);

// What the batch's own command line sets: the jobs file, the part of it to bake (--shard, shard.h),
// the batch report, and the options given to every job; or the parts' reports to merge
// (--merge-reports) and the whole report's file.
struct BatchArgs {
  std::string file, report;
  ShardSpec shard;  // count 0: every job
  int threads = 0, quiet = 0;
  bool progress = false, strict = false, no_warnings = false;
  std::vector<std::string> merge;  // --merge-reports: the parts' reports (then no --batch)
  std::string merged;              // -o: the whole report
};

// Whether argv asks for a batch or its parts (--batch, --shard or --merge-reports; also --OPTION=VALUE).
bool wants_batch(int argc, char** argv);

// Parses the batch's command line: --batch FILE [--shard I/N] [--report FILE] [--threads N] [--quiet]
// [--progress] [--strict] [--no-warnings], or --merge-reports PART... -o FILE [--quiet]. Returns -1 to
// go on, or the exit code of --help. Throws UsageError for --shard without --batch, a wrong --shard,
// or options of the two forms mixed.
int parse_batch_args(int argc, char** argv, BatchArgs& b);

// Runs the batch (with --shard, the jobs of its part only): every job of the file checked first
// (nothing written when one is wrong), then each baked. Returns 0, or the exit code of the first job
// that failed. `doing` is set to what runs (for an out-of-memory message); a signal stops the batch
// (Cancelled). With --merge-reports, merges the parts' reports instead (run_merge_reports).
int run_batch(const BatchArgs& b, const std::function<bool()>& interrupted, const char** doing,
              std::chrono::steady_clock::time_point start);

}  // namespace nmbake
