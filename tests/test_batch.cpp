// nmbake --batch (issue 20, item 6): many jobs in one process, each baking what its own command
// line would; one high-poly loaded once for the jobs that share it; a failing job reported while
// the others run; a wrong file or two jobs writing one output stop everything before any bake.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "cli/shard.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "pipeline/bake.h"
#include "test_support.h"

namespace nmbake {
namespace {

using test::contains;
using test::run_nmbake;

std::size_t lines(const std::string& s) { return std::size_t(std::count(s.begin(), s.end(), '\n')); }

TEST(Batch, JobsBakeWhatTheirCommandsBake) {
  const std::string dir = test::scratch_dir();
  std::filesystem::create_directories(dir + "/jobs/out");
  test::write_file(dir + "/jobs/jobs.json",
                   R"({
    "defaults": {"size": 64, "padding": 4},
    "jobs": [
      {"low": ")" + test::sample_low() +
                       R"(", "highs": [")" + test::sample_high() +
                       R"("], "output": "out/a.png", "options": {"report": "out/a.json"}},
      {"low": ")" + test::sample_low() +
                       R"(", "high": ")" + test::sample_high() +
                       R"(", "output": "out/b.exr", "options": {"samples": 4, "size": 32}},
      {"low": ")" + test::sample_low() +
                       R"(", "highs": [")" + test::sample_high() +
                       R"("], "output": "out/c.tga", "options": {"keep-backfaces": true, "green": "down"}}
    ]})");
  // Run from another folder: relative paths belong to the jobs file's.
  const test::CliRun batch = run_nmbake("--batch jobs/jobs.json --report batch.json --progress", "", dir);
  ASSERT_EQ(batch.code, 0) << batch.err;
  const std::string singles[] = {
      test::sample_low() + " " + test::sample_high() + " -o a.png --size 64 --padding 4",
      test::sample_low() + " " + test::sample_high() + " -o b.exr --size 32 --padding 4 --samples 4",
      test::sample_low() + " " + test::sample_high() + " -o c.tga --size 64 --padding 4 --keep-backfaces --green down"};
  const char* names[] = {"a.png", "b.exr", "c.tga"};
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(run_nmbake(singles[i], "", dir).code, 0);
    // EXR files carry the time they were written: their pixels are compared.
    if (i == 1) EXPECT_TRUE(read_image(dir + "/jobs/out/b.exr").pixels == read_image(dir + "/b.exr").pixels);
    else EXPECT_TRUE(test::read_file(dir + "/jobs/out/" + names[i]) == test::read_file(dir + "/" + names[i])) << names[i];
  }
  EXPECT_TRUE(test::exists(dir + "/jobs/out/a.json"));
  const nlohmann::json report = nlohmann::json::parse(test::read_file(dir + "/batch.json"));
  EXPECT_EQ(report["summary"]["jobs"], 3);
  EXPECT_EQ(report["summary"]["baked"], 3);
  EXPECT_EQ(report["summary"]["failed"], 0);
  EXPECT_EQ(report["summary"]["high_loads_saved"], 2);
  EXPECT_EQ(report["summary"]["bvh_reused"], 2);
  EXPECT_EQ(report["jobs"][0]["report"]["bvh_reused"], false);
  EXPECT_EQ(report["jobs"][2]["report"]["bvh_reused"], true);
  ASSERT_EQ(report["jobs"].size(), 3u);
  EXPECT_EQ(report["jobs"][1]["report"]["options"]["samples"], 4);
  EXPECT_EQ(report["jobs"][2]["report"]["options"]["keep_backfaces"], true);
  // The high-poly's topology is checked by the first job (its normals are in the file, so the bake
  // does not find it on the way) and read by the others: the same answers, no time of their own.
  EXPECT_GT(report["jobs"][0]["report"]["seconds"]["topology"].get<double>(), 0.0);
  EXPECT_EQ(report["jobs"][0]["report"]["high_normals_computed"], false);
  EXPECT_GT(report["jobs"][0]["report"]["high_mesh"]["welded_vertices"].get<std::size_t>(), 0u);
  for (int j = 1; j < 3; ++j) {
    EXPECT_EQ(report["jobs"][j]["report"]["seconds"]["topology"].get<double>(), 0.0) << "job " << j + 1;
    EXPECT_EQ(report["jobs"][j]["report"]["high_mesh"], report["jobs"][0]["report"]["high_mesh"]) << "job " << j + 1;
  }
  EXPECT_TRUE(report["jobs"][0]["error"].is_null());
  // One progress line for the batch, naming each job.
  for (const char* job : {"job 1 of 3: ", "job 3 of 3: tracing"}) EXPECT_TRUE(contains(batch.err, job)) << batch.err;
  EXPECT_TRUE(contains(batch.out, "3 jobs, 3 baked, 0 failed")) << batch.out;
}

