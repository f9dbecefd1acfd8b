// Sections 3 and 6 of the bake bench, both whole nmbake commands: the 1M- and 4M-triangle sculpts
// (wall time, peak memory, the cost of the automatic cage and back-face filter), and far geometry
// with and without culling. Also the whole-command rows the scaling section prints.
#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_bake.h"
#include "bench_support.h"
#include "io/image_io.h"
#include "pipeline/udim.h"

namespace nmbake::bench {

namespace {

// CPU seconds (user + system) of the finished child processes so far.
double children_cpu_seconds() {
  rusage ru{};
  getrusage(RUSAGE_CHILDREN, &ru);
  return double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

// What the automatic cage and the back-face filter cost a whole command: the default command
// against the same command with back faces kept and the scene-wide rear distance it measured
// given (the baseline: the front is then measured for the whole scene by the same probe, the BVH
// culled twice, the rays cast without the filter, as nmbake did before both). Alternated
// default, baseline, default, ... over the rounds, so a change in the host's load falls on both.
struct RobustCost {
  std::vector<double> with, without;          // wall seconds per round
  std::vector<double> with_cpu, without_cpu;  // CPU seconds per round (less disturbed by other load)
  // The baseline's --rear: the scene-wide rear distance the first default run measured (report
  // cage.scene_rear); its front is measured for the whole scene, as nmbake did before.
  double rear = -1.0;
  bool ok = false;
  double ratio() const { return median(with) / median(without); }
};

RobustCost measure_robust_cost(const BenchRun& run, const std::string& command, const std::string& map) {
  const Args& args = run.args;
  RobustCost c;
  for (int round = 0; round < args.rounds; ++round) {
    const double cpu0 = children_cpu_seconds();
    const CommandRun a = run_nmbake(args.exe, command, run.report, 1);
    const double cpu1 = children_cpu_seconds();
    print_command_row("round " + std::to_string(round + 1) + ": default (automatic cage, back faces skipped)", a, map);
    if (!a.ok) return c;
    if (c.rear < 0.0) {
      const nlohmann::json* cage = find_key(a.report, "cage");
      if (!cage || !cage->contains("scene_rear")) return c;
      c.rear = (*cage)["scene_rear"].get<double>();
    }
    const std::string fixed = fmt(" --keep-backfaces --rear %.9g", c.rear);
    const CommandRun b = run_nmbake(args.exe, command + fixed, run.report, 1);
    const double cpu2 = children_cpu_seconds();
    print_command_row("round " + std::to_string(round + 1) + ": baseline" + fixed, b, map);
    if (!b.ok) return c;
    c.with.push_back(a.wall);
    c.without.push_back(b.wall);
    c.with_cpu.push_back(cpu1 - cpu0);
    c.without_cpu.push_back(cpu2 - cpu1);
  }
  c.ok = !c.with.empty();
  return c;
}

void print_robust_cost(BenchRun& run, const RobustCost& c) {
  const std::string what = "automatic cage + back-face filter cost (1M, 2048^2)";
  if (!c.ok) {
    std::printf("Automatic cage and back-face filter cost: a command failed (see stderr).\n\n");
    run.skip_target(what, "<= 1.10x", "command failed");
    return;
  }
  std::string rounds;
  for (std::size_t i = 0; i < c.with.size(); ++i) rounds += fmt(i ? ", %.2f" : "%.2f", c.with[i]) + fmt("/%.2f", c.without[i]);
  std::printf(
      "Automatic cage and back-face filter (suz_L4_x4, 1M triangles, 2048^2, 1 sample .png; the \"round\" rows above, run\n"
      "alternately): default median %.2f s, baseline median %.2f s (`--keep-backfaces --rear %.6g`, the scene-wide rear the\n"
      "default run measured, the front measured for the whole scene: the rule before both), default / baseline %.2fx (target\n"
      "<= 1.10x: %s).\nPer round, default/baseline s: %s.\n"
      "CPU seconds of the commands (all threads; less disturbed by other load), medians: %.2f / %.2f = %.2fx.\n\n",
      median(c.with), median(c.without), c.rear, c.ratio(), verdict(c.ratio() <= 1.10), rounds.c_str(), median(c.with_cpu),
      median(c.without_cpu), median(c.with_cpu) / median(c.without_cpu));
  run.add_target(what, "<= 1.10x",
                 fmt("%.2fx", c.ratio()) + fmt(" (%.2f", median(c.with)) + fmt(" s / %.2f s, medians of ", median(c.without)) +
                     std::to_string(c.with.size()) + " alternated)",
                 c.ratio() <= 1.10);
}

// The targets on the 4096^2 commands: wall time and peak memory, and peak memory against samples.
void judge_memory(BenchRun& run, const CommandRun& m1_4k_1, const CommandRun& m1_4k_16, const CommandRun& m4_4k_16) {
  const char* why = run.args.quick ? "--quick" : "command failed";
  if (m1_4k_16.ok) {
    run.add_target("1M tris 4096^2 16 samples, whole command", "< 60 s wall", fmt("%.2f s", m1_4k_16.wall), m1_4k_16.wall < 60.0);
    run.add_target("1M tris 4096^2 16 samples, peak memory", "< 1024 MiB", fmt("%.0f MiB", m1_4k_16.peak_mib()),
                   m1_4k_16.peak_mib() < 1024.0);
  } else {
    run.skip_target("1M tris 4096^2 16 samples, whole command and peak memory", "< 60 s, < 1 GiB", why);
  }
  if (m4_4k_16.ok) {
    run.add_target("4M tris 4096^2 16 samples, peak memory", "< 3072 MiB", fmt("%.0f MiB", m4_4k_16.peak_mib()),
                   m4_4k_16.peak_mib() < 3072.0);
  } else {
    run.skip_target("4M tris, peak memory", "< 3 GiB", why);
  }
  if (m1_4k_1.ok && m1_4k_16.ok) {
    BakeOptions e1, e16;
    e1.width = e1.height = e16.width = e16.height = 4096;
    e16.samples = 16;
    const double grow = m1_4k_16.peak_mib() - m1_4k_1.peak_mib();
    std::printf(
        "Accumulation buffers vs samples (1M, 4096^2): peak %.0f MiB at 1 sample, %.0f MiB at 16 samples (%+.0f MiB); "
        "the bake's own buffer estimate (estimate_bake_bytes) %s vs %s.\n\n",
        m1_4k_1.peak_mib(), m1_4k_16.peak_mib(), grow, mib(double(estimate_bake_bytes(e1))).c_str(),
        mib(double(estimate_bake_bytes(e16))).c_str());
    run.add_target("peak memory does not grow with samples (1M, 4096^2)", "16-sample peak <= 1-sample peak + 5%",
                   fmt("%.0f", m1_4k_1.peak_mib()) + fmt(" -> %.0f MiB", m1_4k_16.peak_mib()),
                   m1_4k_16.peak_mib() <= 1.05 * m1_4k_1.peak_mib());
  } else {
    run.skip_target("peak memory does not grow with samples", "16-sample peak <= 1-sample peak + 5%", why);
  }
}

// The high-poly triangles a command's report says it culled, or null.
const nlohmann::json* culled_count(const CommandRun& r) {
  const nlohmann::json* c = find_key(r.report, "triangles_culled");
  return c ? c : find_key(r.report, "high_triangles_culled");
}

// The far scene's maps with and without culling, and what culling saved.
void compare_culling(BenchRun& run, const Scenes& scenes, const CommandRun& cull, const CommandRun& keep) {
  const Image a = read_image(run.run_dir + "/far_cull.exr"), b = read_image(run.run_dir + "/far_keep.exr");
  std::size_t differ = 0;
  if (a.pixels.size() == b.pixels.size())
    for (std::size_t i = 0; i < a.pixels.size(); ++i) differ += std::memcmp(&a.pixels[i], &b.pixels[i], 4) != 0;
  const bool same = a.width == b.width && a.height == b.height && a.channels == b.channels && differ == 0;
  std::printf(
      "Saving from culling: wall %.2f -> %.2f s (%.2fx), bvh %.2f -> %.2f s, trace %.2f -> %.2f s, peak %.0f -> %.0f MiB. "
      "Maps with and without culling: %s (%zu of %zu float values differ).\n\n",
      keep.wall, cull.wall, keep.wall / cull.wall, keep.seconds("bvh"), cull.seconds("bvh"), keep.seconds("trace"),
      cull.seconds("trace"), keep.peak_mib(), cull.peak_mib(), same ? "bit-identical" : "DIFFERENT", differ, a.pixels.size());
  run.add_target("far geometry: map with culling = map with --no-cull", "bit-identical pixels",
                 same ? "identical" : std::to_string(differ) + " values differ", same);
  // The copies' triangles: the far scene's count minus torus_s3's; all of them are out of reach.
  const std::size_t far_tris = high_tris(keep) - scenes.t3_high.triangle_count();
  const nlohmann::json* c = culled_count(cull);
  const long long n_culled = c ? c->get<long long>() : -1;
  run.add_target("far geometry: the far copies left out of the BVH", "culled >= " + std::to_string(far_tris) + " (the 3 copies)",
                 c ? std::to_string(n_culled) + " culled" : std::string("not reported"),
                 c && n_culled >= static_cast<long long>(far_tris));
  run.targets.push_back({"far geometry: saving from culling (no figure set)", "measured",
                         fmt("wall %.2fx", keep.wall / cull.wall) +
                             fmt(", bvh %.2fx", keep.seconds("bvh") / std::max(1e-3, cull.seconds("bvh"))) +
                             fmt(", peak %+.0f MiB", cull.peak_mib() - keep.peak_mib()),
                         "-"});
}

}  // namespace

void print_command_header() {
  std::printf(
      "| command | high tris | wall s | load/prepare/bvh/distances/trace/padding/write s | peak memory | map hash |\n"
      "|---|---|---|---|---|---|\n");
}

std::size_t high_tris(const CommandRun& r) {
  const nlohmann::json* h = find_key(r.report, "high_mesh");
  return h && h->contains("triangles") ? (*h)["triangles"].get<std::size_t>() : 0;
}

std::string map_hash_of(const std::string& path) {
  const std::string token = "<UDIM>";
  const std::size_t at = path.find(token);
  if (at != std::string::npos) {  // a map per tile: each tile's number and hash
    std::string all;
    for (int tile = kUdimFirst; tile <= udim_number(kUdimColumns - 1, kUdimRows - 1); ++tile) {
      const std::string file = path.substr(0, at) + std::to_string(tile) + path.substr(at + token.size());
      if (!std::filesystem::exists(file)) continue;
      const std::string h = map_hash_of(file);
      if (h.rfind("unreadable", 0) == 0) return h;
      all += (all.empty() ? "" : " ") + std::to_string(tile) + ":" + h;
    }
    return all.empty() ? "unreadable: no tile of " + path : all;
  }
  try {
    return hex(pixel_hash(read_image(path).pixels));
  } catch (const std::exception& e) {
    return std::string("unreadable: ") + e.what();
  }
}

void print_command_row(const std::string& label, const CommandRun& r, const std::string& map) {
  if (!r.ok) {
    std::printf("| %s | command failed (see stderr) | | | | |\n", label.c_str());
  } else {
    std::printf("| %s | %zu | %.2f | %s | %.0f MiB | %s |\n", label.c_str(), high_tris(r), r.wall, r.stages().c_str(),
                r.peak_mib(), map_hash_of(map).c_str());
  }
  flush();
}

CommandRun run_command_row(const BenchRun& run, const std::string& label, const std::string& inputs, const std::string& map,
                           const std::string& options, int reps) {
  const std::string path = run.run_dir + "/" + map;
  const CommandRun r = run_nmbake(run.args.exe, inputs + " -o " + path + " " + options, run.report, reps);
  print_command_row(label, r, path);
  return r;
}

// 3. Whole commands on the 1M- and 4M-triangle sculpts.
CommandRun run_whole_commands(BenchRun& run, const Scenes& scenes) {
  const Args& args = run.args;
  std::printf("## 3. End to end: whole nmbake commands (wall = the process, stage seconds and peak memory from --report)\n\n");
  std::printf("Load average %s.\n\n", load_average().c_str());
  std::printf(
      "1-sample commands are the best of %d runs; 16-sample commands run once; the \"round\" rows are one run each,\n"
      "the default command and the baseline alternated (summary below the table).\n\n",
      args.rounds);
  print_command_header();
  const std::string m1 = scenes.s4 + "/low.obj " + scenes.m1_ply;
  const CommandRun m1_2k =
      run_command_row(run, "suz_L4_x4 (1M) 2048^2 1 sample .png", m1, "m1_2k.png", "--size 2048", args.rounds);
  run_command_row(run, "suz_L4_x4 (1M) 2048^2 1 sample .exr", m1, "m1_2k.exr", "--size 2048", args.rounds);
  if (m1_2k.ok)
    run.add_target("1M tris 2048^2 1 sample, whole command (.png)", "< 3 s wall", fmt("%.2f s", m1_2k.wall), m1_2k.wall < 3.0);
  const RobustCost cost =
      measure_robust_cost(run, m1 + " -o " + run.run_dir + "/m1_cost.png --size 2048", run.run_dir + "/m1_cost.png");
  CommandRun m1_4k_1, m1_4k_16, m4_4k_16;
  if (!args.quick) {
    m1_4k_1 = run_command_row(run, "suz_L4_x4 (1M) 4096^2 1 sample .png", m1, "m1_4k_1.png", "--size 4096", args.rounds);
    m1_4k_16 = run_command_row(run, "suz_L4_x4 (1M) 4096^2 16 samples .png", m1, "m1_4k_16.png", "--size 4096 --samples 16", 1);
    m4_4k_16 = run_command_row(run, "suz_L4_x16 (4M) 4096^2 16 samples .png", scenes.s4 + "/low.obj " + scenes.m4_ply,
                               "m4_4k_16.png", "--size 4096 --samples 16", 1);
  }
  std::printf("\n");
  print_robust_cost(run, cost);
  judge_memory(run, m1_4k_1, m1_4k_16, m4_4k_16);
  flush();
  return m1_2k;
}

// 6. Far geometry.
void run_far_geometry(BenchRun& run, const Scenes& scenes) {
  const Args& args = run.args;
  std::printf("## 6. Far geometry (torus_s3 low + torus_s3_far4 high, 2048^2 1 sample .exr, whole commands)\n\n");
  std::printf("Load average %s.\n\n", load_average().c_str());
  const bool cull_supported = command_output(args.exe + " --help 2>&1").find("--no-cull") != std::string::npos;
  if (!cull_supported)
    std::printf("culling not available (`nmbake --help` lists no --no-cull): only the default run is measured.\n\n");
  print_command_header();
  const std::string t3_low = scenes.t3 + "/low.obj ";
  const CommandRun base = run_command_row(run, "torus_s3 alone (no far geometry)", t3_low + scenes.t3 + "/high.ply", "t3.exr",
                                          "--size 2048", args.rounds);
  const CommandRun cull = run_command_row(run, std::string("torus_s3_far4, default") + (cull_supported ? " (culling)" : ""),
                                          t3_low + scenes.far_ply, "far_cull.exr", "--size 2048", args.rounds);
  CommandRun keep;
  if (cull_supported)
    keep = run_command_row(run, "torus_s3_far4, --no-cull", t3_low + scenes.far_ply, "far_keep.exr", "--size 2048 --no-cull",
                           args.rounds);
  std::printf("\n");
  auto culled = [](const CommandRun& r) {
    const nlohmann::json* c = culled_count(r);
    return c ? std::to_string(c->get<long long>()) : std::string("not reported");
  };
  if (cull.ok) std::printf("High-poly triangles culled (report): default %s", culled(cull).c_str());
  if (keep.ok) std::printf(", --no-cull %s", culled(keep).c_str());
  std::printf(".\n\n");
  if (cull.ok && keep.ok) {
    compare_culling(run, scenes, cull, keep);
  } else {
    run.skip_target("far geometry: culling identical and faster", "bit-identical, faster",
                    cull_supported ? "command failed" : "culling not available");
  }
  if (base.ok && cull.ok)
    std::printf(
        "Against torus_s3 alone, the far scene's default map is %s (the far copies widen the bounding box the bake re-centres on "
        "and the diagonal auto distances scale with, so this need not be identical).\n\n",
        map_hash_of(run.run_dir + "/t3.exr") == map_hash_of(run.run_dir + "/far_cull.exr") ? "bit-identical" : "different");
  flush();
}

}  // namespace nmbake::bench
