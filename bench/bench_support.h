// Helpers for bench_bake: timing, formatting, the machine and commit, the generated scenes
// (subdivided and far-geometry meshes written once into the scratch folder), whole nmbake
// commands, map hashes.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image.h"
#include "core/mesh.h"
#include "raycast.h"

namespace nmbake::bench {

constexpr double kPi = 3.14159265358979323846;

using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0);
double cpu_now();  // process CPU seconds, all threads

// The best (smallest) wall and CPU seconds over rounds.
struct Timing {
  double wall = 1e30, cpu = 1e30;
  void keep_min(double w, double c);
  void keep_min(const Timing& t) { keep_min(t.wall, t.cpu); }
};

// How a bare loop hands the rays to Embree: one rtcIntersect1 per ray, packets (of
// Scene::packet_width rays) filled from the Ray structs (Scene::intersect(const Ray*, ...)), or
// packets from rays already held as arrays (raycast::RayBatch, the bake's own layout; the arrays
// are filled before the clock starts).
enum class Bare { single, packets, arrays };

// Casts `rays` with `threads` threads in chunks of 4096, nothing but Embree calls.
Timing bare_loop(const raycast::Scene& scene, const std::vector<raycast::Ray>& rays, int threads, Bare mode);

// What the run is measured on: date, CPU, cores, memory, load, the commit of the source tree.
struct Machine {
  std::string date, cpu_model, simd, commit;  // simd: the widest vector ISA flags /proc/cpuinfo lists
  int cores = 0;
  double memory_gib = 0;
};
Machine describe_machine(const std::string& source_dir);
std::string load_average();  // /proc/loadavg's first three figures, or "unknown"

// Output of a shell command (stdout), empty when it cannot run.
std::string command_output(const std::string& cmd);

// Midpoint subdivision (1 -> 4 triangles) with normalized midpoint normals.
Mesh subdivide(const Mesh& m);
// `m` plus copies translated by each offset (normals per vertex, as in the input).
Mesh with_copies(const Mesh& m, const std::vector<glm::vec3>& offsets);
// Binary little-endian PLY / OBJ with per-vertex positions and normals, written to a temporary
// name and renamed, so an interrupted run never leaves a half file to be reused.
void write_binary_ply(const std::string& path, const Mesh& m);
void write_obj(const std::string& path, const Mesh& m);

// A whole nmbake command run as its own process (so peak memory is the bake's alone).
struct CommandRun {
  bool ok = false;
  double wall = 0;
  nlohmann::json report;  // its --report
  double seconds(const char* stage) const;
  double peak_mib() const;
  std::string stages() const;  // "load/prepare/bvh/distances/trace/padding/write" seconds
};
// Runs `exe args --quiet --report ...` `reps` times and keeps the fastest run.
CommandRun run_nmbake(const std::string& exe, const std::string& args, const std::string& report_path, int reps);

// The first value stored under `key` anywhere in `j` (depth first), or null.
const nlohmann::json* find_key(const nlohmann::json& j, const std::string& key);

// FNV-1a over the bits of the pixel values: equal hashes = bit-identical maps (for comparing
// runs and commits).
std::uint64_t pixel_hash(const Image::Pixels& pixels);

std::string mib(double bytes);
std::string fmt(const char* format, double v);  // printf of one number
std::string hex(std::uint64_t h);               // 16 hex digits
double median(std::vector<double> v);           // 0 when empty

}  // namespace nmbake::bench

namespace nmbake::bench {

// OpenMesh's own reader (OpenMesh::IO::read_mesh into a TriMesh with vertex normals requested),
// for comparison with nmbake's loaders. seconds < 0 when the read failed.
struct OpenMeshRead {
  double seconds = -1;
  std::size_t vertices = 0, faces = 0;
};
OpenMeshRead openmesh_read(const std::string& path);
// Assimp's ReadFile with the flags nmbake's Assimp reader uses (bench_assimp.cpp); same fields.
OpenMeshRead assimp_read(const std::string& path);

}  // namespace nmbake::bench