TEST(Batch, AFailingJobLeavesTheOthersToRun) {
  const std::string dir = test::scratch_dir();
  test::write_file(dir + "/jobs.json", R"({"defaults": {"size": 32}, "jobs": [
      {"low": "missing.obj", "highs": [")" +
                                           test::sample_high() + R"("], "output": "a.png"},
      {"low": ")" + test::sample_low() + R"(", "highs": [")" +
                                           test::sample_high() + R"("], "output": "b.png"}]})");
  const test::CliRun r = run_nmbake("--batch jobs.json --report batch.json", "", dir);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(contains(r.err, "error: jobs.json: job 1 (a.png): missing.obj: cannot open")) << r.err;
  EXPECT_FALSE(test::exists(dir + "/a.png"));
  EXPECT_TRUE(test::exists(dir + "/b.png"));
  const nlohmann::json report = nlohmann::json::parse(test::read_file(dir + "/batch.json"));
  EXPECT_EQ(report["jobs"][0]["exit_code"], 2);
  EXPECT_TRUE(contains(report["jobs"][0]["error"].get<std::string>(), "missing.obj"));
  EXPECT_EQ(report["summary"]["failed"], 1);
  // --strict: a job with a warning fails with 5 (nothing of it written), the others are baked.
  test::write_file(dir + "/strict.json", R"({"defaults": {"size": 32}, "jobs": [
      {"low": ")" + test::sample_low() + R"(", "highs": [")" +
                                             test::sample_high() +
                                             R"("], "output": "s1.png", "options": {"front": 0.0001, "rear": 0.0001}},
      {"low": ")" + test::sample_low() + R"(", "highs": [")" +
                                             test::sample_high() + R"("], "output": "s2.png"}]})");
  const test::CliRun strict = run_nmbake("--batch strict.json --strict", "", dir);
  EXPECT_EQ(strict.code, 5) << strict.err;
  EXPECT_FALSE(test::exists(dir + "/s1.png"));
  EXPECT_TRUE(test::exists(dir + "/s2.png"));
}

TEST(Batch, AWrongFileStopsEverythingBeforeTheFirstBake) {
  const std::string dir = test::scratch_dir();
  const std::string job = R"({"low": ")" + test::sample_low() + R"(", "highs": [")" + test::sample_high() + R"("], "output": ")";
  struct Case {
    std::string text;
    int code;
    const char* message;
  };
  const Case cases[] = {
      {"{\"jobs\": [" + job + "a.png\"}, " + job + "./a.png\"}]}", 1,
       "job 2: the map ./a.png is also written by job 1 (the map a.png)"},
      {"{\"jobs\": [" + job + "a.png\"}, " + job + "b.png\", \"options\": {\"report\": \"a.png\"}}]}", 1,
       "job 2: the report a.png is also written by job 1"},
      {"{\"jobs\": [" + job + "a.png\", \"options\": {\"sampels\": 4}}]}", 1,
       "job 1: The following argument was not expected: --sampels"},
      {"{\"jobs\": [" + job + "a.png\", \"options\": {\"output\": \"x.png\"}}]}", 1, "\"output\" is not an option"},
      {"{\"jobs\": [" + job + "a.png\", \"options\": {\"samples\": 0}}]}", 1, "job 1: --samples must be between 1 and 1024"},
      {"{\"jobs\": [" + job + "a.png\", \"options\": {\"size\": [1, 2]}}]}", 1, "must be a string, a number or true/false"},
      {"{\"jobs\": [{\"low\": \"x.obj\", \"output\": \"a.png\"}]}", 1, "job 1: needs \"low\", \"highs\" and \"output\""},
      {"{\"jobs\": [" + job + "a.png\", \"outptu\": 1}]}", 1, "unknown field \"outptu\""},
      {"{\"jobs\": []}", 2, "\"jobs\" is empty"},
      {"{\"jobs\": [" + job + "a.png\"}", 2, "jobs.json: not valid JSON: parse error at line 1"},
      {"[1, 2]", 2, "expected an object with \"jobs\""},
      {"{\"jobs\": [" + job + "a.png\"}], \"default\": {}}", 2, "unknown field \"default\""},
  };
  for (const Case& c : cases) {
    test::write_file(dir + "/jobs.json", c.text);
    const test::CliRun r = run_nmbake("--batch jobs.json --report batch.json", "", dir);
    EXPECT_EQ(r.code, c.code) << c.text;
    EXPECT_TRUE(contains(r.err, c.message)) << c.text << "\n" << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_FALSE(test::exists(dir + "/a.png")) << c.text;
    EXPECT_FALSE(test::exists(dir + "/b.png")) << c.text;
    EXPECT_FALSE(test::exists(dir + "/batch.json")) << c.text;
  }
  const test::CliRun missing = run_nmbake("--batch nothing.json", "", dir);
  EXPECT_EQ(missing.code, 2);
  EXPECT_TRUE(contains(missing.err, "nothing.json: cannot read")) << missing.err;
  EXPECT_EQ(run_nmbake("--batch jobs.json --samples 4", "", dir).code, 1) << "job options belong in the file";
  const test::CliRun help = run_nmbake("--batch --help", "", dir);
  EXPECT_EQ(help.code, 0);
  EXPECT_TRUE(contains(help.out, "--batch TEXT")) << help.out;
  EXPECT_TRUE(contains(run_nmbake("--help", "", dir).out, "nmbake --batch jobs.json"));
}

