#include "cli/batch.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <set>

#include <unistd.h>
#include <CLI/CLI.hpp>

#include "cli/job.h"
#include "cli/json_file.h"
#include "cli/outputs.h"
#include "cli/progress.h"
#include "cli/shell.h"
#include "core/stopwatch.h"
#include "core/errors.h"
#include "io/text_file.h"
#include "pipeline/bake.h"

namespace nmbake {

namespace {

// Options whose value is a file: made relative to the jobs file's folder.
const std::set<std::string> kPathOptions = {"cage", "report", "miss-mask", "suspect-mask", "save-cage"};
// Keys a job's options may not hold: they are the job's own fields, or the batch's.
const std::set<std::string> kJobFields = {"low", "high", "highs", "output", "o", "batch", "help", "h", "version"};

std::string resolve(const std::string& dir, const std::string& path) {
  if (dir.empty() || path.empty() || path.front() == '/') return path;
  return (std::filesystem::path(dir) / path).string();
}

std::string job_name(const std::string& path, std::size_t index) { return path + ": job " + std::to_string(index); }

// A string field of a job (or of an option), else UsageError naming it.
std::string text_of(const nlohmann::json& v, const std::string& where) {
  if (v.is_string() && !v.get<std::string>().empty()) return v.get<std::string>();
  throw UsageError(where + " must be a non-empty string, got " + v.dump());
}

// An option's value as command-line words: a flag is given when true; numbers as JSON writes them.
void add_option(std::vector<std::string>& argv, const std::string& key, const nlohmann::json& v, const std::string& dir,
                const std::string& where) {
  if (kJobFields.count(key)) throw UsageError(where + ": \"" + key + "\" is not an option (a job's own field, or the batch's)");
  if (key.empty() || key.front() == '-') throw UsageError(where + ": option \"" + key + "\": give it without dashes");
  const std::string flag = "--" + key;
  if (v.is_boolean()) {
    if (v.get<bool>()) argv.push_back(flag);
  } else if (v.is_number_integer() || v.is_number_float()) {
    argv.push_back(flag);
    argv.push_back(v.dump());
  } else if (v.is_string()) {
    argv.push_back(flag);
    argv.push_back(kPathOptions.count(key) ? resolve(dir, v.get<std::string>()) : v.get<std::string>());
  } else {
    throw UsageError(where + ": option \"" + key + "\" must be a string, a number or true/false, got " + v.dump());
  }
}

const nlohmann::json& object_field(const nlohmann::json& parent, const char* key, const std::string& where) {
  static const nlohmann::json empty = nlohmann::json::object();
  const auto it = parent.find(key);
  if (it == parent.end()) return empty;
  if (!it->is_object()) throw UsageError(where + ": \"" + key + "\" must be an object of options");
  return *it;
}

}  // namespace

std::vector<BatchJob> parse_batch(const std::string& path, const std::string& text, const nlohmann::json& shared) {
  const nlohmann::json doc = parse_json_file_text(path, text);
  if (!doc.is_object() || !doc.contains("jobs") || !doc["jobs"].is_array())
    throw InputError(path + ": expected an object with \"jobs\": [...] (and optionally \"defaults\": {...})");
  for (const auto& [key, value] : doc.items())
    if (key != "jobs" && key != "defaults") throw InputError(path + ": unknown field \"" + key + "\" (\"defaults\", \"jobs\")");
  const nlohmann::json& defaults = object_field(doc, "defaults", path);
  const std::string dir = std::filesystem::path(path).parent_path().string();
  std::vector<BatchJob> jobs;
  if (doc["jobs"].empty()) throw InputError(path + ": \"jobs\" is empty");
  for (const nlohmann::json& j : doc["jobs"]) {
    BatchJob job;
    job.index = jobs.size() + 1;
    const std::string where = job_name(path, job.index);
    if (!j.is_object()) throw UsageError(where + " must be an object with \"low\", \"highs\", \"output\" and \"options\"");
    for (const auto& [key, value] : j.items())
      if (key != "low" && key != "high" && key != "highs" && key != "output" && key != "options")
        throw UsageError(where + ": unknown field \"" + key + "\" (\"low\", \"highs\", \"output\", \"options\")");
    if (!j.contains("low") || !j.contains("output") || (!j.contains("highs") && !j.contains("high")))
      throw UsageError(where + ": needs \"low\", \"highs\" and \"output\"");
    job.argv = {"nmbake", resolve(dir, text_of(j["low"], where + ": \"low\""))};
    const nlohmann::json highs = j.contains("highs") ? j["highs"] : nlohmann::json::array({j["high"]});
    if (!highs.is_array() || highs.empty()) throw UsageError(where + ": \"highs\" must be an array of files");
    for (const nlohmann::json& h : highs) job.argv.push_back(resolve(dir, text_of(h, where + ": \"highs\"")));
    job.argv.push_back("--output");
    job.argv.push_back(resolve(dir, text_of(j["output"], where + ": \"output\"")));
    // The job's options, then the defaults it does not set, then the batch's own.
    nlohmann::json options = object_field(j, "options", where);
    for (const nlohmann::json* more : {&defaults, &shared})
      for (const auto& [key, value] : more->items())
        if (!options.contains(key)) options[key] = value;
    for (const auto& [key, value] : options.items()) add_option(job.argv, key, value, dir, where);
    jobs.push_back(std::move(job));
  }
  return jobs;
}

namespace {

// Whether argv holds the option `name` (alone, or as name=VALUE).
bool has_batch_option(int argc, char** argv, const char* name) {
  const std::size_t n = std::strlen(name);
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], name, n) == 0 && (argv[i][n] == '\0' || argv[i][n] == '=')) return true;
  return false;
}

}  // namespace

