// Section 11: peak memory against high-poly triangle count, the whole nmbake command at 1M, 4M and
// 16M triangles (suz_L4 subdivided once, twice and three times; the 16M file is made here, by the
// bench's own subdivision, the first time), 2048^2, 1 sample, each process measured alone (max RSS
// through the measuring helper, bench_blender.cpp). Bytes per triangle = (peak - the map's buffers
// (estimate_bake_bytes) - the process's floor at no triangles) / triangles; target <= 150 at 4M and
// 16M (issue 22).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_bake.h"
#include "bench_support.h"
#include "io/mesh_io.h"
#include "pipeline/bake.h"

namespace nmbake::bench {

namespace {

namespace fs = std::filesystem;

struct MemoryRow {
  std::string name, high;
  double triangles = 0;
  Measured m;
};

}  // namespace

void run_memory(BenchRun& run, const Scenes& scenes) {
  std::printf("## 11. Peak memory against triangles (whole commands, 2048^2, 1 sample, max RSS of each process)\n\n");
  const std::string m16_ply = run.args.scratch + "/suz_L4_x64.ply";
  if (!run.args.quick && !fs::exists(m16_ply)) {
    const auto t0 = Clock::now();
    write_binary_ply(m16_ply, subdivide(load_mesh(scenes.m4_ply)));
    std::printf("Made %s (suz_L4_x16 subdivided once more) in %.1f s.\n\n", m16_ply.c_str(), since(t0));
  }
  std::vector<MemoryRow> rows = {{"suz_L4 (252k)", scenes.s4 + "/high.ply", 251904.0, {}},
                                 {"suz_L4_x4 (1M)", scenes.m1_ply, 1007616.0, {}},
                                 {"suz_L4_x16 (4M)", scenes.m4_ply, 4030464.0, {}}};
  if (!run.args.quick) rows.push_back({"suz_L4_x64 (16M)", m16_ply, 16121856.0, {}});
  BakeOptions o;
  o.width = o.height = 2048;
  const double map_mib = double(estimate_bake_bytes(o)) / 1048576.0;
  std::printf("Load average %s. The map's buffers (estimate_bake_bytes, 2048^2): %.0f MiB.\n\n", load_average().c_str(), map_mib);
  std::printf("| high-poly | triangles | wall s | peak MiB | bytes per triangle beyond the map |\n|---|---|---|---|---|\n");
  for (MemoryRow& r : rows) {
    r.m = measure({run.args.exe, scenes.s4 + "/low.obj", r.high, "-o", run.run_dir + "/mem.png", "--size", "2048", "--quiet"},
                  run.run_dir + "/mem.log");
    if (!r.m.ok) {
      std::printf("| %s | %.0f | failed: %s | | |\n", r.name.c_str(), r.triangles, r.m.why.c_str());
      continue;
    }
    const double per = (r.m.rss_mib - map_mib) * 1048576.0 / r.triangles;
    std::printf("| %s | %.0f | %.2f | %.0f | %.0f |\n", r.name.c_str(), r.triangles, r.m.wall, r.m.rss_mib, per);
    flush();
  }
  // The slope between the largest two: what each further triangle costs, without the fixed part.
  const MemoryRow& a = rows[rows.size() - 2];
  const MemoryRow& b = rows.back();
  if (a.m.ok && b.m.ok)
    std::printf("\nBetween %s and %s: %.0f bytes per added triangle.\n", a.name.c_str(), b.name.c_str(),
                (b.m.rss_mib - a.m.rss_mib) * 1048576.0 / (b.triangles - a.triangles));
  std::printf("\n");
  for (const MemoryRow& r : rows) {
    if (r.triangles < 4e6) continue;
    const std::string what = "peak memory per triangle, " + r.name + ", 2048^2";
    if (!r.m.ok) {
      run.skip_target(what, "<= 150 B + the map", r.m.why);
      continue;
    }
    const double per = (r.m.rss_mib - map_mib) * 1048576.0 / r.triangles;
    run.add_target(what, "<= 150 B + the map", fmt("%.0f B", per) + fmt(" (%.0f MiB peak)", r.m.rss_mib), per <= 150.0);
  }
  flush();
}

}  // namespace nmbake::bench