// The BVH a bake keeps for the next bakes from the same high-poly: built over every triangle, taken
// by a bake on the same scene centre, and the maps are those of bakes that build their own.
TEST(Batch, AKeptBvhGivesTheSameMaps) {
  const Mesh low = load_mesh(test::sample_low()), high = load_mesh(test::sample_high());
  BakeOptions o;
  o.width = o.height = 64;
  const BakeResult plain = bake_normal_map(low, high, nullptr, o);
  BvhCache cache;
  o.bvh_cache = &cache;
  const BakeResult first = bake_normal_map(low, high, nullptr, o);
  ASSERT_TRUE(cache.kept != nullptr);
  EXPECT_FALSE(first.stats.bvh.reused);
  EXPECT_EQ(first.stats.select.high_triangles_culled, 0u) << "a kept BVH holds every triangle";
  for (const bool keep_backfaces : {false, true}) {
    o.keep_backfaces = keep_backfaces;
    o.samples = keep_backfaces ? 4 : 1;
    BakeOptions own = o;
    own.bvh_cache = nullptr;
    const BakeResult again = bake_normal_map(low, high, nullptr, o), alone = bake_normal_map(low, high, nullptr, own);
    EXPECT_TRUE(again.stats.bvh.reused);
    EXPECT_TRUE(again.map.pixels == alone.map.pixels) << "keep_backfaces " << keep_backfaces;
  }
  EXPECT_TRUE(first.map.pixels == plain.map.pixels);
  EXPECT_EQ(cache.reused, 2u);
  // A low-poly reaching beyond the high-poly's bounds moves the scene's centre: that bake builds its own.
  Mesh moved = low;
  for (glm::vec3& p : moved.positions) p.x += 0.5f;
  o.keep_backfaces = false;
  o.samples = 1;
  const BakeResult other = bake_normal_map(moved, high, nullptr, o);
  EXPECT_FALSE(other.stats.bvh.reused);
  EXPECT_EQ(cache.reused, 2u);
}

