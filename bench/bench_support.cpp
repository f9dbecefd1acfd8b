#include "bench_support.h"

#include <sys/wait.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <unordered_map>

namespace nmbake::bench {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double cpu_now() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void Timing::keep_min(double w, double c) {
  wall = std::min(wall, w);
  cpu = std::min(cpu, c);
}

Timing bare_loop(const raycast::Scene& scene, const std::vector<raycast::Ray>& rays, int threads, Bare mode) {
  // Everything the loop writes or reads besides Embree is made and touched here, outside the timing.
  std::vector<raycast::Hit> hits(rays.size());
  raycast::RayArrays arrays(rays.data(), mode == Bare::arrays ? rays.size() : 0);
  std::atomic<std::size_t> next{0};
  const std::size_t chunk = 4096;
  const auto t0 = Clock::now();
  const double c0 = cpu_now();
  auto work = [&] {
    for (std::size_t i; (i = next.fetch_add(chunk)) < rays.size();) {
      const std::size_t n = std::min(chunk, rays.size() - i);
      // The bake's rays are coherent (neighbouring texels in a row): the packet loops say so too,
      // as the bake does (raycast::RayBatch::coherent).
      if (mode == Bare::arrays) {
        raycast::RayBatch batch = arrays.rays(i);
        batch.coherent = true;
        scene.intersect(batch, arrays.hits(i), n);
      } else if (mode == Bare::packets) {
        scene.intersect(&rays[i], &hits[i], n, true);
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

std::string command_output(const std::string& cmd) {
  std::string out;
  if (FILE* p = ::popen(cmd.c_str(), "r")) {
    char buf[4096];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    ::pclose(p);
  }
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return in ? a + " " + b + " " + c : std::string("unknown");
}

Machine describe_machine(const std::string& source_dir) {
  Machine m;
  char date[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M %Z", std::localtime(&now));
  m.date = date;
  m.cores = int(std::thread::hardware_concurrency());
  std::ifstream cpu("/proc/cpuinfo");
  for (std::string line; std::getline(cpu, line);)
    if (line.rfind("model name", 0) == 0 && m.cpu_model.empty()) {
      m.cpu_model = line.substr(line.find(':') + 2);
    } else if (line.rfind("flags", 0) == 0 && m.simd.empty()) {
      line += ' ';
      for (const char* isa : {"sse4_2", "avx", "avx2", "avx512f"})
        if (line.find(std::string(" ") + isa + " ") != std::string::npos) m.simd += std::string(m.simd.empty() ? "" : " ") + isa;
    }
  std::ifstream mem("/proc/meminfo");
  for (std::string line; std::getline(mem, line);)
    if (line.rfind("MemTotal:", 0) == 0) m.memory_gib = std::atof(line.c_str() + 9) / 1048576.0;
  const std::string git = "git -C '" + source_dir + "' ";
  m.commit = command_output(git + "rev-parse --short=12 HEAD 2>/dev/null");
  if (m.commit.empty()) {
    m.commit = "unknown (no git checkout at " + source_dir + ")";
  } else {
    const std::string branch = command_output(git + "rev-parse --abbrev-ref HEAD 2>/dev/null");
    const bool dirty = !command_output(git + "status --porcelain --untracked-files=no 2>/dev/null").empty();
    m.commit += " (" + branch + (dirty ? ", with uncommitted changes" : "") + ")";
  }
  return m;
}

Mesh subdivide(const Mesh& m) {
  Mesh out;
  out.source = m.source + " (subdivided)";
  out.positions = m.positions;
  std::vector<glm::vec3> normals(m.positions.size());
  for (std::size_t c = 0; c < m.position_index.size(); ++c) normals[m.position_index[c]] = m.normals[m.normal_index[c]];
  std::unordered_map<std::uint64_t, std::uint32_t> mid;
  mid.reserve(m.position_index.size());
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

namespace {

// Normals per position (the files we write carry one normal per vertex).
std::vector<glm::vec3> vertex_normals(const Mesh& m) {
  std::vector<glm::vec3> n(m.positions.size(), glm::vec3(0, 0, 1));
  if (m.has_normals())
    for (std::size_t c = 0; c < m.position_index.size(); ++c) n[m.position_index[c]] = m.normals[m.normal_index[c]];
  return n;
}

void rename_into_place(const std::string& tmp, const std::string& path, bool good) {
  if (!good) {
    std::filesystem::remove(tmp);
    throw std::runtime_error("bench: cannot write " + path);
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace

Mesh with_copies(const Mesh& m, const std::vector<glm::vec3>& offsets) {
  Mesh out;
  out.source = m.source + " (with far copies)";
  const std::vector<glm::vec3> n = vertex_normals(m);
  const std::size_t nv = m.positions.size();
  for (std::size_t k = 0; k <= offsets.size(); ++k) {
    const glm::vec3 d = k == 0 ? glm::vec3(0.0f) : offsets[k - 1];
    for (std::size_t i = 0; i < nv; ++i) {
      out.positions.push_back(m.positions[i] + d);
      out.normals.push_back(n[i]);
    }
    for (std::uint32_t v : m.position_index) out.position_index.push_back(std::uint32_t(v + k * nv));
  }
  out.normal_index = out.position_index;
  return out;
}

void write_binary_ply(const std::string& path, const Mesh& m) {
  const std::string tmp = path + ".partial";
  const std::vector<glm::vec3> n = vertex_normals(m);
  {
    std::ofstream f(tmp, std::ios::binary);
    f << "ply\nformat binary_little_endian 1.0\nelement vertex " << m.positions.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
      << "element face " << m.triangle_count() << "\nproperty list uchar int vertex_indices\nend_header\n";
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      f.write(reinterpret_cast<const char*>(&m.positions[i]), 12);
      f.write(reinterpret_cast<const char*>(&n[i]), 12);
    }
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
      const unsigned char three = 3;
      f.write(reinterpret_cast<const char*>(&three), 1);
      f.write(reinterpret_cast<const char*>(&m.position_index[3 * t]), 12);
    }
    f.close();
    rename_into_place(tmp, path, bool(f));
  }
}

void write_obj(const std::string& path, const Mesh& m) {
  const std::string tmp = path + ".partial";
  const std::vector<glm::vec3> n = vertex_normals(m);
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw std::runtime_error("bench: cannot write " + tmp);
  std::fprintf(f, "# %s\n", m.source.c_str());
  for (const glm::vec3& p : m.positions) std::fprintf(f, "v %.6f %.6f %.6f\n", p.x, p.y, p.z);
  for (const glm::vec3& v : n) std::fprintf(f, "vn %.6f %.6f %.6f\n", v.x, v.y, v.z);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t a = m.position_index[3 * t] + 1, b = m.position_index[3 * t + 1] + 1, c = m.position_index[3 * t + 2] + 1;
    std::fprintf(f, "f %u//%u %u//%u %u//%u\n", a, a, b, b, c, c);
  }
  const bool good = std::ferror(f) == 0;
  rename_into_place(tmp, path, std::fclose(f) == 0 && good);
}

double CommandRun::seconds(const char* stage) const {
  const nlohmann::json* s = find_key(report, "seconds");
  return s && s->contains(stage) ? (*s)[stage].get<double>() : -1.0;
}

double CommandRun::peak_mib() const {
  const nlohmann::json* p = find_key(report, "peak_memory_bytes");
  return p ? p->get<double>() / 1048576.0 : -1.0;
}

std::string CommandRun::stages() const {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%.2f/%.2f/%.2f/%.2f/%.2f/%.2f/%.2f", seconds("load"), seconds("prepare"), seconds("bvh"),
                seconds("distances"), seconds("trace"), seconds("padding"), seconds("write"));
  return buf;
}

CommandRun run_nmbake(const std::string& exe, const std::string& args, const std::string& report_path, int reps) {
  CommandRun best;
  const std::string cmd = exe + " " + args + " --quiet --report " + report_path;
  for (int r = 0; r < std::max(1, reps); ++r) {
    const auto t0 = Clock::now();
    const int rc = std::system(cmd.c_str());
    const double wall = since(t0);
    if (rc != 0) {
      std::fprintf(stderr, "bench: command failed (%d): %s\n", rc, cmd.c_str());
      return CommandRun{};
    }
    if (best.ok && wall >= best.wall) continue;
    std::ifstream in(report_path);
    best.report = nlohmann::json::parse(in);
    best.wall = wall;
    best.ok = true;
  }
  return best;
}

const nlohmann::json* find_key(const nlohmann::json& j, const std::string& key) {
  if (j.is_object()) {
    auto it = j.find(key);
    if (it != j.end()) return &*it;
    for (const auto& item : j.items())
      if (const nlohmann::json* f = find_key(item.value(), key)) return f;
  } else if (j.is_array()) {
    for (const auto& v : j)
      if (const nlohmann::json* f = find_key(v, key)) return f;
  }
  return nullptr;
}

std::uint64_t pixel_hash(const Image::Pixels& pixels) {
  std::uint64_t h = 1469598103934665603ull;
  for (float v : pixels) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, 4);
    for (int b = 0; b < 4; ++b) {
      h ^= (bits >> (8 * b)) & 0xffu;
      h *= 1099511628211ull;
    }
  }
  return h;
}

std::string mib(double bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.0f MiB", bytes / 1048576.0);
  return buf;
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string hex(std::uint64_t h) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t h = v.size() / 2;
  return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
}

}  // namespace nmbake::bench