bool wants_batch(int argc, char** argv) {
  return has_batch_option(argc, argv, "--batch") || has_batch_option(argc, argv, "--shard") ||
         has_batch_option(argc, argv, "--merge-reports");
}

int parse_batch_args(int argc, char** argv, BatchArgs& b) {
  const bool merging = has_batch_option(argc, argv, "--merge-reports");
  if (!merging && !has_batch_option(argc, argv, "--batch"))
    throw UsageError("--shard applies to --batch: nmbake --batch jobs.json --shard I/N [--report part.json]");
  CLI::App app{
      "nmbake --batch: bake the jobs of a JSON file in one process, or one part of them on a farm (--shard);\n"
      "nmbake --merge-reports: the batch report of the parts' (docs/usage.md, \"Batch\", \"Batches on a farm\").",
      "nmbake"};
  std::string shard;
  app.add_option("--batch", b.file, "The jobs file");
  app.add_option("--shard", shard,
                 "I/N: bake only part I (0 to N-1) of N of the jobs, those sharing a high-poly in one part, the same "
                 "split on every machine; --report then writes the part's report (for a Slurm array: --shard "
                 "$SLURM_ARRAY_TASK_ID/N)");
  app.add_option("--report", b.report, "Write the batch's JSON report: each job's report and a summary");
  app.add_option("--threads", b.threads, "Worker threads of every job (default: all cores)");
  app.add_flag("--quiet", b.quiet, "As nmbake's --quiet, for every job");
  app.add_flag("--progress", b.progress, "Show the progress line even when stderr is not a terminal");
  app.add_flag("--strict", b.strict, "Any warning fails its job (exit 5 for the batch); the others still run");
  app.add_flag("--no-warnings", b.no_warnings, "Do not print warnings");
  app.add_option("--merge-reports", b.merge,
                 "PART...: instead of a batch, merge the --report files of the parts of one --shard N into the report "
                 "one process would write (-o FILE; exit: the first failed job's, as the batch's)");
  app.add_option("-o,--output", b.merged, "With --merge-reports: the batch report to write");
  app.footer(std::string("\n") + kBatchExample + "\n" + kExitCodes);
  require_numbers(app);
  for (int i = 1; i < argc; ++i)  // before parsing: `--batch --help` would read "--help" as the file
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::printf("%s", app.help().c_str());
      return 0;
    }
  const char* what = merging ? "--merge-reports: " : "--batch: ";
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    throw UsageError(what + std::string(e.what()));
  }
  if (merging) {
    for (const char* other : {"--batch", "--shard", "--report", "--threads", "--progress", "--strict", "--no-warnings"})
      if (app.count(other))
        throw UsageError(std::string("--merge-reports: ") + other + " is an option of a batch's run (--batch), not of the merge");
    if (b.merge.empty()) throw UsageError("--merge-reports: give the parts' reports, then -o FILE");
    if (b.merged.empty()) throw UsageError("--merge-reports: -o FILE, the batch report to write, is required");
    return -1;
  }
  if (app.count("--output")) throw UsageError("--batch: -o applies to --merge-reports; the batch's report is --report FILE");
  if (b.file.empty()) throw UsageError("--batch: the jobs file is empty");
  if (app.count("--shard")) b.shard = parse_shard(shard);
  return -1;
}

}  // namespace nmbake

