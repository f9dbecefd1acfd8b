// The bake bench: stage times, rays per second, the tracing stage against a bare Embree loop over
// the same rays in the same process, and the whole command's wall time and peak memory.
// Prints figures and ratios; asserts nothing (targets are read by people, not by CI).
#include <sys/wait.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>

#include "bake.h"
#include "image_io.h"
#include "mesh_io.h"
#include "raycast.h"

using namespace nmbake;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Timing {
  double wall = 1e30, cpu = 1e30;
  void keep_min(double w, double c) {
    wall = std::min(wall, w);
    cpu = std::min(cpu, c);
  }
};

// The bare loop: the same rays, the same number of threads, nothing but Embree calls.
Timing bare_loop(const raycast::Scene& scene, const std::vector<raycast::Ray>& rays, int threads, bool packets) {
  std::vector<raycast::Hit> hits(rays.size());
  std::atomic<std::size_t> next{0};
  const std::size_t chunk = 4096;
  const auto t0 = Clock::now();
  const double c0 = cpu_now();
  auto work = [&] {
    for (std::size_t i; (i = next.fetch_add(chunk)) < rays.size();) {
      const std::size_t n = std::min(chunk, rays.size() - i);
      if (packets) {
        scene.intersect(&rays[i], &hits[i], n);
      } else {
        for (std::size_t k = i; k < i + n; ++k) hits[k] = scene.intersect(rays[k]);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  Timing t;
  t.keep_min(since(t0), cpu_now() - c0);
  return t;
}

// Midpoint subdivision (1 -> 4 triangles) with normalized midpoint normals.
Mesh subdivide(const Mesh& m) {
  Mesh out;
  out.source = m.source + " (subdivided)";
  out.positions = m.positions;
  std::vector<glm::vec3> normals(m.positions.size());
  for (std::size_t c = 0; c < m.position_index.size(); ++c) normals[m.position_index[c]] = m.normals[m.normal_index[c]];
  std::unordered_map<std::uint64_t, std::uint32_t> mid;
  auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
    const std::uint64_t key = (std::uint64_t(std::min(a, b)) << 32) | std::max(a, b);
    auto it = mid.find(key);
    if (it != mid.end()) return it->second;
    const std::uint32_t id = std::uint32_t(out.positions.size());
    out.positions.push_back(0.5f * (out.positions[a] + out.positions[b]));
    normals.push_back(glm::normalize(normals[a] + normals[b]));
    mid.emplace(key, id);
    return id;
  };
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t a = m.position_index[3 * t], b = m.position_index[3 * t + 1], c = m.position_index[3 * t + 2];
    const std::uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
    for (std::uint32_t v : {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca}) out.position_index.push_back(v);
  }
  out.normals = normals;
  out.normal_index = out.position_index;
  return out;
}

void write_binary_ply(const std::string& path, const Mesh& m) {
  std::ofstream f(path, std::ios::binary);
  f << "ply\nformat binary_little_endian 1.0\nelement vertex " << m.positions.size()
    << "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
    << "element face " << m.triangle_count() << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    f.write(reinterpret_cast<const char*>(&m.positions[i]), 12);
    f.write(reinterpret_cast<const char*>(&m.normals[i]), 12);
  }
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const unsigned char three = 3;
    f.write(reinterpret_cast<const char*>(&three), 1);
    f.write(reinterpret_cast<const char*>(&m.position_index[3 * t]), 12);
  }
}

// Runs nmbake as its own process (so peak memory is the bake's alone); returns wall seconds and
// fills `report` from its --report JSON.
double run_nmbake(const std::string& exe, const std::string& args, const std::string& report_path, nlohmann::json& report) {
  const std::string cmd = exe + " " + args + " --quiet --report " + report_path;
  const auto t0 = Clock::now();
  const int rc = std::system(cmd.c_str());
  const double wall = since(t0);
  if (rc != 0) {
    std::fprintf(stderr, "bench: command failed (%d): %s\n", rc, cmd.c_str());
    return -1.0;
  }
  std::ifstream in(report_path);
  report = nlohmann::json::parse(in);
  return wall;
}

}  // namespace

