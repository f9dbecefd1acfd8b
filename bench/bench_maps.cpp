// Section 12 of the bake bench: the texture set's speed targets (issue 35), each measured in this
// run on the 1M-triangle pair (suz_L4's low.obj onto suz_L4_x4), 1 sample:
//   a. the cheap maps' cost: `--maps normal,height,position,curvature,object-id,material-id`
//      against the plain normal bake at 2048^2, whole commands (file writes included) alternated
//      over the rounds, medians and their ratio;
//   b. `--maps normal,ao --ao-rays 64` against Blender's Cycles AO bake of the same pair at 64
//      samples (blender_bake.py's ao mode, the same AO distance), alternated, at --ao-size (2048
//      by default), with Blender's own load / bake / save split;
//   c. the AO's tracing in the bake against a bare Embree loop over the same rays:
//      `bench_occlusion --from-bake SIZE` (built beside this program), its table and ratio.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bench_bake.h"
#include "bench_support.h"

namespace nmbake::bench {

namespace {

namespace fs = std::filesystem;

// The AO distance both bakers get: nmbake's automatic one on this pair (0.1 of the scene's
// bounding-box diagonal, 2.761), given explicitly so that Blender's world AO distance is the same.
constexpr const char* kAoDistance = "0.2761";
constexpr const char* kCheapMaps = "normal,height,position,curvature,object-id,material-id";

std::string rounds_text(const std::vector<double>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += fmt(i ? ", %.2f" : "%.2f", v[i]);
  return s;
}

void print_side(const std::string& what, const Side& s) {
  if (!s.ok()) std::printf("| %s | failed: %s | | |\n", what.c_str(), s.failed.c_str());
  else std::printf("| %s | %.2f | %.0f | %s |\n", what.c_str(), median(s.wall), median(s.rss), rounds_text(s.wall).c_str());
  flush();
}

// Blender's "blender-bake: load L bake B save S" lines of its log, as medians.
std::string blender_split(const std::string& log) {
  std::ifstream in(log);
  std::vector<double> load, bake, save;
  for (std::string line; std::getline(in, line);) {
    double l = 0, b = 0, s = 0;
    if (std::sscanf(line.c_str(), "blender-bake: load %lf bake %lf save %lf", &l, &b, &s) == 3)
      load.push_back(l), bake.push_back(b), save.push_back(s);
  }
  if (bake.empty()) return "";
  return fmt("load %.2f s, ", median(load)) + fmt("bake %.2f s, ", median(bake)) + fmt("save %.2f s", median(save));
}

// a. Plain normal bake against normal + the cheap maps.
void cheap_maps(BenchRun& run, const Scenes& scenes) {
  const std::string low = scenes.s4 + "/low.obj", dir = run.run_dir + "/";
  const std::vector<std::string> plain = {run.args.exe,          low,      scenes.m1_ply, "-o",
                                          dir + "set_plain.png", "--size", "2048",        "--quiet"};
  std::vector<std::string> set = {run.args.exe, low, scenes.m1_ply, "-o", dir + "set_<MAP>.png", "--size", "2048", "--quiet"};
  set.insert(set.end(), {"--maps", kCheapMaps});
  Side a, b;
  for (int round = 0; round < run.args.rounds; ++round) {
    run_side(run, a, plain, dir + "set_plain.log");
    run_side(run, b, set, dir + "set_cheap.log");
  }
  std::printf(
      "a. Cheap maps. 2048^2 .png, 1 sample, every core, whole commands (writes included) alternated over %d round%s: "
      "`nmbake LOW HIGH -o OUT.png --size 2048 --quiet` and the same with `-o OUT_<MAP>.png --maps %s`.\n\n",
      run.args.rounds, run.args.rounds == 1 ? "" : "s", kCheapMaps);
  std::printf("| command | median wall s | median max RSS MiB | per round wall s |\n|---|---|---|---|\n");
  print_side("normal", a);
  print_side("normal + height, position, curvature, object-id, material-id", b);
  const std::string what = "cheap maps (height, position, curvature, IDs) over the normal bake, 1M tris 2048^2";
  if (a.ok() && b.ok()) {
    const double ratio = median(b.wall) / median(a.wall);
    std::printf("| ratio (maps / normal) | %.3f | %.2f | |\n\n", ratio, median(b.rss) / median(a.rss));
    run.add_target(what, "<= +15%",
                   fmt("%+.0f%%", 100.0 * (ratio - 1.0)) + fmt(" (%.2f s", median(b.wall)) + fmt(" / %.2f s", median(a.wall)) +
                       ", whole commands, medians of " + std::to_string(a.wall.size()) + " alternated rounds)",
                   ratio <= 1.15);
  } else {
    std::printf("\n");
    run.skip_target(what, "<= +15%", "a command failed");
  }
  flush();
}

// b. nmbake's AO against Blender's.
void ao_against_blender(BenchRun& run, const Scenes& scenes) {
  const std::string size = std::to_string(run.args.ao_size), low = scenes.s4 + "/low.obj", dir = run.run_dir + "/";
  const std::vector<std::string> nm = {
      run.args.exe, low,         scenes.m1_ply, "-o", dir + "ao_<MAP>.png", "--size",    size,
      "--maps",     "normal,ao", "--ao-rays",   "64", "--ao-distance",      kAoDistance, "--quiet"};
  std::string why;
  std::string blender = find_blender(why);
  if (!blender.empty() && !fs::exists(blender_script())) why = blender_script() + " not found", blender.clear();
  std::vector<std::string> bl = {blender, "-b",       "--factory-startup", "--python-exit-code",
                                 "1",     "--python", blender_script(),    "--"};
  bl.insert(bl.end(), {low, scenes.m1_ply, dir + "ao_blender.png", size, "64", kBlenderExtrusion, "ao", kAoDistance});
  // Blender's AO bake takes minutes at 2048^2: one round each unless --rounds asks for more than 3.
  const int rounds = run.args.rounds > 3 ? run.args.rounds : 1;
  Side a, b;
  for (int round = 0; round < rounds; ++round) {
    run_side(run, a, nm, dir + "ao_nmbake.log");
    if (!blender.empty()) run_side(run, b, bl, dir + "ao_blender.log");
  }
  std::printf(
      "b. AO against Blender. %s^2 .png, 1 sample, every core, alternated over %d round%s: `nmbake LOW HIGH -o OUT_<MAP>.png "
      "--size %s --maps normal,ao --ao-rays 64 --ao-distance %s --quiet` (automatic cage) and `blender -b --factory-startup "
      "--python bench/blender_bake.py -- LOW HIGH OUT.png %s 64 %s ao %s` (Cycles AO bake, selected-to-active, 64 samples, "
      "world AO distance %s, fixed cage extrusion %s)%s.\n\n",
      size.c_str(), rounds, rounds == 1 ? "" : "s", size.c_str(), kAoDistance, size.c_str(), kBlenderExtrusion, kAoDistance,
      kAoDistance, kBlenderExtrusion, blender.empty() ? (": Blender not run, " + why).c_str() : "");
  std::printf("| command | median wall s | median max RSS MiB | per round wall s |\n|---|---|---|---|\n");
  print_side("nmbake --maps normal,ao --ao-rays 64", a);
  if (!blender.empty()) print_side("Blender AO bake, 64 samples", b);
  const std::string what = "normal + AO (64 rays) vs Blender's AO bake (64 samples), 1M tris " + size + "^2";
  if (a.ok() && b.ok()) {
    const double ratio = median(b.wall) / median(a.wall);
    std::printf("| ratio (Blender / nmbake) | %.1fx | %.1fx | |\n\n", ratio, median(b.rss) / median(a.rss));
    const std::string split = blender_split(dir + "ao_blender.log");
    if (!split.empty()) std::printf("Blender's own split (blender_bake.py): %s.\n\n", split.c_str());
    const std::string measured = fmt("%.1fx", ratio) + fmt(" (Blender %.2f s", median(b.wall)) +
                                 fmt(" / nmbake %.2f s", median(a.wall)) + ", " + std::to_string(rounds) + " round" +
                                 (rounds == 1 ? "" : "s") + ")";
    if (run.args.ao_size == 2048) run.add_target(what, ">= 10x", measured, ratio >= 10.0);
    else run.targets.push_back({what, ">= 10x (at 2048^2)", measured + ", not at the target's size", "-"});
  } else {
    std::printf("\n");
    run.skip_target(what, ">= 10x", !a.ok() ? "nmbake failed" : blender.empty() ? why : "Blender failed: " + b.failed);
  }
  flush();
}

// c. bench_occlusion --from-bake: the bake's AO rays against the bare loop.
void ao_against_bare_loop(BenchRun& run) {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  const std::string occlusion = (self.parent_path() / "bench_occlusion").string();
  const std::string what =
      "AO tracing in the bake vs a bare Embree loop over the same rays, 1M tris " + std::to_string(run.args.ao_size) + "^2";
  std::printf("c. AO tracing against the bare loop (`bench_occlusion --from-bake %d --threads %d --rounds 1`).\n\n",
              run.args.ao_size, run.threads);
  if (ec || !fs::exists(occlusion)) {
    std::printf("bench_occlusion not found beside bench_bake: not measured.\n\n");
    run.skip_target(what, "<= 1.3x", "bench_occlusion not built");
    return;
  }
  const std::string out =
      command_output("'" + occlusion + "' --sculpt '" + run.args.shared + "/sculpts/suz_L4' --from-bake " +
                     std::to_string(run.args.ao_size) + " --threads " + std::to_string(run.threads) + " --rounds 1 2>&1");
  std::printf("%s\n\n", out.c_str());
  double ratio = 0.0;
  const std::size_t at = out.find("ratio bake AO tracing / bare loop:");
  if (at != std::string::npos && std::sscanf(out.c_str() + at, "ratio bake AO tracing / bare loop: %lf", &ratio) == 1)
    run.add_target(what, "<= 1.3x", fmt("%.2fx", ratio), ratio <= 1.3);
  else run.skip_target(what, "<= 1.3x", "bench_occlusion printed no ratio");
  flush();
}

}  // namespace

// 12. Texture sets.
void run_maps(BenchRun& run, const Scenes& scenes) {
  std::printf("## 12. Texture sets (suz_L4 low.obj onto suz_L4_x4, 1M triangles; load average %s)\n\n", load_average().c_str());
  flush();
  cheap_maps(run, scenes);
  ao_against_blender(run, scenes);
  ao_against_bare_loop(run);
}

}  // namespace nmbake::bench
