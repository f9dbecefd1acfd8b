// The bake bench's sections (bench_bake.cpp runs them in order and prints their Markdown to
// stdout), the state they share, and the helpers more than one of them uses.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_support.h"
#include "core/mesh.h"
#include "pipeline/bake.h"
#include "raycast.h"

namespace nmbake::bench {

// The command line (bench_bake.cpp's top comment).
struct Args {
  std::string shared = "../shared/data";  // the shared data folder (sculpts/)
  std::string exe = "nmbake";             // the nmbake command the whole-command rows run
  std::string scratch = (std::filesystem::temp_directory_path() / "nmbake-bench").string();  // generated meshes, reused
  int rounds = 3;        // each timed figure the best of this many rounds
  int trace_rounds = 7;  // rounds of section 1 at 1 and 4 samples
  bool quick = false;    // fewer rows, as a smoke check
  int ao_size = 2048;    // --ao-size: section 12's AO rows, map side (Blender's AO bake at 2048^2 takes minutes)
  std::string sections;  // --sections: the sections to run ("3,9"); empty = all (0, the scenes, always runs)
  bool runs(int section) const;
};

// Every target of the issues, with what this run measured (the closing "Targets" table).
struct Target {
  std::string what, goal, measured, verdict;  // verdict: MET, NOT MET or "-" (not judged)
};

// What every section reads, and the targets they add to.
struct BenchRun {
  Args args;
  int threads = 1;      // of the in-process bakes and bare loops
  std::string run_dir;  // this run's maps and reports, removed at the end
  std::string report;   // the --report file of the whole commands
  std::vector<Target> targets;

  void add_target(const std::string& what, const std::string& goal, const std::string& measured, bool met);
  void skip_target(const std::string& what, const std::string& goal, const std::string& why);  // not measured
};

// The scenes: folders of the shared sculpts and the meshes section 0 generates from them.
struct Scenes {
  std::string t3, s3, s4;                       // sculpts/torus_s3, suz_L3, suz_L4 (low.obj, high.ply)
  std::string m1_ply, m1_obj, m4_ply, far_ply;  // suz_L4_x4 (1M triangles), suz_L4_x16 (4M), torus_s3_far4
  std::string udim_low;                         // suz_L4's low-poly with its UV quadrants on 4 UDIM tiles
  Mesh t3_low, t3_high;                         // torus_s3, loaded once
};

// Blender's side of the whole-command comparisons (bench_blender.cpp, bench_maps.cpp): its bake
// script (bench/blender_bake.py) and the cage extrusion both bakers get, scene units (the script's
// top comment).
std::string blender_script();
constexpr const char* kBlenderExtrusion = "0.05";

// One side of a whole-command comparison: its figures over the rounds.
struct Side {
  std::vector<double> wall, rss;  // seconds, MiB per round
  std::string failed;             // why it stopped, empty while it runs
  bool ok() const { return failed.empty() && !wall.empty(); }
};

// Runs one round of `command` for `side` (none once it has failed; `log` takes its output); on a failure copies the log into
// the scratch folder (the run's folder is removed), says why in side.failed and returns false.
bool run_side(const BenchRun& run, Side& side, const std::vector<std::string>& command, const std::string& log);

const char* verdict(bool met);  // "MET" or "NOT MET"
void flush();                   // stdout, so a long run shows each row as it is measured

// A bake's distances pinned (so the timed rounds skip the measurement), and the rays a bake with
// them casts (bake_rays, bench_stages.h).
struct Recorded {
  std::vector<raycast::Ray> rays;
  std::vector<glm::vec3> positions;  // high-poly, re-centred
  BakeOptions options;
  std::size_t culled = 0;  // high-poly triangles the bake left out of its BVH
};
Recorded record(const Mesh& low, const Mesh& high, int size, int samples);

// BVH build time and 8-packet trace time of one build quality on recorded rays.
struct QualityRow {
  std::string scene;
  int samples = 0;
  raycast::BuildQuality quality{};
  std::size_t triangles = 0;
  double build = 1e30;  // seconds
  Timing trace;
  std::size_t rays = 0;
};

// Whole-command table: its header, and a row (wall, stage seconds, peak memory, hash of `map`).
void print_command_header();
void print_command_row(const std::string& label, const CommandRun& r, const std::string& map);
// Runs `nmbake inputs -o RUN_DIR/map options` (the fastest of `reps`) and prints its row as `label`.
CommandRun run_command_row(const BenchRun& run, const std::string& label, const std::string& inputs, const std::string& map,
                           const std::string& options, int reps);
std::size_t high_tris(const CommandRun& r);        // the high-poly triangle count of its report, or 0
std::string map_hash_of(const std::string& path);  // hex pixel_hash of the image, or why it cannot be read

// The sections, in the order they print; each adds its targets to `run`.
void generate_scenes(const BenchRun& run, Scenes& scenes);                                      // 0
std::vector<QualityRow> run_tracing(BenchRun& run);                                             // 1 (rows for 2)
void run_bvh_quality(const BenchRun& run, const Scenes& scenes, std::vector<QualityRow> rows);  // 2
CommandRun run_whole_commands(BenchRun& run, const Scenes& scenes);              // 3; returns the 1M 2048^2 .png row for 5
void run_loading(BenchRun& run, const Scenes& scenes);                           // 4
void run_scaling(BenchRun& run, const Scenes& scenes, const CommandRun& m1_2k);  // 5
void run_serial_shares(BenchRun& run, const Scenes& scenes);                     // 5's last part (bench_serial.cpp)
void run_far_geometry(BenchRun& run, const Scenes& scenes);                      // 6
void run_floods(BenchRun& run, const Scenes& scenes);                            // 7 (bench_floods.cpp)
void run_batch(BenchRun& run, const Scenes& scenes);                             // 8 (bench_batch.cpp)
void run_png_settings(BenchRun& run, const Scenes& scenes);                      // 9 (bench_png.cpp)
void run_blender(BenchRun& run, const Scenes& scenes);                           // 10 (bench_blender.cpp)

// `bench_bake --measure-child CMD ARGS...`, the process section 10 starts each command with (a fresh
// one, so the command's ru_maxrss does not start from the bench's peak): forks and runs CMD (searched on PATH) with this
// process's stdin, stdout and stderr, waits for it, and prints "bench-measured: status S wall W maxrss_kib K" (S the raw wait
// status, W seconds). Returns CMD's exit code, 1 when a signal ended it, 127 when it cannot start.
inline constexpr const char* kMeasureChild = "--measure-child";

// One command's wall seconds and max resident set, or why it failed.
struct Measured {
  bool ok = false;
  double wall = 0.0, rss_mib = 0.0;
  std::string why;  // "exit 1", "signal 9", "cannot start: ..."
};

// Runs `command` (program and arguments) through the measuring helper above, stdin from /dev/null
// and its output (and the helper's figures) into `log` (bench_blender.cpp).
Measured measure(const std::vector<std::string>& command, const std::string& log);
void run_memory(BenchRun& run, const Scenes& scenes);  // 11 (bench_memory.cpp)
// Blender: $NMBAKE_BLENDER when set, else `blender` on PATH; empty (and `why`) when not found
// (bench_blender.cpp).
std::string find_blender(std::string& why);
void run_maps(BenchRun& run, const Scenes& scenes);  // 12 (bench_maps.cpp)
int measure_child(char** argv);                      // argv: CMD ARGS..., null-terminated

}  // namespace nmbake::bench
