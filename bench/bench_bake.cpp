// The bake bench (issues 2 and 6): one run prints, as Markdown tables, the tracing stage against a
// bare Embree loop over the same rays (same process, same threads), BVH build quality, whole
// commands on 1M and 4M triangles with peak memory and what the automatic cage and back-face filter
// cost them, loading against OpenMesh's readers, thread / triangle / texel scaling, and far-geometry
// culling, degenerate floods (duplicate faces, huge polygons), batches, PNG settings, and the whole
// command side by side with Blender's Cycles bake of the same pair; every target with its measured
// value and MET / NOT MET. Everything printed is measured in this run; nothing asserts (not a test).
//
//   bench_bake SHARED_DATA NMBAKE_EXE [--rounds N] [--trace-rounds N] [--quick] [--scratch DIR] [--sections LIST]
//                [--ao-size N]
//
// --rounds N: each timed figure is the best of N rounds (default 3; 1 with --quick).
// --trace-rounds N: rounds of section 1's bake-then-bare-loops comparison at 1 and 4 samples
// (default 7; --rounds with --quick): the ratio judged there is the closest to the noise-free one
// with more rounds, and those rounds cost little. 16 samples take --rounds.
// --quick: fewer rows (1 sample only, no 4096^2 or 4M-triangle commands) as a smoke check.
// --sections LIST: only these sections (comma-separated numbers; 0, the scenes, always runs).
// --ao-size N: the map side of section 12's AO rows (default 2048; Blender's AO bake takes minutes there).
// --scratch DIR: where the generated meshes are written once and reused (default
// $TMPDIR/nmbake-bench); each run's maps and reports go to a subfolder removed at the end.
//
// The sections live in bench_tracing.cpp (1, 2), bench_commands.cpp (3, 6), bench_scaling.cpp
// (4, 5; 5's serial shares in bench_serial.cpp), bench_floods.cpp (7), bench_batch.cpp (8), bench_png.cpp (9), bench_blender.cpp
// (10, with blender_bake.py; Blender is $NMBAKE_BLENDER or `blender` on PATH, else nmbake's rows alone) bench_memory.cpp (11) and
// bench_maps.cpp (12, texture sets); this file parses the arguments, prints the machine, generates the scenes (0) and prints the
// targets. `bench_bake --measure-child CMD ARGS...` is not for people: section 10 starts each
// command through it (bench_bake.h).
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "bench_bake.h"
#include "bench_support.h"
#include "io/mesh_io.h"
#include "io/text_file.h"
#include "tests/build_paths.h"

using namespace nmbake::bench;
namespace fs = std::filesystem;