// The kept BVH is found by the high-poly's content, not by where the mesh lies in memory: a copy
// takes it, the same mesh with a vertex moved (the same box) does not.
TEST(Batch, AKeptBvhIsFoundByContent) {
  const Mesh low = load_mesh(test::sample_low());
  Mesh high = load_mesh(test::sample_high());
  BakeOptions o;
  o.width = o.height = 64;
  BvhCache cache;
  o.bvh_cache = &cache;
  EXPECT_FALSE(bake_normal_map(low, high, nullptr, o).stats.bvh.reused);
  const Mesh copy = high;
  EXPECT_TRUE(bake_normal_map(low, copy, nullptr, o).stats.bvh.reused);
  glm::vec3 lo = high.positions[0], hi = lo;
  for (const glm::vec3& p : high.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const auto inside = std::find_if(high.positions.begin(), high.positions.end(), [&](const glm::vec3& p) {
    return glm::all(glm::greaterThan(p, lo)) && glm::all(glm::lessThan(p, hi));
  });
  ASSERT_NE(inside, high.positions.end());
  *inside = glm::mix(*inside, 0.5f * (lo + hi), 0.01f);  // the box stays
  EXPECT_FALSE(bake_normal_map(low, high, nullptr, o).stats.bvh.reused);
  EXPECT_EQ(cache.reused, 1u);
}

// Batches on a render farm (issue 37, item 3): --batch jobs.json --shard I/N bakes part I of N, the
// jobs sharing a high-poly in one part, the same split everywhere; --merge-reports makes of the
// parts' reports the report of one process. The known answers: the maps of one process, byte for
// byte, and its report's summary; the split of a 6-job file worked out by hand below.

void write_shard_mesh(const std::string& path, const Mesh& m) { std::ofstream(path) << obj_text(m, "test_batch_shard"); }

// A relief z = a sin(fx x) cos(fy y) over [-1,1]^2 with its analytic normals.
Mesh shard_relief(double a, double fx, double fy) {
  return test::make_height_field(
      24, 24, [=](double x, double y) { return a * std::sin(fx * x) * std::cos(fy * y); },
      [=](double x, double y) {
        const glm::dvec3 n(-a * fx * std::cos(fx * x) * std::cos(fy * y), a * fy * std::sin(fx * x) * std::sin(fy * y), 1.0);
        return glm::normalize(n);
      });
}

// Writes the meshes into DIR/meshes and the 6-job file: jobs 1, 3 and 5 bake from A (one group),
// 2, 4 and 6 each from its own high-poly; every map 32 x 32, so the cost is 1024 texels a job.
// Groups by cost: A 3072, then B, C, D 1024 each: A to part 0, B to part 1, C to part 2, D to part 1
// (parts 1 and 2 equal: the lower). Parts: {1, 3, 5}, {2, 6}, {4}.
std::string write_six_jobs(const std::string& dir) {
  std::filesystem::create_directories(dir + "/meshes");
  write_shard_mesh(dir + "/meshes/low.obj", test::make_grid(4, 4, -0.8f, 0.8f, -0.8f, 0.8f));
  write_shard_mesh(dir + "/meshes/low2.obj", test::make_grid(2, 2, -0.5f, 0.5f, -0.5f, 0.5f));
  write_shard_mesh(dir + "/meshes/A.obj", shard_relief(0.05, 3.0, 2.0));
  write_shard_mesh(dir + "/meshes/B.obj", shard_relief(0.08, 2.0, 1.0));
  write_shard_mesh(dir + "/meshes/C.obj", shard_relief(0.03, 1.0, 4.0));
  write_shard_mesh(dir + "/meshes/D.obj", shard_relief(0.06, 5.0, 3.0));
  const auto job = [](const char* low, const char* high, const char* out, const char* options) {
    return std::string("{\"low\": \"../meshes/") + low + "\", \"highs\": [\"../meshes/" + high + "\"], \"output\": \"out/" + out +
           "\", \"options\": {" + options + "}}";
  };
  return "{\"defaults\": {\"size\": 32, \"padding\": 2},\n \"jobs\": [\n" + job("low.obj", "A.obj", "a.png", "") + ",\n" +
         job("low.obj", "B.obj", "b.png", "") + ",\n" + job("low2.obj", "A.obj", "c.png", "\"green\": \"down\"") + ",\n" +
         job("low.obj", "C.obj", "d.tga", "") + ",\n" + job("low.obj", "A.obj", "e.png", "\"samples\": 4") + ",\n" +
         job("low.obj", "D.obj", "f.png", "\"report\": \"out/f.json\"") + "]}\n";
}

const char* const kSixOutputs[] = {"a.png", "b.png", "c.png", "d.tga", "e.png", "f.png"};

nlohmann::json read_json(const std::string& path) { return nlohmann::json::parse(test::read_file(path)); }

TEST(BatchShard, ThreePartsBakeWhatOneProcessBakes) {
  const std::string dir = test::scratch_dir();
  const std::string jobs = write_six_jobs(dir);
  for (const char* where : {"one", "farm"}) {
    std::filesystem::create_directories(dir + "/" + where + "/out");
    test::write_file(dir + "/" + where + "/jobs.json", jobs);
  }
  const test::CliRun one = run_nmbake("--batch one/jobs.json --report one.json", "", dir);
  ASSERT_EQ(one.code, 0) << one.err;
  const std::vector<std::vector<std::size_t>> expected = {{1, 3, 5}, {2, 6}, {4}};
  for (int i = 0; i < 3; ++i) {
    const std::string n = std::to_string(i);
    const test::CliRun part = run_nmbake("--batch farm/jobs.json --shard " + n + "/3 --report part" + n + ".json", "", dir);
    ASSERT_EQ(part.code, 0) << part.err;
    EXPECT_TRUE(contains(part.out, "batch farm/jobs.json part " + n + "/3: " + std::to_string(expected[i].size()) + " jobs"))
        << part.out;
    const nlohmann::json r = read_json(dir + "/part" + n + ".json");
    EXPECT_EQ(r["shard"]["index"], i);
    EXPECT_EQ(r["shard"]["count"], 3);
    EXPECT_EQ(r["shard"]["jobs_in_file"], 6);
    EXPECT_EQ(r["shard"]["jobs"].get<std::vector<std::size_t>>(), expected[i]);
    EXPECT_EQ(r["summary"]["jobs"], expected[i].size());
  }
  // The maps, byte for byte.
  for (const char* name : kSixOutputs) {
    const std::string a = test::read_file(dir + "/one/out/" + name), b = test::read_file(dir + "/farm/out/" + name);
    EXPECT_FALSE(a.empty()) << name;
    EXPECT_TRUE(a == b) << name;
  }
  EXPECT_TRUE(test::exists(dir + "/farm/out/f.json"));
  // The merged report (parts in any order) against one process's: every summary count, each job's.
  const test::CliRun merge = run_nmbake("--merge-reports part2.json part0.json part1.json -o batch.json", "", dir);
  ASSERT_EQ(merge.code, 0) << merge.err;
  EXPECT_TRUE(contains(merge.out, "merged 3 parts of farm/jobs.json into batch.json: 6 jobs, 6 baked, 0 failed")) << merge.out;
  const nlohmann::json whole = read_json(dir + "/one.json"), merged = read_json(dir + "/batch.json");
  for (const char* key : {"jobs", "baked", "failed", "high_loads_saved", "bvh_reused"})
    EXPECT_EQ(merged["summary"][key], whole["summary"][key]) << key;
  EXPECT_EQ(merged["summary"]["jobs"], 6);
  EXPECT_EQ(merged["summary"]["high_loads_saved"], 2) << "jobs 3 and 5 take job 1's A";
  EXPECT_TRUE(merged["summary"]["seconds"].is_number());
  ASSERT_EQ(merged["jobs"].size(), 6u);
  for (std::size_t j = 0; j < 6; ++j) {
    const nlohmann::json &m = merged["jobs"][j], &w = whole["jobs"][j];
    EXPECT_EQ(m["job"], j + 1);
    for (const char* key : {"job", "exit_code", "error"}) EXPECT_EQ(m[key], w[key]) << key << " of job " << j + 1;
    EXPECT_EQ(std::filesystem::path(m["output"].get<std::string>()).filename().string(), kSixOutputs[j]);
    // The options but the files (one/... and farm/...): the measured distances included.
    nlohmann::json mo = m["report"]["options"], wo = w["report"]["options"];
    for (const char* file : {"low", "high", "output"}) {
      EXPECT_EQ(std::filesystem::path(mo[file].get<std::string>()).filename().string(),
                std::filesystem::path(wo[file].get<std::string>()).filename().string());
      mo.erase(file), wo.erase(file);
    }
    EXPECT_EQ(mo, wo) << "job " << j + 1;
    EXPECT_EQ(m["report"]["bvh_reused"], w["report"]["bvh_reused"]) << "job " << j + 1;
  }
  EXPECT_EQ(merged["merged"]["count"], 3);
  EXPECT_EQ(merged["merged"]["parts"], nlohmann::json({"part0.json", "part1.json", "part2.json"}));
  EXPECT_EQ(merged["batch"], "farm/jobs.json");
  EXPECT_FALSE(merged.contains("shard"));
}

// Groups by the set of high-poly files as the batch resolves them (relative to the jobs file),
// whatever their spelling and order; balanced by texels, largest first.
TEST(BatchShard, JobsSharingAHighPolyStayInOnePart) {
  const std::string here = std::filesystem::current_path().string();
  std::vector<ShardJob> jobs = {
      {{"m/a.obj"}, 100},                  // 0: group a
      {{"m/b.obj", "m/c.obj"}, 100},       // 1: group bc
      {{"m/./a.obj"}, 100},                // 2: a, another spelling
      {{"m/c.obj", "m/b.obj"}, 100},       // 3: bc in the other order
      {{here + "/m/a.obj"}, 100},          // 4: a, absolute
      {{"m/d.obj"}, 400},                  // 5: d, the costliest job
      {{"m/x/../b.obj", "m/c.obj"}, 100},  // 6: bc
      {{"m/b.obj"}, 50},                   // 7: b alone is another set
  };
  EXPECT_EQ(count_job_groups(jobs), 4u);
  // Groups: a 300, bc 300, d 400, b 50. d -> 0, a -> 1, bc -> 2 (the file's order among equals), b -> 1.
  const auto parts = split_jobs(jobs, 3);
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts[0], (std::vector<std::size_t>{5}));
  EXPECT_EQ(parts[1], (std::vector<std::size_t>{0, 2, 4, 7}));
  EXPECT_EQ(parts[2], (std::vector<std::size_t>{1, 3, 6}));
  // One part: everything, in file order.
  EXPECT_EQ(split_jobs(jobs, 1)[0], (std::vector<std::size_t>{0, 1, 2, 3, 4, 5, 6, 7}));
  // More parts than groups: the last get none.
  const auto many = split_jobs(jobs, 6);
  EXPECT_TRUE(many[4].empty() && many[5].empty());
  std::size_t total = 0;
  for (const auto& p : many) total += p.size();
  EXPECT_EQ(total, jobs.size());
}

