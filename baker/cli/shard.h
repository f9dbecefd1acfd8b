// Batches on a render farm (issue 37, item 3): `nmbake --batch jobs.json --shard I/N` bakes part I of
// N of the jobs, and `nmbake --merge-reports part*.json -o batch.json` makes one batch report of the
// parts' reports (docs/usage.md, "Batches on a farm").
//
// The split is a function of the jobs file alone (no thread count, hash seed or directory order
// enters it), so every task of an array job computes the same one: jobs whose high-poly files are
// the same set (each path resolved against the jobs file's folder as the batch does, made absolute
// and lexically normal) form a group, which stays in one part so that its files are loaded and its
// BVH built once; groups go, the costliest first (ties: the one that comes first in the file), to
// the part with the least cost so far (ties: the lowest part). A job's cost is its map's texel count
// (--size W x H; the same for every UDIM tile and map of the set).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace nmbake {

// --shard I/N: part `index` (0 to count - 1) of `count`.
struct ShardSpec {
  int index = 0;
  int count = 0;  // 0: no --shard (the whole batch)
};

// The most parts --shard takes.
constexpr int kMaxShards = 1000000;

// Reads --shard's value "I/N" (whole decimal numbers, 0 <= I < N <= kMaxShards). Throws UsageError
// naming the value.
ShardSpec parse_shard(const std::string& text);

// A job of the file as the split sees it.
struct ShardJob {
  std::vector<std::string> highs;  // its high-poly files, as the batch resolved them
  std::uint64_t cost = 0;          // texels of its map
};

// The group key of a job's high-poly files: the set of them, each absolute and lexically normal.
std::string high_poly_key(const std::vector<std::string>& highs);

// The jobs (by their position in `jobs`, file order) of each of `count` parts, each part's in file
// order; a part may get none when there are fewer groups than parts.
std::vector<std::vector<std::size_t>> split_jobs(const std::vector<ShardJob>& jobs, int count);

// How many groups of jobs sharing a high-poly `jobs` has.
std::size_t count_job_groups(const std::vector<ShardJob>& jobs);

// The jobs file's fingerprint, which the merge compares: "fnv1a64:" and 16 hex digits of its bytes.
std::string jobs_file_fingerprint(const std::string& text);

// The batch report of the parts' reports (`paths` name them in messages, `parts` are their JSON), as
// one process baking the whole file writes it: "jobs" every part's, in file order; "summary" each
// count summed (jobs, baked, failed, high_loads_saved, bvh_reused) and "seconds" the parts' sum (the
// time of one process, roughly); "merged" the parts' files, their count, the jobs file's fingerprint
// and the longest part's seconds. Throws InputError for a file that is not a part's report, and
// UsageError naming the file for parts of different jobs files or --shard counts, a part given
// twice, or a part (or a job) missing.
nlohmann::json merge_batch_reports(const std::vector<std::string>& paths, const std::vector<nlohmann::json>& parts);

// nmbake --merge-reports PART... -o FILE [--quiet]: reads the parts, merges them, writes FILE (to a
// temporary file renamed into place) and prints one summary line unless quiet. Returns the exit code
// of the first job (in file order) that failed, else 0, as the batch itself does.
int run_merge_reports(const std::vector<std::string>& paths, const std::string& output, bool quiet);

}  // namespace nmbake
