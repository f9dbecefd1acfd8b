// Sections 4 and 5 of the bake bench: nmbake's mesh loaders against OpenMesh's readers on the same
// files, and how the bake scales with threads, high-poly triangles and texels (and, last, each stage's serial
// share at 1 and 2 threads with Amdahl's prediction at 16: bench_serial.cpp).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_bake.h"
#include "bench_support.h"
#include "io/mesh_io.h"

namespace nmbake::bench {

namespace {

namespace fs = std::filesystem;

struct LoadRow {
  std::string path, label;
  double goal;  // seconds
};

// One row of section 4 (and its target); returns the note on OpenMesh's reader, empty when it failed.
std::string run_load_row(BenchRun& run, const LoadRow& row) {
  double ours = 1e30, theirs = 1e30, assimp = 1e30;
  std::size_t tris = 0, om_faces = 0;
  MeshLoadInfo info;
  for (int round = 0; round < run.args.rounds; ++round) {
    const auto t0 = Clock::now();
    const Mesh m = load_mesh(row.path, {}, &info);
    ours = std::min(ours, since(t0));
    tris = m.triangle_count();
    const OpenMeshRead om = openmesh_read(row.path);
    if (om.seconds >= 0) theirs = std::min(theirs, om.seconds), om_faces = om.faces;
    const OpenMeshRead ai = assimp_read(row.path);
    if (ai.seconds >= 0) assimp = std::min(assimp, ai.seconds);
  }
  const bool om_ok = theirs < 1e29;
  const bool ai_ok = assimp < 1e29;
  std::printf("| %s %s | %.1f | %zu | %.3f (%s) | %s | %s | %s | %s | < %.1f s | %s |\n", fs::path(row.path).filename().c_str(),
              row.label.c_str(), double(fs::file_size(row.path)) / 1048576.0, tris, ours, info.format.c_str(),
              om_ok ? fmt("%.3f", theirs).append(" (").append(std::to_string(om_faces)).append(" faces)").c_str() : "read failed",
              om_ok ? fmt("%.1fx", theirs / ours).c_str() : "-", ai_ok ? fmt("%.3f", assimp).c_str() : "read failed",
              ai_ok ? fmt("%.1fx", assimp / ours).c_str() : "-", row.goal, verdict(ours < row.goal));
  run.add_target("load 1M tris " + row.label, fmt("< %.1f s", row.goal), fmt("%.3f s", ours), ours < row.goal);
  flush();
  if (!om_ok) return "";
  return "- " + row.label + ": OpenMesh's read_mesh alone takes " + fmt("%.2f s", theirs) + " (target " +
         fmt("%.1f s", row.goal) + "), so OpenMesh's reader " + (theirs < row.goal ? "would not be" : "would be") +
         " the bottleneck; nmbake's load_mesh (format " + info.format + ") takes " + fmt("%.2f s", ours) + ", " +
         fmt("%.1fx", theirs / ours) + " faster.\n";
}

void run_thread_scaling(BenchRun& run, const Scenes& scenes) {
  std::printf("### Threads (torus_s3 2048^2 1 sample, in process; 1 and 2 threads alternate in every round)\n\n");
  std::printf("Load average %s.\n\n", load_average().c_str());
  const Mesh &t3_low = scenes.t3_low, &t3_high = scenes.t3_high;
  const Recorded rec = record(t3_low, t3_high, 2048, 1);
  raycast::Scene scene(&rec.positions[0].x, rec.positions.size(), t3_high.position_index.data(), t3_high.triangle_count());
  Timing trace[2], bare[2];
  for (int round = 0; round < run.args.rounds; ++round)
    for (int t = 1; t <= 2; ++t) {
      BakeOptions o = rec.options;
      o.threads = t;
      const BakeResult r = bake_normal_map(t3_low, t3_high, nullptr, o);
      trace[t - 1].keep_min(r.stats.trace.seconds, r.stats.trace.cpu_seconds);
      bare[t - 1].keep_min(bare_loop(scene, rec.rays, t, Bare::arrays));
    }
  std::printf("| threads | trace s (CPU) | bare 8-packet from arrays s (CPU) |\n|---|---|---|\n");
  for (int t = 0; t < 2; ++t)
    std::printf("| %d | %.3f (%.3f) | %.3f (%.3f) |\n", t + 1, trace[t].wall, trace[t].cpu, bare[t].wall, bare[t].cpu);
  const double speedup = trace[0].wall / trace[1].wall;
  std::printf(
      "\nSpeed-up 1 -> 2 threads (wall): trace stage %.2fx, bare loop %.2fx (target >= 1.8x on the trace stage: %s).\n"
      "CPU seconds 2 threads / 1 thread (work added by going parallel; 1.00 = none): trace stage %.2f, bare loop %.2f.\n"
      "Wall speed-up needs both cores free: see the load average above.\n\n",
      speedup, bare[0].wall / bare[1].wall, verdict(speedup >= 1.8), trace[1].cpu / trace[0].cpu, bare[1].cpu / bare[0].cpu);
  run.add_target("trace stage 2 threads vs 1 (torus_s3 2048^2)", ">= 1.8x", fmt("%.2fx", speedup), speedup >= 1.8);
  flush();
}

void run_triangle_scaling(const BenchRun& run, const Scenes& scenes, const CommandRun& m1_2k) {
  std::printf("### Triangle count (whole commands, suz family: same low-poly, 2048^2 1 sample .png)\n\n");
  print_command_header();
  const std::string s4_low = scenes.s4 + "/low.obj ";
  std::vector<CommandRun> rows;
  rows.push_back(run_command_row(run, "suz_L3 2048^2 1 sample .png", s4_low + scenes.s3 + "/high.ply", "s3.png", "--size 2048",
                                 run.args.rounds));
  rows.push_back(run_command_row(run, "suz_L4 2048^2 1 sample .png", s4_low + scenes.s4 + "/high.ply", "s4.png", "--size 2048",
                                 run.args.rounds));
  if (m1_2k.wall > 0.0) {  // section 3 ran it
    rows.push_back(m1_2k);
    print_command_row("suz_L4_x4 (1M) 2048^2 1 sample .png (row of section 3)", m1_2k, run.run_dir + "/m1_2k.png");
  } else {  // section 3 not asked for (--sections): the row run here
    rows.push_back(run_command_row(run, "suz_L4_x4 (1M) 2048^2 1 sample .png", s4_low + scenes.m1_ply, "m1_2k.png", "--size 2048",
                                   run.args.rounds));
  }
  if (!run.args.quick)
    rows.push_back(run_command_row(run, "suz_L4_x16 (4M) 2048^2 1 sample .png", s4_low + scenes.m4_ply, "m4_2k.png",
                                   "--size 2048", run.args.rounds));
  std::printf(
      "\n| high tris | x tris | wall s | x wall | bvh s | x bvh | trace s | x trace | peak MiB "
      "|\n|---|---|---|---|---|---|---|---|---|\n");
  const CommandRun* prev = nullptr;
  for (const CommandRun& r : rows) {
    if (!r.ok) continue;
    auto x = [&](double now, double before) { return prev ? fmt("%.2fx", now / before) : std::string("-"); };
    std::printf("| %zu | %s | %.2f | %s | %.2f | %s | %.2f | %s | %.0f |\n", high_tris(r),
                x(double(high_tris(r)), prev ? double(high_tris(*prev)) : 1.0).c_str(), r.wall,
                x(r.wall, prev ? prev->wall : 1.0).c_str(), r.seconds("bvh"),
                x(r.seconds("bvh"), prev ? prev->seconds("bvh") : 1.0).c_str(), r.seconds("trace"),
                x(r.seconds("trace"), prev ? prev->seconds("trace") : 1.0).c_str(), r.peak_mib());
    prev = &r;
  }
  std::printf("\n(x = against the row above.)\n\n");
  flush();
}

void run_texel_scaling(const BenchRun& run, const Scenes& scenes) {
  std::printf("### Texel count (torus_s3, 1 sample, in process, auto distances)\n\n");
  std::printf(
      "| size | covered texels | rays | prepare s | bvh s | distances s | trace s (CPU) | padding s | bake s | ns per ray | x "
      "trace |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|\n");
  double first_trace = 0;
  for (int size : run.args.quick ? std::vector<int>{1024, 2048} : std::vector<int>{1024, 2048, 4096}) {
    BakeOptions o;
    o.width = o.height = size;
    BakeStats best;
    double best_total = 1e30;
    Timing trace;
    for (int round = 0; round < run.args.rounds; ++round) {
      const auto t0 = Clock::now();
      const BakeResult r = bake_normal_map(scenes.t3_low, scenes.t3_high, nullptr, o);
      const double total = since(t0);
      trace.keep_min(r.stats.trace.seconds, r.stats.trace.cpu_seconds);
      if (total < best_total) best_total = total, best = r.stats;
    }
    if (first_trace == 0) first_trace = trace.wall;
    std::printf("| %d^2 | %zu | %.2fM | %.3f | %.3f | %.3f | %.3f (%.3f) | %.3f | %.3f | %.0f | %.2fx |\n", size,
                best.trace.texels_covered, double(best.trace.rays) / 1e6, best.prepare.seconds, best.bvh.seconds,
                best.distances.seconds, trace.wall, trace.cpu, best.pad.seconds, best_total,
                1e9 * trace.wall / double(best.trace.rays), trace.wall / first_trace);
    flush();
  }
  std::printf("\n(stage columns from the fastest whole bake; trace = best of the rounds; x trace = against 1024^2.)\n\n");
}

}  // namespace

// 4. Loading: nmbake's loaders against OpenMesh's and Assimp's readers on the same files.
void run_loading(BenchRun& run, const Scenes& scenes) {
  std::printf("## 4. Loading 1M triangles (best of %d; files in the page cache)\n\nLoad average %s.\n\n", run.args.rounds,
              load_average().c_str());
  std::printf(
      "| file | MiB | triangles | nmbake load_mesh s (reader) | OpenMesh read_mesh s | OpenMesh / nmbake | Assimp ReadFile s | "
      "Assimp / nmbake | target | verdict |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n");
  std::string openmesh_note;
  for (const LoadRow& row : {LoadRow{scenes.m1_ply, "binary PLY", 0.5}, LoadRow{scenes.m1_obj, "OBJ", 2.0}})
    openmesh_note += run_load_row(run, row);
  std::printf(
      "\nnmbake reads OBJ and PLY with its own parsers (mesh_io_obj.cpp, mesh_io_ply.cpp) into its flat Mesh; OFF and STL go\n"
      "through OpenMesh's readers, glTF, FBX, DAE and the rest through Assimp (ReadFile alone timed here, without\n"
      "nmbake's placing and welding).\n%s\n",
      openmesh_note.c_str());
}

// 5. Scaling.
void run_scaling(BenchRun& run, const Scenes& scenes, const CommandRun& m1_2k) {
  std::printf("## 5. Scaling\n\n");
  run_thread_scaling(run, scenes);
  run_triangle_scaling(run, scenes, m1_2k);
  run_texel_scaling(run, scenes);
  run_serial_shares(run, scenes);
}

}  // namespace nmbake::bench
