// nmbake --batch (issue 20, item 6): many jobs in one process, each baking what its own command
// line would; one high-poly loaded once for the jobs that share it; a failing job reported while
// the others run; a wrong file or two jobs writing one output stop everything before any bake.
#include <algorithm>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

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
  EXPECT_TRUE(contains(help.out, "--batch TEXT REQUIRED")) << help.out;
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

}  // namespace
}  // namespace nmbake