// The same file gives the same split whatever the thread count, the folder the command runs in and
// the spelling of the jobs file's path; the fingerprint is the file's bytes'.
TEST(BatchShard, TheSplitIsTheFilesAlone) {
  const std::string dir = test::scratch_dir();
  std::filesystem::create_directories(dir + "/farm/out");
  test::write_file(dir + "/farm/jobs.json", write_six_jobs(dir));
  std::vector<ShardJob> jobs;
  for (int i = 0; i < 40; ++i) jobs.push_back({{"h" + std::to_string(i % 13) + ".obj"}, std::uint64_t(1 + (i * 7919) % 31)});
  const auto first = split_jobs(jobs, 5);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(split_jobs(jobs, 5), first);
  const std::string runs[] = {"--batch farm/jobs.json --threads 1 --shard 1/3 --report p.json",
                              "--batch " + dir + "/farm/jobs.json --threads 2 --shard 1/3 --report p.json",
                              "--batch ./farm/../farm/jobs.json --shard 1/3 --report p.json"};
  for (const std::string& args : runs) {
    const test::CliRun r = run_nmbake(args, "", dir);
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json p = read_json(dir + "/p.json");
    EXPECT_EQ(p["shard"]["jobs"], nlohmann::json({2, 6})) << args;
    EXPECT_EQ(p["shard"]["jobs_file"], jobs_file_fingerprint(test::read_file(dir + "/farm/jobs.json")));
  }
  EXPECT_EQ(jobs_file_fingerprint(""), "fnv1a64:cbf29ce484222325");
  EXPECT_EQ(jobs_file_fingerprint("a"), "fnv1a64:af63dc4c8601ec8c");
}