int main(int argc, char** argv) {
  std::string shared = argc > 1 ? argv[1] : "../shared/data";
  std::string exe = argc > 2 ? argv[2] : "nmbake";
  const std::string scratch = std::filesystem::temp_directory_path() / "nmbake-bench";
  std::filesystem::create_directories(scratch);
  const int threads = std::max(1, int(std::thread::hardware_concurrency()));
  std::printf("nmbake bench: %d cores, shared data %s\n\n", threads, shared.c_str());

  const char* scenes[] = {"torus_s3", "suz_L4"};
  std::printf("Each figure is the best of 3 rounds; a round runs the bake and both bare loops back to back.\n"
              "CPU = process CPU seconds (all threads), less disturbed by other load than wall time.\n\n");
  std::printf("| scene | size | samples | high tris | load s | bvh s | trace s (CPU) | pad s | rays | Mrays/s | bare 1-ray s (CPU) | bare 8-packet s (CPU) | trace / best bare, wall | CPU |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const char* name : scenes) {
    const std::string dir = shared + "/sculpts/" + name;
    if (!std::filesystem::exists(dir + "/high.ply")) {
      std::printf("| %s | skipped: %s not found |\n", name, dir.c_str());
      continue;
    }
    auto t0 = Clock::now();
    LoadOptions lo;
    lo.require_uvs = true;
    const Mesh low = load_mesh(dir + "/low.obj", lo);
    const Mesh high = load_mesh(dir + "/high.ply");
    const double load = since(t0);
    for (int samples : {1, 4}) {
      BakeOptions o;
      o.width = o.height = 2048;
      o.samples = samples;
      std::vector<raycast::Ray> rays;
      o.record_rays = &rays;
      const BakeResult first = bake_normal_map(low, high, nullptr, o);
      o.record_rays = nullptr;
      o.front = first.stats.front;
      o.rear = first.stats.rear;
      // The BVH the bare loop uses: the same re-centred coordinates the bake traced.
      const glm::dvec3 centre = first.stats.centre;
      std::vector<glm::vec3> pos(high.positions.size());
      for (std::size_t i = 0; i < pos.size(); ++i) pos[i] = glm::vec3(glm::dvec3(high.positions[i]) - centre);
      raycast::Scene scene(&pos[0].x, pos.size(), high.position_index.data(), high.triangle_count());
      Timing trace, bare1, bare8;
      double bvh = 0, pad = 0;
      for (int round = 0; round < 3; ++round) {
        const BakeResult r = bake_normal_map(low, high, nullptr, o);
        if (r.stats.seconds_trace < trace.wall) {
          bvh = r.stats.seconds_bvh;
          pad = r.stats.seconds_padding;
        }
        trace.keep_min(r.stats.seconds_trace, r.stats.cpu_seconds_trace);
        const Timing b1 = bare_loop(scene, rays, threads, false), b8 = bare_loop(scene, rays, threads, true);
        bare1.keep_min(b1.wall, b1.cpu);
        bare8.keep_min(b8.wall, b8.cpu);
      }
      std::printf("| %s | 2048 | %d | %zu | %.3f | %.3f | %.3f (%.3f) | %.3f | %.2fM | %.2f | %.3f (%.3f) | %.3f (%.3f) | %.2fx | %.2fx |\n", name,
                  samples, high.triangle_count(), load, bvh, trace.wall, trace.cpu, pad, double(rays.size()) / 1e6,
                  double(rays.size()) / trace.wall / 1e6, bare1.wall, bare1.cpu, bare8.wall, bare8.cpu,
                  trace.wall / std::min(bare1.wall, bare8.wall), trace.cpu / std::min(bare1.cpu, bare8.cpu));
      std::fflush(stdout);
    }
  }

  // Whole commands as a user runs them: wall time and peak memory of the process.
  std::printf("\n| command | wall s | stage seconds (load/prepare/bvh/distances/trace/padding/write) | peak memory MiB |\n|---|---|---|---|\n");
  auto row = [&](const std::string& label, const std::string& args) {
    nlohmann::json rep;
    const double wall = run_nmbake(exe, args, scratch + "/report.json", rep);
    if (wall < 0) return;
    const auto& s = rep["seconds"];
    std::printf("| %s | %.2f | %.2f/%.2f/%.2f/%.2f/%.2f/%.2f/%.2f | %.0f |\n", label.c_str(), wall, s["load"].get<double>(),
                s["prepare"].get<double>(), s["bvh"].get<double>(), s["distances"].get<double>(), s["trace"].get<double>(),
                s["padding"].get<double>(), s["write"].get<double>(), rep["peak_memory_bytes"].get<double>() / 1048576.0);
    std::fflush(stdout);
  };
  const std::string t3 = shared + "/sculpts/torus_s3";
  if (std::filesystem::exists(t3 + "/high.ply")) {
    row("torus_s3 2048^2 1 sample .png", t3 + "/low.obj " + t3 + "/high.ply -o " + scratch + "/t3.png --size 2048");
    row("torus_s3 2048^2 1 sample .exr", t3 + "/low.obj " + t3 + "/high.ply -o " + scratch + "/t3.exr --size 2048");
  }
  const std::string s4 = shared + "/sculpts/suz_L4";
  if (std::filesystem::exists(s4 + "/high.ply")) {
    const std::string big = scratch + "/suz_L4_x4.ply";
    if (!std::filesystem::exists(big)) write_binary_ply(big, subdivide(load_mesh(s4 + "/high.ply")));
    row("suz_L4 subdivided (1.0M tris) 4096^2 1 sample", s4 + "/low.obj " + big + " -o " + scratch + "/s4x4.png --size 4096");
  }
  return 0;
}
