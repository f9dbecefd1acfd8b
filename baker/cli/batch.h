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
#pragma once

#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/args.h"

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

// What the batch's own command line sets: the jobs file, the batch report, and the options given to
// every job.
struct BatchArgs {
  std::string file, report;
  int threads = 0, quiet = 0;
  bool progress = false, strict = false, no_warnings = false;
};

// Whether argv asks for a batch (--batch FILE or --batch=FILE).
bool wants_batch(int argc, char** argv);

// Parses the batch's command line: --batch FILE [--report FILE] [--threads N] [--quiet] [--progress]
// [--strict] [--no-warnings]. Returns -1 to go on, or the exit code of --help.
int parse_batch_args(int argc, char** argv, BatchArgs& b);

// Runs the batch: every job checked first (nothing written when one is wrong), then each baked.
// Returns 0, or the exit code of the first job that failed. `doing` is set to what runs (for an
// out-of-memory message); a signal stops the batch (Cancelled).
int run_batch(const BatchArgs& b, const std::function<bool()>& interrupted, const char** doing,
              std::chrono::steady_clock::time_point start);

}  // namespace nmbake