TEST(BatchShard, AWrongShardIsRefused) {
  const std::string dir = test::scratch_dir();
  std::filesystem::create_directories(dir + "/farm/out");
  test::write_file(dir + "/farm/jobs.json", write_six_jobs(dir));
  struct Case {
    std::string args, message;
  };
  const Case cases[] = {
      {"--batch farm/jobs.json --shard 3/2", "--shard 3/2: part I must be 0 to N-1 (1)"},
      {"--batch farm/jobs.json --shard 2/2", "--shard 2/2: part I must be 0 to N-1 (1)"},
      {"--batch farm/jobs.json --shard 0/0", "--shard 0/0: N, the number of parts, must be 1 to 1000000"},
      {"--batch farm/jobs.json --shard -1/2", "--shard takes I/N"},
      {"--batch farm/jobs.json --shard=-1/2", "--shard takes I/N"},
      {"--batch farm/jobs.json --shard a/b", "--shard takes I/N, part I (0 to N-1) of N parts"},
      {"--batch farm/jobs.json --shard 1", "got '1'"},
      {"--batch farm/jobs.json --shard 1/", "got '1/'"},
      {"--batch farm/jobs.json --shard /2", "got '/2'"},
      {"--batch farm/jobs.json --shard +1/2", "got '+1/2'"},
      {"--batch farm/jobs.json --shard '1 /2'", "got '1 /2'"},
      {"--batch farm/jobs.json --shard 1/2/3", "got '1/2/3'"},
      {"--batch farm/jobs.json --shard 1/99999999999", "got '1/99999999999'"},
      {"--batch farm/jobs.json --shard", "--batch: --shard: 1 required TEXT missing"},
      {"--shard 0/2", "--shard applies to --batch"},
      {"meshes/low.obj meshes/A.obj -o x.png --shard 0/2", "--shard applies to --batch"},
      {"--batch farm/jobs.json --shard 0/2 -o x.json", "-o applies to --merge-reports"},
  };
  for (const Case& c : cases) {
    const test::CliRun r = run_nmbake("--report p.json " + c.args, "", dir);
    EXPECT_EQ(r.code, 1) << c.args << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, "error: ")) << c.args << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, c.message)) << c.args << "\n" << r.err;
    EXPECT_EQ(lines(r.err), 1u) << c.args << "\n" << r.err;
    EXPECT_FALSE(test::exists(dir + "/p.json")) << c.args;
    EXPECT_FALSE(test::exists(dir + "/farm/out/a.png")) << c.args;
  }
  const std::string help = run_nmbake("--batch --help", "", dir).out;
  for (const char* option : {"--shard", "--merge-reports", "-o,--output"}) EXPECT_TRUE(contains(help, option)) << help;
  EXPECT_TRUE(contains(run_nmbake("--help", "", dir).out, "--merge-reports part*.json -o batch.json"));
}

