#include "test_support.h"

#include <cstring>
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <gtest/gtest.h>

#include "cli/command.h"
#include "core/rasterize.h"
#include "core/tangent_frames.h"
#include "io/mesh_io.h"
#include "pipeline/bake_stages.h"
#include "pipeline/trace.h"
#include "build_paths.h"

namespace nmbake::test {

std::string data_path(const std::string& relative) { return std::string(nmbake::build::data_dir()) + "/" + relative; }

std::string shared_data_path(const std::string& relative) {
  return std::string(nmbake::build::shared_data_dir()) + "/" + relative;
}

bool exists(const std::string& path) { return std::filesystem::exists(path); }

const std::string& sample_low() {
  static const std::string path = data_path("sample/torus_low.obj");
  return path;
}

MeshPair load_pair(const std::string& low_path, const std::string& high_path, MeshLoadInfo* low_info) {
  LoadOptions with_uvs;
  with_uvs.require_uvs = true;
  MeshPair pair;
  pair.low = load_mesh(low_path, with_uvs, low_info);
  LoadOptions shared;
  shared.origin = pair.low.origin;
  pair.high = load_mesh(high_path, shared);
  return pair;
}

const std::string& sample_high() {
  static const std::string path = data_path("sample/torus_high.ply");
  return path;
}

std::string scratch_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "scratch";
  for (char& c : name)
    if (c == '/') c = '_';
  std::filesystem::path dir = std::filesystem::path(nmbake::build::binary_dir()) / "test-scratch" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_file(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
  if (!out.flush()) throw std::runtime_error("cannot write " + path);
}

std::vector<std::string> shell_words(const std::string& line) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == ' ' || c == '\t' || c == '\n') {
      if (in_word) words.push_back(word), word.clear(), in_word = false;
      continue;
    }
    in_word = true;
    if (c == '\'' || c == '"') {
      const std::size_t end = line.find(c, i + 1);
      if (end == std::string::npos) throw std::invalid_argument("shell_words: unclosed quote in: " + line);
      const std::string quoted = line.substr(i + 1, end - i - 1);
      if (c == '"' && quoted.find_first_of("$`\\") != std::string::npos)
        throw std::invalid_argument("shell_words: $, ` or \\ inside double quotes in: " + line);
      word += quoted;
      i = end;
    } else if (c == '\\' && i + 1 < line.size()) {
      word += line[++i];
    } else if (std::string("|&;<>()$`*?[]{}~#").find(c) != std::string::npos) {
      throw std::invalid_argument(std::string("shell_words: unquoted '") + c + "' in: " + line);
    } else {
      word += c;
    }
  }
  if (in_word) words.push_back(word);
  return words;
}

namespace {

// Points descriptor `fd` at `path` until destroyed, then back where it pointed before.
class Redirect {
 public:
  Redirect(int fd, const std::string& path, int flags) : fd_(fd), saved_(::dup(fd)) {
    const int file = ::open(path.c_str(), flags, 0644);
    if (saved_ < 0 || file < 0) throw std::runtime_error("cannot redirect to " + path);
    ::dup2(file, fd);
    ::close(file);
  }
  ~Redirect() {
    ::dup2(saved_, fd_);
    ::close(saved_);
  }
  Redirect(const Redirect&) = delete;
  Redirect& operator=(const Redirect&) = delete;

 private:
  int fd_, saved_;
};

}  // namespace

int run_nmbake_in(const std::vector<std::string>& words, const std::string& dir, const std::string& out_name,
                  const std::string& err_name) {
  return run_command_in(nmbake_command, "nmbake", words, dir, out_name, err_name);
}

int run_command_in(int (*command)(int, char**), const std::string& name, const std::vector<std::string>& words,
                   const std::string& dir, const std::string& out_name, const std::string& err_name) {
  std::vector<std::string> args{name};
  args.insert(args.end(), words.begin(), words.end());
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  const std::filesystem::path cwd = std::filesystem::current_path();
  std::filesystem::current_path(dir);
  int code = -1;
  {
    const Redirect in(0, "/dev/null", O_RDONLY);
    const Redirect out(1, out_name, O_WRONLY | O_CREAT | O_TRUNC);
    const Redirect err(2, err_name, O_WRONLY | O_CREAT | O_TRUNC);
    code = command(int(args.size()), argv.data());
    std::fflush(stdout);
    std::fflush(stderr);
  }
  std::filesystem::current_path(cwd);
  return code;
}

