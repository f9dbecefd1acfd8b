// Section 7 of the bake bench (issue 21, item 13): degenerate floods, whose bake time must grow at
// most as n log n with the input. Whole commands at 64^2 on torus_s3's low-poly against a high-poly
// of n copies of one face, and of one n-corner polygon (a disc), at n and 4n; the target is the
// ratio of the two times against 4 log(4n) / log(n).
#include <cmath>
#include <cstdio>
#include <string>

#include "bench_bake.h"
#include "bench_support.h"

namespace nmbake::bench {

namespace {

// One face (a triangle under torus_s3's low-poly) `copies` times, as OBJ.
void write_stack(const std::string& path, std::size_t copies) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return;
  std::fprintf(f, "v -5 -5 0\nv 5 -5 0\nv 0 5 0\n");
  for (std::size_t i = 0; i < copies; ++i) std::fputs("f 1 2 3\n", f);
  std::fclose(f);
}

// A disc of radius 1.6 at z = 0.3 as one polygon of `corners` corners, as OBJ.
void write_disc(const std::string& path, std::size_t corners) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return;
  for (std::size_t i = 0; i < corners; ++i) {
    const double a = 2.0 * 3.14159265358979323846 * double(i) / double(corners);
    std::fprintf(f, "v %.9f %.9f 0.3\n", 1.6 * std::cos(a), 1.6 * std::sin(a));
  }
  std::fputs("f", f);
  for (std::size_t i = 1; i <= corners; ++i) std::fprintf(f, " %zu", i);
  std::fputs("\n", f);
  std::fclose(f);
}

}  // namespace

void run_floods(BenchRun& run, const Scenes& scenes) {
  const Args& args = run.args;
  const std::size_t n = args.quick ? 62500 : 250000;
  std::printf("## 7. Degenerate floods (torus_s3 low, 64^2, whole commands; n = %zu and 4n)\n\n", n);
  std::printf("Load average %s.\n\n", load_average().c_str());
  print_command_header();
  const double allowed = 4.0 * std::log(4.0 * double(n)) / std::log(double(n));
  struct Flood {
    const char* name;
    void (*write)(const std::string&, std::size_t);
  };
  for (const Flood& flood : {Flood{"copies of one face", write_stack}, Flood{"corners of one polygon", write_disc}}) {
    double wall[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
      const std::size_t count = k == 0 ? n : 4 * n;
      const std::string path =
          run.run_dir + "/flood_" + std::to_string(count) + (flood.write == write_stack ? "_stack" : "_disc") + ".obj";
      flood.write(path, count);
      const CommandRun r = run_command_row(run, std::to_string(count) + " " + flood.name, scenes.t3 + "/low.obj " + path,
                                           "flood.png", "--size 64", args.rounds);
      wall[k] = r.ok ? r.wall : -1.0;
    }
    const bool measured = wall[0] > 0 && wall[1] > 0;
    const double ratio = measured ? wall[1] / wall[0] : 0.0;
    run.add_target(std::string("floods: ") + flood.name + ", time(4n) / time(n)", fmt("<= %.2f (n log n)", allowed),
                   measured ? fmt("%.2f", ratio) : std::string("command failed"), measured && ratio <= allowed);
  }
  std::printf("\n");
  flush();
}

}  // namespace nmbake::bench
