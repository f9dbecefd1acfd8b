#include "cli/shard.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <system_error>

#include "cli/json_file.h"
#include "core/errors.h"
#include "core/fnv.h"
#include "io/output_files.h"
#include "io/text_file.h"

namespace nmbake {

namespace {

// A whole decimal number of `word`, or -1 (a sign, spaces, other characters, overflow).
long long shard_number(const std::string& word) {
  if (word.empty() || word.size() > 9 || word.find_first_not_of("0123456789") != std::string::npos) return -1;
  long long n = -1;
  std::from_chars(word.data(), word.data() + word.size(), n);
  return n;
}

// A part's "shard" as its report holds it, checked for what the merge reads.
struct PartInfo {
  int index = 0, count = 0;
  std::size_t jobs_in_file = 0;
  std::string fingerprint;
  std::vector<std::size_t> jobs;  // by their number in the file, from 1
};

PartInfo part_info(const std::string& path, const nlohmann::json& r) {
  const auto bad = [&](const std::string& what) {
    return InputError(path + ": not a report of nmbake --batch --shard (" + what + ")");
  };
  if (!r.is_object() || !r.contains("shard") || !r["shard"].is_object()) throw bad("no \"shard\"");
  const nlohmann::json& s = r["shard"];
  for (const char* key : {"index", "count", "jobs_in_file"})
    if (!s.contains(key) || !s[key].is_number_unsigned()) throw bad(std::string("no whole number \"shard\".\"") + key + "\"");
  if (!s.contains("jobs_file") || !s["jobs_file"].is_string()) throw bad("no \"shard\".\"jobs_file\"");
  if (!s.contains("jobs") || !s["jobs"].is_array()) throw bad("no \"shard\".\"jobs\"");
  if (!r.contains("jobs") || !r["jobs"].is_array() || r["jobs"].size() != s["jobs"].size())
    throw bad("\"jobs\" does not list the jobs of \"shard\".\"jobs\"");
  if (!r.contains("summary") || !r["summary"].is_object()) throw bad("no \"summary\"");
  PartInfo p;
  const auto count = s["count"].get<std::uint64_t>(), index = s["index"].get<std::uint64_t>();
  if (count < 1 || count > std::uint64_t(kMaxShards) || index >= count) throw bad("\"shard\" is not a part I of N");
  p.count = int(count);
  p.index = int(index);
  p.jobs_in_file = s["jobs_in_file"].get<std::size_t>();
  p.fingerprint = s["jobs_file"].get<std::string>();
  for (std::size_t i = 0; i < s["jobs"].size(); ++i) {
    const nlohmann::json& j = s["jobs"][i];
    const nlohmann::json& entry = r["jobs"][i];
    if (!j.is_number_unsigned() || j.get<std::uint64_t>() < 1 || j.get<std::uint64_t>() > p.jobs_in_file)
      throw bad("\"shard\".\"jobs\" holds " + j.dump() + ", not a job of the file");
    if (!entry.is_object() || !entry.contains("job") || entry["job"] != j)
      throw bad("\"jobs\" does not list the jobs of \"shard\".\"jobs\"");
    if (!p.jobs.empty() && j.get<std::size_t>() <= p.jobs.back()) throw bad("\"shard\".\"jobs\" is not in file order");
    p.jobs.push_back(j.get<std::size_t>());
  }
  return p;
}

// A summary count of a part's report (0 when absent: an older report).
std::uint64_t summary_count(const nlohmann::json& r, const char* key) {
  const auto it = r["summary"].find(key);
  return it != r["summary"].end() && it->is_number_unsigned() ? it->get<std::uint64_t>() : 0;
}

double summary_seconds(const nlohmann::json& r) {
  const auto it = r["summary"].find("seconds");
  return it != r["summary"].end() && it->is_number() ? it->get<double>() : 0.0;
}

}  // namespace

ShardSpec parse_shard(const std::string& text) {
  const std::size_t slash = text.find('/');
  const long long i = slash == std::string::npos ? -1 : shard_number(text.substr(0, slash));
  const long long n = slash == std::string::npos ? -1 : shard_number(text.substr(slash + 1));
  std::string word;
  for (char c : text) word += (c >= ' ' && c < 127) ? c : '?';
  if (word.size() > 40) word = word.substr(0, 40) + "...";
  if (i < 0 || n < 0)
    throw UsageError(
        "--shard takes I/N, part I (0 to N-1) of N parts, e.g. --shard 0/4 or --shard $SLURM_ARRAY_TASK_ID/4; got '" + word +
        "'");
  if (n < 1 || n > kMaxShards)
    throw UsageError("--shard " + word + ": N, the number of parts, must be 1 to " + std::to_string(kMaxShards));
  if (i >= n) throw UsageError("--shard " + word + ": part I must be 0 to N-1 (" + std::to_string(n - 1) + ")");
  return {int(i), int(n)};
}

std::string high_poly_key(const std::vector<std::string>& highs) {
  std::set<std::string> set;
  for (const std::string& h : highs) {
    std::error_code ec;
    std::filesystem::path p = std::filesystem::absolute(h, ec);
    if (ec) p = h;
    set.insert(p.lexically_normal().string());
  }
  std::string key;
  for (const std::string& s : set) key += s + '\n';
  return key;
}

namespace {

// The groups of jobs sharing a high-poly, in the order of their first job in the file.
struct JobGroup {
  std::vector<std::size_t> jobs;
  std::uint64_t cost = 0;
};

std::vector<JobGroup> group_jobs(const std::vector<ShardJob>& jobs) {
  std::vector<JobGroup> groups;
  std::map<std::string, std::size_t> by_key;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const auto [it, added] = by_key.emplace(high_poly_key(jobs[i].highs), groups.size());
    if (added) groups.emplace_back();
    JobGroup& g = groups[it->second];
    g.jobs.push_back(i);
    g.cost += jobs[i].cost;
  }
  return groups;
}

}  // namespace