// More parts than groups: a part with no job bakes nothing, says so and writes its empty report; the
// merge of all of them is still the whole.
TEST(BatchShard, AnEmptyPartBakesNothing) {
  const std::string dir = test::scratch_dir();
  std::filesystem::create_directories(dir + "/farm/out");
  test::write_file(dir + "/farm/jobs.json", write_six_jobs(dir));
  const test::CliRun empty = run_nmbake("--batch farm/jobs.json --shard 5/6 --report p5.json", "", dir);
  EXPECT_EQ(empty.code, 0) << empty.err;
  EXPECT_EQ(lines(empty.err), 1u) << empty.err;
  EXPECT_TRUE(contains(empty.err,
                       "farm/jobs.json: --shard 5/6 gets no job (6 jobs in 4 groups sharing a high-poly); nothing "
                       "baked"))
      << empty.err;
  for (const char* name : kSixOutputs) EXPECT_FALSE(test::exists(dir + "/farm/out/" + name)) << name;
  const nlohmann::json r = read_json(dir + "/p5.json");
  EXPECT_TRUE(r["jobs"].empty());
  EXPECT_TRUE(r["shard"]["jobs"].empty());
  EXPECT_EQ(r["summary"]["jobs"], 0);
  EXPECT_EQ(r["summary"]["baked"], 0);
  std::string parts;
  for (int i = 0; i < 5; ++i) {
    const std::string n = std::to_string(i);
    ASSERT_EQ(run_nmbake("--batch farm/jobs.json --quiet --shard " + n + "/6 --report p" + n + ".json", "", dir).code, 0);
    parts += " p" + n + ".json";
  }
  const test::CliRun merge = run_nmbake("--merge-reports" + parts + " p5.json -o all.json --quiet", "", dir);
  ASSERT_EQ(merge.code, 0) << merge.err;
  EXPECT_TRUE(merge.out.empty()) << merge.out;
  const nlohmann::json all = read_json(dir + "/all.json");
  EXPECT_EQ(all["summary"]["jobs"], 6);
  EXPECT_EQ(all["summary"]["baked"], 6);
  EXPECT_EQ(all["jobs"].size(), 6u);
}

// A failed job fails its part and the merge alike (the first failure's exit code, as one process).
TEST(BatchShard, AFailedJobFailsTheMerge) {
  const std::string dir = test::scratch_dir();
  std::string jobs = write_six_jobs(dir);
  jobs.replace(jobs.find("../meshes/D.obj"), 15, "../meshes/none.obj");
  std::filesystem::create_directories(dir + "/farm/out");
  test::write_file(dir + "/farm/jobs.json", jobs);
  EXPECT_EQ(run_nmbake("--batch farm/jobs.json --quiet --shard 0/3 --report p0.json", "", dir).code, 0);
  EXPECT_EQ(run_nmbake("--batch farm/jobs.json --quiet --shard 1/3 --report p1.json", "", dir).code, 2);
  EXPECT_EQ(run_nmbake("--batch farm/jobs.json --quiet --shard 2/3 --report p2.json", "", dir).code, 0);
  const test::CliRun merge = run_nmbake("--merge-reports p0.json p1.json p2.json -o all.json", "", dir);
  EXPECT_EQ(merge.code, 2) << merge.err;
  const nlohmann::json all = read_json(dir + "/all.json");
  EXPECT_EQ(all["summary"]["failed"], 1);
  EXPECT_EQ(all["summary"]["baked"], 5);
  EXPECT_EQ(all["jobs"][5]["exit_code"], 2);
  EXPECT_TRUE(contains(all["jobs"][5]["error"].get<std::string>(), "none.obj"));
}