namespace nmbake {

namespace {

using Clock = std::chrono::steady_clock;

// Each job's command line as nmbake parses it; every problem found before the first bake.
std::vector<Args> check_jobs(const std::string& path, const std::vector<BatchJob>& jobs) {
  std::vector<Args> all(jobs.size());
  struct Output {
    std::string path, what;
    std::size_t job;
  };
  std::vector<Output> outputs;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const std::string where = path + ": job " + std::to_string(jobs[i].index);
    CLI::App app{"", "nmbake"};
    Args& a = all[i];
    add_options(app, a);
    std::vector<const char*> argv;
    for (const std::string& w : jobs[i].argv) argv.push_back(w.c_str());
    try {
      app.parse(int(argv.size()), const_cast<char**>(argv.data()));
    } catch (const CLI::ParseError& e) {
      throw UsageError(where + ": " + e.what());
    }
    finish_args(a, app);
    try {
      validate_options(bake_options(a));
    } catch (const Error& e) {
      throw UsageError(where + ": " + e.what());
    }
    for (const auto& [file, what] : {std::pair{&a.output, "the map"}, std::pair{&a.miss_mask, "the miss mask"},
                                     std::pair{&a.suspect_mask, "the suspect mask"}, std::pair{&a.save_cage, "the cage"},
                                     std::pair{&a.report, "the report"}}) {
      if (file->empty()) continue;
      for (const Output& o : outputs)
        if (same_file(o.path, *file))
          throw UsageError(where + ": " + what + " " + *file + " is also written by job " + std::to_string(jobs[o.job].index) +
                           " (" + o.what + " " + o.path + "); nothing written");
      outputs.push_back({*file, what, i});
    }
  }
  return all;
}

// The batch's options given to every job, as a job's "options" would give them.
nlohmann::json shared_options(const BatchArgs& b) {
  nlohmann::json shared = nlohmann::json::object();
  if (b.threads) shared["threads"] = b.threads;
  if (b.quiet) shared["quiet"] = true;
  if (b.quiet > 1 || b.no_warnings) shared["no-warnings"] = true;
  if (b.strict) shared["strict"] = true;
  return shared;
}

}  // namespace