std::size_t count_job_groups(const std::vector<ShardJob>& jobs) { return group_jobs(jobs).size(); }

std::vector<std::vector<std::size_t>> split_jobs(const std::vector<ShardJob>& jobs, int count) {
  std::vector<JobGroup> groups = group_jobs(jobs);
  // Largest first; equal costs keep the file's order (the groups are in it).
  std::stable_sort(groups.begin(), groups.end(), [](const JobGroup& a, const JobGroup& b) { return a.cost > b.cost; });
  std::vector<std::vector<std::size_t>> parts(std::size_t(std::max(count, 1)));
  std::vector<std::uint64_t> load(parts.size(), 0);
  for (const JobGroup& g : groups) {
    const std::size_t p = std::size_t(std::min_element(load.begin(), load.end()) - load.begin());  // the first of equals
    load[p] += g.cost;
    parts[p].insert(parts[p].end(), g.jobs.begin(), g.jobs.end());
  }
  for (auto& part : parts) std::sort(part.begin(), part.end());
  return parts;
}

std::string jobs_file_fingerprint(const std::string& text) {
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fnv1a64(text)));
  return std::string("fnv1a64:") + hex;
}

nlohmann::json merge_batch_reports(const std::vector<std::string>& paths, const std::vector<nlohmann::json>& parts) {
  if (paths.empty() || paths.size() != parts.size()) throw UsageError("--merge-reports: give the reports of every part");
  std::vector<PartInfo> infos;
  for (std::size_t i = 0; i < parts.size(); ++i) infos.push_back(part_info(paths[i], parts[i]));
  // One jobs file, one count, each part once.
  const PartInfo& first = infos.front();
  std::vector<std::size_t> given(std::size_t(first.count), SIZE_MAX);  // part -> its position in `parts`
  for (std::size_t i = 0; i < infos.size(); ++i) {
    const PartInfo& p = infos[i];
    if (p.fingerprint != first.fingerprint || p.jobs_in_file != first.jobs_in_file)
      throw UsageError(paths[i] + ": a part of another jobs file than " + paths[0] + " (" + p.fingerprint + ", not " +
                       first.fingerprint + "); merge the parts of one batch");
    if (p.count != first.count)
      throw UsageError(paths[i] + ": part " + std::to_string(p.index) + "/" + std::to_string(p.count) + ", but " + paths[0] +
                       " is a part of " + std::to_string(first.count) + "; merge the parts of one --shard N");
    if (given[std::size_t(p.index)] != SIZE_MAX)
      throw UsageError(paths[i] + ": part " + std::to_string(p.index) + "/" + std::to_string(p.count) + " again (also " +
                       paths[given[std::size_t(p.index)]] + ")");
    given[std::size_t(p.index)] = i;
  }
  for (std::size_t k = 0; k < given.size(); ++k)
    if (given[k] == SIZE_MAX)
      throw UsageError("--merge-reports: part " + std::to_string(k) + "/" + std::to_string(first.count) +
                       " is missing (its report, written by --shard " + std::to_string(k) + "/" + std::to_string(first.count) +
                       ")");
  // Each job of the file in exactly one part.
  std::size_t listed = 0;
  for (const PartInfo& p : infos) listed += p.jobs.size();
  if (listed < first.jobs_in_file)
    throw UsageError("--merge-reports: the parts hold " + std::to_string(listed) + " jobs of the file's " +
                     std::to_string(first.jobs_in_file) + " (parts split by another nmbake?)");
  std::vector<std::size_t> owner(first.jobs_in_file + 1, SIZE_MAX);
  for (std::size_t i = 0; i < infos.size(); ++i)
    for (std::size_t job : infos[i].jobs) {
      if (owner[job] != SIZE_MAX)
        throw UsageError(paths[i] + ": job " + std::to_string(job) + " is also in " + paths[owner[job]] +
                         " (parts split by another nmbake?)");
      owner[job] = i;
    }
  for (std::size_t job = 1; job <= first.jobs_in_file; ++job)
    if (owner[job] == SIZE_MAX)
      throw UsageError("--merge-reports: job " + std::to_string(job) +
                       " of the jobs file is in no part (parts split by another nmbake?)");

  // The whole: the jobs in file order, the counts summed.
  nlohmann::json jobs = nlohmann::json::array();
  std::vector<std::size_t> next(parts.size(), 0);
  for (std::size_t job = 1; job <= first.jobs_in_file; ++job) {
    const std::size_t i = owner[job];
    jobs.push_back(parts[i]["jobs"][next[i]++]);
  }
  std::uint64_t counts[5] = {};
  const char* const keys[5] = {"jobs", "baked", "failed", "high_loads_saved", "bvh_reused"};
  double seconds = 0.0, longest = 0.0;
  nlohmann::json files = nlohmann::json::array();
  for (std::size_t k = 0; k < given.size(); ++k) {
    const nlohmann::json& r = parts[given[k]];
    for (int c = 0; c < 5; ++c) counts[c] += summary_count(r, keys[c]);
    seconds += summary_seconds(r);
    longest = std::max(longest, summary_seconds(r));
    files.push_back(paths[given[k]]);
  }
  nlohmann::json summary = nlohmann::json::object();
  for (int c = 0; c < 5; ++c) summary[keys[c]] = counts[c];
  summary["seconds"] = seconds;
  const nlohmann::json& batch = parts[given[0]].contains("batch") ? parts[given[0]]["batch"] : nlohmann::json(nullptr);
  return {{"batch", batch},
          {"jobs", jobs},
          {"summary", summary},
          {"merged",
           {{"parts", files}, {"count", first.count}, {"jobs_file", first.fingerprint}, {"seconds_longest_part", longest}}}};
}