TEST(BatchShard, TheMergeRefusesPartsThatDoNotMakeOneBatch) {
  const std::string dir = test::scratch_dir();
  const std::string jobs = write_six_jobs(dir);
  std::filesystem::create_directories(dir + "/farm/out");
  std::filesystem::create_directories(dir + "/other/out");
  test::write_file(dir + "/farm/jobs.json", jobs);
  test::write_file(dir + "/other/jobs.json", jobs + " ");  // another file: one byte more
  const auto part = [&](const std::string& where, const std::string& shard, const std::string& report) {
    ASSERT_EQ(run_nmbake("--batch " + where + "/jobs.json --quiet --shard " + shard + " --report " + report, "", dir).code, 0);
  };
  part("farm", "0/2", "a0.json");
  part("farm", "1/2", "a1.json");
  part("farm", "0/3", "b0.json");
  part("other", "1/2", "o1.json");
  ASSERT_EQ(run_nmbake("--batch farm/jobs.json --quiet --report whole.json", "", dir).code, 0);
  test::write_file(dir + "/a0-copy.json", test::read_file(dir + "/a0.json"));
  nlohmann::json forged = read_json(dir + "/a1.json");
  forged["shard"]["jobs"].insert(forged["shard"]["jobs"].begin(), 1);  // part 0's first job, claimed too
  forged["jobs"].insert(forged["jobs"].begin(), read_json(dir + "/a0.json")["jobs"][0]);
  test::write_file(dir + "/forged.json", forged.dump());
  test::write_file(dir + "/broken.json", "{\"shard\": ");
  struct Case {
    std::string args;
    int code;
    std::string message;
  };
  const Case cases[] = {
      {"a0.json o1.json", 1, "o1.json: a part of another jobs file than a0.json"},
      {"a0.json b0.json", 1, "b0.json: part 0/3, but a0.json is a part of 2; merge the parts of one --shard N"},
      {"a0.json a0-copy.json a1.json", 1, "a0-copy.json: part 0/2 again (also a0.json)"},
      {"a0.json a0.json a1.json", 1, "a0.json: part 0/2 again (also a0.json)"},
      {"a1.json", 1, "--merge-reports: part 0/2 is missing"},
      {"a0.json forged.json", 1, "forged.json: job 1 is also in a0.json"},
      {"a0.json whole.json", 2, "whole.json: not a report of nmbake --batch --shard (no \"shard\")"},
      {"a0.json broken.json", 2, "broken.json: not valid JSON"},
      {"a0.json gone.json", 2, "gone.json: cannot read"},
  };
  for (const Case& c : cases) {
    const test::CliRun r = run_nmbake("--merge-reports " + c.args + " -o out.json", "", dir);
    EXPECT_EQ(r.code, c.code) << c.args << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, "error: " + c.message)) << c.args << "\n" << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_FALSE(test::exists(dir + "/out.json")) << c.args;
  }
  const Case usage[] = {
      {"--merge-reports a0.json a1.json", 1, "-o FILE, the batch report to write, is required"},
      {"--merge-reports a0.json a1.json -o a0.json", 1, "a0.json; nothing written"},
      {"--merge-reports a0.json a1.json -o out.json --shard 0/2", 1,
       "--merge-reports: --shard is an option of a batch's run (--batch), not of the merge"},
      {"--merge-reports a0.json a1.json -o out.json --batch farm/jobs.json", 1,
       "--merge-reports: --batch is an option of a batch's run"},
      {"--merge-reports -o out.json", 1, "--merge-reports"},
  };
  for (const Case& c : usage) {
    const std::string before = test::read_file(dir + "/a0.json");
    const test::CliRun r = run_nmbake(c.args, "", dir);
    EXPECT_EQ(r.code, c.code) << c.args << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, c.message)) << c.args << "\n" << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_FALSE(test::exists(dir + "/out.json")) << c.args;
    EXPECT_EQ(test::read_file(dir + "/a0.json"), before);
  }
  // The two parts of one batch do merge, into the one-process report's summary.
  ASSERT_EQ(run_nmbake("--merge-reports a1.json a0.json -o out.json", "", dir).code, 0);
  const nlohmann::json merged = read_json(dir + "/out.json"), whole = read_json(dir + "/whole.json");
  for (const char* key : {"jobs", "baked", "failed", "high_loads_saved", "bvh_reused"})
    EXPECT_EQ(merged["summary"][key], whole["summary"][key]) << key;
}

}  // namespace
}  // namespace nmbake