namespace nmbake::bench {

const char* verdict(bool met) { return met ? "MET" : "NOT MET"; }

void flush() { std::fflush(stdout); }

void BenchRun::add_target(const std::string& what, const std::string& goal, const std::string& measured, bool met) {
  targets.push_back({what, goal, measured, verdict(met)});
}

void BenchRun::skip_target(const std::string& what, const std::string& goal, const std::string& why) {
  targets.push_back({what, goal, "not measured: " + why, "-"});
}

// Scenes made once from the shared sculpts and reused by later runs.
void generate_scenes(const BenchRun& run, Scenes& scenes) {
  const Args& args = run.args;
  std::printf("## 0. Generated scenes (in %s)\n\n| file | MiB | made |\n|---|---|---|\n", args.scratch.c_str());
  scenes.m1_ply = args.scratch + "/suz_L4_x4.ply";
  scenes.m1_obj = args.scratch + "/suz_L4_x4.obj";
  scenes.m4_ply = args.scratch + "/suz_L4_x16.ply";
  scenes.far_ply = args.scratch + "/torus_s3_far4.ply";
  const std::string &m1_ply = scenes.m1_ply, &m1_obj = scenes.m1_obj, &m4_ply = scenes.m4_ply, &far_ply = scenes.far_ply;
  LoadOptions low_options;
  low_options.require_uvs = true;
  scenes.t3_low = load_mesh(scenes.t3 + "/low.obj", low_options);
  scenes.t3_high = load_mesh(scenes.t3 + "/high.ply");
  const Mesh& t3_high = scenes.t3_high;
  // Far copies: translated by 4 scene diagonals, placed symmetrically so the scene's bounding-box
  // centre (the bake re-centres on it) stays where it was.
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : t3_high.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  const float far_d = 4.0f * glm::length(hi - lo);
  auto make = [&](const std::string& path, auto&& build) {
    const auto t0 = Clock::now();
    const bool exists = fs::exists(path);
    if (!exists) build();
    std::printf("| %s | %.1f | %s |\n", fs::path(path).filename().c_str(), double(fs::file_size(path)) / 1048576.0,
                exists ? "reused from an earlier run" : fmt("this run, %.1f s", since(t0)).c_str());
    flush();
  };
  if (!fs::exists(m1_ply) || !fs::exists(m1_obj) || !fs::exists(m4_ply)) {
    const Mesh m1 = subdivide(load_mesh(scenes.s4 + "/high.ply"));
    make(m1_ply, [&] { write_binary_ply(m1_ply, m1); });
    make(m1_obj, [&] { write_obj(m1_obj, m1); });
    make(m4_ply, [&] { write_binary_ply(m4_ply, subdivide(m1)); });
  } else {
    for (const std::string& p : {m1_ply, m1_obj, m4_ply}) make(p, [] {});
  }
  // suz_L4's low-poly on UDIM tiles 1001, 1002, 1011 and 1012: each triangle's UVs in the quadrant
  // of the unit square holding its UV centroid, scaled by 2 into that quadrant's tile (islands cut
  // by a quadrant's edge reach a little beyond their tile: a warning, and the bake cuts them there).
  scenes.udim_low = args.scratch + "/suz_L4_udim4.obj";
  make(scenes.udim_low, [&] {
    const Mesh low = load_mesh(scenes.s4 + "/low.obj", low_options);
    Mesh tiled;
    tiled.positions = low.positions;
    tiled.position_index = low.position_index;
    for (std::size_t t = 0; t < low.triangle_count(); ++t) {
      const glm::vec2 c = (low.corner_uv(t, 0) + low.corner_uv(t, 1) + low.corner_uv(t, 2)) / 3.0f;
      const glm::vec2 q(c.x >= 0.5f ? 1.0f : 0.0f, c.y >= 0.5f ? 1.0f : 0.0f);
      for (int k = 0; k < 3; ++k) {
        tiled.uv_index.push_back(std::uint32_t(tiled.uvs.size()));
        tiled.uvs.push_back((low.corner_uv(t, k) - 0.5f * q) * 2.0f + q);
      }
    }
    write_text_atomically(scenes.udim_low, obj_text(tiled, "suz_L4 low.obj, UV quadrants on UDIM tiles 1001 1002 1011 1012"));
  });
  make(far_ply, [&] {
    write_binary_ply(far_ply, with_copies(t3_high, {glm::vec3(far_d), glm::vec3(-far_d), glm::vec3(far_d, -far_d, 0)}));
  });
  std::printf(
      "\nsuz_L4_x4 = suz_L4 high subdivided once (1 -> 4 triangles), suz_L4_x16 = twice; torus_s3_far4 = torus_s3 high "
      "plus 3 copies translated by %.2f (4 scene diagonals) along (1,1,1), (-1,-1,-1), (1,-1,0); suz_L4_udim4 = suz_L4 "
      "low with each UV quadrant scaled onto its own UDIM tile (1001, 1002, 1011, 1012).\n\n",
      double(far_d));
  flush();
}

}  // namespace nmbake::bench

namespace {}  // namespace

bool Args::runs(int section) const {
  if (sections.empty()) return true;
  const std::string list = "," + sections + ",";
  return list.find("," + std::to_string(section) + ",") != std::string::npos;
}