int run_batch(const BatchArgs& b, const std::function<bool()>& interrupted, const char** doing, Clock::time_point start) {
  if (!b.merge.empty()) return run_merge_reports(b.merge, b.merged, b.quiet > 0);
  const std::string text = read_text_file(b.file);
  const std::vector<BatchJob> jobs = parse_batch(b.file, text, shared_options(b));
  const std::vector<Args> args = check_jobs(b.file, jobs);  // every job, also other parts': each part refuses a wrong file
  if (!b.report.empty()) check_output_files({{"--batch", b.file, "the jobs"}}, {{"--report", b.report, "the batch report"}});
  // The jobs to bake: all, or the part's (positions in `jobs`, in file order).
  std::vector<std::size_t> take(jobs.size());
  for (std::size_t i = 0; i < take.size(); ++i) take[i] = i;
  const bool sharded = b.shard.count > 0;
  std::string part;  // "part 1/3"
  if (sharded) {
    std::vector<ShardJob> costs(jobs.size());
    for (std::size_t i = 0; i < jobs.size(); ++i) {
      const BakeOptions o = bake_options(args[i]);  // checked by check_jobs
      costs[i] = {args[i].highs, std::uint64_t(o.width) * std::uint64_t(o.height)};
    }
    take = split_jobs(costs, b.shard.count)[std::size_t(b.shard.index)];
    part = "part " + std::to_string(b.shard.index) + "/" + std::to_string(b.shard.count);
    if (take.empty() && b.quiet < 2)
      std::fprintf(stderr, "nmbake: %s: --shard %d/%d gets no job (%zu jobs in %zu groups sharing a high-poly); nothing baked\n",
                   b.file.c_str(), b.shard.index, b.shard.count, jobs.size(), count_job_groups(costs));
  }
  Progress progress(!b.quiet && (b.progress || ::isatty(STDERR_FILENO)), start, interrupted);
  MeshCache cache;
  nlohmann::json reports = nlohmann::json::array();
  int first_failure = 0;
  std::size_t failed = 0;
  for (std::size_t k = 0; k < take.size(); ++k) {
    const std::size_t i = take[k];
    const Args& a = args[i];
    progress.label(sharded ? "job " + std::to_string(jobs[i].index) + " (" + std::to_string(k + 1) + " of " +
                                 std::to_string(take.size()) + " of " + part + "): "
                           : "job " + std::to_string(i + 1) + " of " + std::to_string(jobs.size()) + ": ");
    nlohmann::json report;
    const JobEnv env{jobs[i].argv, interrupted, doing, progress, Clock::now(), &cache, true, &report};
    int code = 0;
    std::string error;
    const auto t0 = Clock::now();
    try {
      bake_job(a, env);
    } catch (const Cancelled&) {
      throw;
    } catch (...) {
      const Failure f = failure_of(std::current_exception(), {}, doing);
      code = f.status;
      error = f.message;
    }
    if (code) {
      progress.above([&] {
        std::fprintf(stderr, "error: %s: job %zu (%s): %s\n", b.file.c_str(), jobs[i].index, a.output.c_str(), error.c_str());
      });
      ++failed;
      if (!first_failure) first_failure = code;
    }
    reports.push_back({{"job", jobs[i].index},
                       {"output", a.output},
                       {"exit_code", code},
                       {"error", code ? nlohmann::json(error) : nlohmann::json(nullptr)},
                       {"seconds", seconds_since(t0)},
                       {"report", code ? nlohmann::json(nullptr) : report}});
    if (interrupted()) throw Cancelled();
  }
  progress.finish();
  const double seconds = seconds_since(start);
  std::size_t bvh_reused = 0;
  for (const auto& [key, high] : cache.highs) bvh_reused += high->bvh.reused;
  if (!b.report.empty()) {
    nlohmann::json summary = {{"batch", b.file},
                              {"jobs", reports},
                              {"summary",
                               {{"jobs", take.size()},
                                {"baked", take.size() - failed},
                                {"failed", failed},
                                {"high_loads_saved", cache.hits},
                                {"bvh_reused", bvh_reused},
                                {"seconds", seconds}}}};
    if (sharded) {
      nlohmann::json taken = nlohmann::json::array();
      for (std::size_t i : take) taken.push_back(jobs[i].index);
      summary["shard"] = {{"index", b.shard.index},
                          {"count", b.shard.count},
                          {"jobs", taken},
                          {"jobs_in_file", jobs.size()},
                          {"jobs_file", jobs_file_fingerprint(text)}};
    }
    write_text_atomically(b.report, summary.dump(2) + "\n");
  }
  if (!b.quiet)
    std::printf(
        "nmbake: batch %s%s: %zu jobs, %zu baked, %zu failed, %.2f s; high-poly files loaded once for %zu jobs, a BVH reused by "
        "%zu\n",
        b.file.c_str(), sharded ? (" " + part).c_str() : "", take.size(), take.size() - failed, failed, seconds, cache.hits,
        bvh_reused);
  return first_failure;
}

}  // namespace nmbake