int run_merge_reports(const std::vector<std::string>& paths, const std::string& output, bool quiet) {
  std::vector<NamedFile> inputs;
  for (const std::string& p : paths) inputs.push_back({"--merge-reports", p, "a part's report"});
  check_output_files(inputs, {{"--output", output, "the batch report"}});
  std::vector<nlohmann::json> parts;
  for (const std::string& p : paths) parts.push_back(parse_json_file_text(p, read_text_file(p)));
  const nlohmann::json merged = merge_batch_reports(paths, parts);
  write_text_atomically(output, merged.dump(2) + "\n");
  int first_failure = 0;
  for (const nlohmann::json& j : merged["jobs"])
    if (!first_failure && j.contains("exit_code") && j["exit_code"].is_number_integer())
      first_failure = j["exit_code"].get<int>();
  const nlohmann::json& s = merged["summary"];
  if (!quiet)
    std::printf(
        "nmbake: merged %d parts of %s into %s: %llu jobs, %llu baked, %llu failed, %.2f s in all (longest part %.2f s)\n",
        merged["merged"]["count"].get<int>(),
        merged["batch"].is_string() ? merged["batch"].get<std::string>().c_str() : "the batch", output.c_str(),
        static_cast<unsigned long long>(s["jobs"].get<std::uint64_t>()),
        static_cast<unsigned long long>(s["baked"].get<std::uint64_t>()),
        static_cast<unsigned long long>(s["failed"].get<std::uint64_t>()), s["seconds"].get<double>(),
        merged["merged"]["seconds_longest_part"].get<double>());
  return first_failure;
}

}  // namespace nmbake