CliRun run_nmbake(const std::string& args, const std::string& prefix, const std::string& dir) {
  CliRun r;
  r.dir = dir.empty() ? scratch_dir() : dir;
  std::filesystem::remove(r.dir + "/r.json");
  const char* process = std::getenv("NMBAKE_TEST_PROCESS");
  if (prefix.empty() && !(process && std::string(process) == "1")) {
    r.code = run_nmbake_in(shell_words(args), r.dir);
  } else {
    const std::string exe = std::string(nmbake::build::binary_dir()) + "/baker/nmbake";
    const std::string cmd = "cd '" + r.dir + "' && " + prefix + " '" + exe + "' " + args + " >out.txt 2>err.txt";
    const int status = std::system(("bash -c \"" + cmd + "\"").c_str());
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  r.out = read_file(r.dir + "/out.txt");
  r.err = read_file(r.dir + "/err.txt");
  if (exists(r.dir + "/r.json")) r.report = nlohmann::json::parse(read_file(r.dir + "/r.json"));
  std::printf("$ nmbake %s\n-> exit %d\n%s%s", args.c_str(), r.code, r.out.c_str(), r.err.c_str());
  return r;
}

bool contains(const std::string& s, const std::string& what) { return s.find(what) != std::string::npos; }

BakeOptions bake_options(int size, int samples, int padding) {
  BakeOptions o;
  o.width = o.height = size;
  o.samples = samples;
  o.padding = padding;
  return o;
}

Mesh make_grid(int nx, int ny, float x0, float x1, float y0, float y1) {
  Mesh m;
  m.source = "grid";
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      float s = float(i) / float(nx), t = float(j) / float(ny);
      m.positions.push_back({x0 + (x1 - x0) * s, y0 + (y1 - y0) * t, 0.0f});
      m.uvs.push_back({s, t});
    }
  m.normals.push_back({0, 0, 1});
  auto id = [&](int i, int j) { return std::uint32_t(j * (nx + 1) + i); };
  std::uint32_t face = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i, ++face) {
      std::uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      for (std::uint32_t v : {a, b, c, a, c, d}) {
        m.position_index.push_back(v);
        m.uv_index.push_back(v);
        m.normal_index.push_back(0);
      }
      m.source_face.push_back(face);
      m.source_face.push_back(face);
    }
  return m;
}

Mesh make_torus(int nu, int nv, float R, float r) {
  Mesh m;
  m.source = "torus";
  const double pi = 3.14159265358979323846;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) {
      const double a = 2 * pi * (i % nu) / nu, b = 2 * pi * (j % nv) / nv;
      const glm::dvec3 n(std::cos(b) * std::cos(a), std::cos(b) * std::sin(a), std::sin(b));
      const glm::dvec3 c(R * std::cos(a), R * std::sin(a), 0.0);
      m.positions.push_back(glm::vec3(c + double(r) * n));
      m.normals.push_back(glm::vec3(n));
      m.uvs.push_back({float(i) / float(nu), float(j) / float(nv)});
    }
  auto id = [&](int i, int j) { return std::uint32_t(j * (nu + 1) + i); };
  std::uint32_t face = 0;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i, ++face) {
      const std::uint32_t a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      for (std::uint32_t v : {a, b, c, a, c, d}) {
        m.position_index.push_back(v);
        m.uv_index.push_back(v);
        m.normal_index.push_back(v);
      }
      m.source_face.push_back(face);
      m.source_face.push_back(face);
    }
  return m;
}

double angle_deg(const glm::dvec3& a, const glm::dvec3& b) {
  const double la = glm::length(a), lb = glm::length(b);
  if (la == 0.0 || lb == 0.0) return 0.0;
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * 180.0 / 3.14159265358979323846;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

glm::dvec3 decode_rgb(const float* c) {
  double n[3];
  return codec::decode_texel(c, n) ? glm::dvec3(n[0], n[1], n[2]) : glm::dvec3(0.0);
}

void for_each_decoded_texel(
    const Mesh& low, const Image& map,
    const std::function<void(int x, int y, const glm::dvec3& world, const glm::dvec3& point, std::size_t triangle)>& fn) {
  const TangentFrames frames = compute_tangent_frames(low);
  const auto owner = rasterize_texel_triangles(low, map.width, map.height);
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x) {
      const std::int32_t t = owner[std::size_t(y) * map.width + x];
      if (t < 0) continue;
      double b[3];
      const TexelTriangle tri =
          setup_texel_triangle(low.corner_uv(t, 0), low.corner_uv(t, 1), low.corner_uv(t, 2), map.width, map.height);
      if (!covers(tri, sample_point(x, y, 0.5, 0.5), b)) continue;
      glm::dvec3 p(0.0);
      for (int c = 0; c < 3; ++c) p += b[c] * glm::dvec3(low.corner_position(std::size_t(t), c));
      const glm::dvec3 world = decode_tangent_normal(interpolate_frame(frames, std::size_t(t), b), decode_rgb(map.at(x, y)));
      fn(x, y, world, p, std::size_t(t));
    }
}

std::size_t texels_traced_otherwise(const Mesh& low, const TraceInputs& traced, const BakeOptions& o, const BakeResult& r,
                                    std::size_t* covered, const UvTileFilter* tile) {
  std::vector<std::uint32_t> texels;
  for (std::uint32_t i = 0; i < r.coverage.size(); ++i)
    if (r.coverage[i]) texels.push_back(i);
  if (covered) *covered = texels.size();
  const TileBins bins = bin_triangles(low, o.width, o.height, trace_tile_side(o), tile);
  const std::vector<glm::dvec3> v = trace_texels(traced.s, traced.scene, bins, traced.rays, o, 2, r.stats, texels);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double n = std::fabs(v[i][c]) < 1e-6 ? 0.0 : v[i][c];  // the trace's snap to 0 (trace.cpp)
      if (float(n * 0.5 + 0.5) != r.map.pixels[3 * std::size_t(texels[i]) + std::size_t(c)]) {
        ++differ;
        break;
      }
    }
  return differ;
}

}  // namespace nmbake::test