namespace {

Args parse_args(int argc, char** argv) {
  Args a;
  int positional = 0;
  bool rounds_given = false, trace_rounds_given = false;
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    if (s == "--quick") {
      a.quick = true;
    } else if (s == "--rounds" && i + 1 < argc) {
      a.rounds = std::max(1, std::atoi(argv[++i]));
      rounds_given = true;
    } else if (s == "--trace-rounds" && i + 1 < argc) {
      a.trace_rounds = std::max(1, std::atoi(argv[++i]));
      trace_rounds_given = true;
    } else if (s == "--sections" && i + 1 < argc) {
      a.sections = argv[++i];
    } else if (s == "--ao-size" && i + 1 < argc) {
      a.ao_size = std::max(16, std::atoi(argv[++i]));
    } else if (s == "--scratch" && i + 1 < argc) {
      a.scratch = argv[++i];
    } else if (!s.empty() && s[0] != '-' && positional < 2) {
      (positional++ == 0 ? a.shared : a.exe) = s;
    } else {
      std::fprintf(stderr,
                   "usage: bench_bake SHARED_DATA NMBAKE_EXE [--rounds N] [--trace-rounds N] [--quick] [--scratch DIR] "
                   "[--sections 3,9] [--ao-size N]\n");
      std::exit(1);
    }
  }
  if (a.quick && !rounds_given) a.rounds = 1;
  if (a.quick && !trace_rounds_given) a.trace_rounds = a.rounds;
  return a;
}

void print_machine(const BenchRun& run) {
  const Args& args = run.args;
  const Machine machine = describe_machine(nmbake::build::source_dir());
  std::printf("# nmbake bench\n\n");
  std::printf("- date: %s\n", machine.date.c_str());
  std::printf("- machine: %d cores, %s (%s), %.1f GiB RAM; load average at start %s\n", machine.cores, machine.cpu_model.c_str(),
              machine.simd.c_str(), machine.memory_gib, load_average().c_str());
  std::printf("- commit: %s; %s\n", machine.commit.c_str(), command_output(args.exe + " --version 2>&1").c_str());
  std::printf("- mode: %s, each timed figure the best of %d round%s; in-process bakes and bare loops use %d threads\n",
              args.quick ? "--quick" : "full", args.rounds, args.rounds == 1 ? "" : "s", run.threads);
  std::printf("- shared data %s, scratch %s\n\n", args.shared.c_str(), args.scratch.c_str());
  flush();
}

void print_targets(const BenchRun& run, Clock::time_point start) {
  std::printf("## Targets\n\n| target | goal | measured | verdict |\n|---|---|---|---|\n");
  for (const Target& t : run.targets)
    std::printf("| %s | %s | %s | %s |\n", t.what.c_str(), t.goal.c_str(), t.measured.c_str(), t.verdict.c_str());
  std::printf("\nBench run time %.0f s; load average at the end %s.\n", since(start), load_average().c_str());
  flush();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == kMeasureChild) return measure_child(argv + 2);
  BenchRun run;
  run.args = parse_args(argc, argv);
  const Args& args = run.args;
  const auto start = Clock::now();
  run.threads = std::max(1, int(std::thread::hardware_concurrency()));
  Scenes scenes;
  scenes.t3 = args.shared + "/sculpts/torus_s3";
  scenes.s3 = args.shared + "/sculpts/suz_L3";
  scenes.s4 = args.shared + "/sculpts/suz_L4";
  for (const std::string& d : {scenes.t3, scenes.s3, scenes.s4})
    if (!fs::exists(d + "/high.ply") || !fs::exists(d + "/low.obj")) {
      std::fprintf(stderr, "bench: %s/{low.obj,high.ply} not found (the bench needs ../shared/data)\n", d.c_str());
      return 1;
    }
  fs::create_directories(args.scratch);
  run.run_dir = args.scratch + "/run-" + std::to_string(::getpid());
  fs::create_directories(run.run_dir);
  run.report = run.run_dir + "/report.json";

  print_machine(run);
  generate_scenes(run, scenes);
  if (args.runs(1) || args.runs(2)) {
    std::vector<QualityRow> quality_rows = run_tracing(run);
    run_bvh_quality(run, scenes, std::move(quality_rows));
  }
  CommandRun m1_2k;
  if (args.runs(3)) m1_2k = run_whole_commands(run, scenes);
  if (args.runs(4)) run_loading(run, scenes);
  if (args.runs(5)) run_scaling(run, scenes, m1_2k);
  if (args.runs(6)) run_far_geometry(run, scenes);
  if (args.runs(7)) run_floods(run, scenes);
  if (args.runs(8)) run_batch(run, scenes);
  if (args.runs(9)) run_png_settings(run, scenes);
  if (args.runs(10)) run_blender(run, scenes);
  if (args.runs(11)) run_memory(run, scenes);
  if (args.runs(12)) run_maps(run, scenes);
  print_targets(run, start);
  std::error_code ec;
  fs::remove_all(run.run_dir, ec);
  return 0;
}
