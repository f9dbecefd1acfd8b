#include "accuracy_scenes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "bench_support.h"
#include "core/errors.h"
#include "io/mesh_io.h"
#include "procedural.h"
#include "raycast.h"

namespace nmbake::bench {

namespace fs = std::filesystem;

namespace {

// A grid of nx x ny quads over [-1,1]^2 at z = height(x,y) with normals normal(x,y); UVs onto [0,1]^2.
Mesh make_height_field(int nx, int ny, const std::function<double(double, double)>& height,
                       const std::function<glm::dvec3(double, double)>& normal) {
  Mesh m;
  m.source = "height field";
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const double s = double(i) / nx, t = double(j) / ny, x = -1 + 2 * s, y = -1 + 2 * t;
      m.positions.push_back(glm::vec3(float(x), float(y), float(height(x, y))));
      m.normals.push_back(glm::vec3(normal(x, y)));
      m.uvs.push_back({float(s), float(t)});
    }
  auto id = [&](int i, int j) { return std::uint32_t(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      for (std::uint32_t v : {id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j), id(i + 1, j + 1), id(i, j + 1)}) {
        m.position_index.push_back(v);
        m.uv_index.push_back(v);
        m.normal_index.push_back(v);
      }
  m.source_face.assign(m.triangle_count(), 0);
  return m;
}

}  // namespace

AccuracyScene height_field_scene(bool quick) {
  // z = 0.05 sin(2 pi x) sin(3 pi y) on [-1,1]^2, 513 x 513 vertices, analytic normals (issue 2).
  auto h = [](double x, double y) { return 0.05 * std::sin(2 * kPi * x) * std::sin(3 * kPi * y); };
  auto n = [](double x, double y) {
    const double hx = 0.05 * 2 * kPi * std::cos(2 * kPi * x) * std::sin(3 * kPi * y);
    const double hy = 0.05 * 3 * kPi * std::sin(2 * kPi * x) * std::cos(3 * kPi * y);
    return glm::normalize(glm::dvec3(-hx, -hy, 1.0));
  };
  AccuracyScene s;
  s.name = "height_field";
  s.description = "z = 0.05 sin(2 pi x) sin(3 pi y) on [-1,1]^2, 513x513 grid with analytic normals, over one quad";
  s.reference = "analytic";
  s.high = make_height_field(512, 512, h, n);
  s.low = make_height_field(
      1, 1, [](double, double) { return 0.0; }, [](double, double) { return glm::dvec3(0, 0, 1); });
  s.front = s.rear = 0.06f;
  // Rays run along -z from (x, y, 0): the surface is met at (x, y, h(x, y)).
  s.analytic = [n](const glm::dvec3& p) { return n(p.x, p.y); };
  s.sizes = quick ? std::vector<int>{64, 128} : std::vector<int>{512, 1024, 2048, 4096};
  return s;
}

AccuracyScene displaced_sphere_scene(bool quick) {
  const double a = 0.03, k = 41;  // k odd (procedural.h)
  auto radius = [=](double th, double ph) { return procedural::displaced_sphere_radius(a, k, th, ph); };
  auto normal = [=](double th, double ph) { return procedural::displaced_sphere_normal(a, k, th, ph); };
  auto unit = [](double th, double ph) {
    return glm::dvec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
  };
  AccuracyScene s;
  s.name = "displaced_sphere";
  const int nphi = quick ? 512 : 2048;
  s.description = "r = 1 + 0.03 sin(41 theta) sin(41 phi), " + std::to_string(nphi) + "x" + std::to_string(nphi / 2) +
                  " lat-long grid with analytic normals, over a 48x24 lat-long sphere";
  s.reference = "analytic";
  s.high = procedural::make_sphere(nphi, nphi / 2, radius, normal);
  s.low = procedural::make_sphere(
      48, 24, [](double, double) { return 1.0; }, unit);
  s.front = s.rear = 0.05f;
  // The low-poly's vertices are unit vectors and its normals equal them, so the interpolated ray
  // normal is parallel to P: every ray is radial and meets the surface in direction P / |P|.
  s.analytic = [normal](const glm::dvec3& p) {
    const glm::dvec3 d = glm::normalize(p);
    return normal(std::acos(std::clamp(d.z, -1.0, 1.0)), std::atan2(d.y, d.x));
  };
  s.sizes = quick ? std::vector<int>{64, 128} : std::vector<int>{512, 1024, 2048};
  s.quantization_runs = true;
  return s;
}

AccuracyScene sculpt_scene(const std::string& data, const std::string& name, bool quick) {
  AccuracyScene s;
  s.name = name;
  s.low_file = data + "/sculpts/" + name + "/low.obj";
  s.high_file = data + "/sculpts/" + name + "/high.ply";
  LoadOptions lo;
  lo.require_uvs = true;
  s.low = load_mesh(s.low_file, lo);
  s.high = load_mesh(s.high_file);
  s.description = "sculpts/" + name + ": " + std::to_string(s.high.triangle_count()) + " high-poly triangles over " +
                  std::to_string(s.low.triangle_count()) + " low-poly, auto ray distances";
  s.reference = "64-sample bake";
  s.sizes = quick ? std::vector<int>{128} : std::vector<int>{512, 1024, 2048};
  return s;
}

// A scan over a low-poly made here: a cube-sphere (6 faces of n x n quads) whose vertices are
// projected radially from the scan's bounding-box centre onto its outermost surface, UVs from the
// six cube faces laid out as square islands in a 3 x 2 atlas (the bottom third of the map unused).
AccuracyScene scan_scene(const std::string& data, const std::string& file, bool quick) {
  AccuracyScene s;
  s.name = fs::path(file).stem().string();
  s.high_file = data + "/meshes/cgal/" + file;
  s.high = load_mesh(s.high_file);
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::vec3& p : s.high.positions) lo = glm::min(lo, glm::dvec3(p)), hi = glm::max(hi, glm::dvec3(p));
  const glm::dvec3 c = 0.5 * (lo + hi);
  const double reach = glm::length(hi - lo);
  std::vector<glm::vec3> pos(s.high.positions.size());
  for (std::size_t i = 0; i < pos.size(); ++i) pos[i] = glm::vec3(glm::dvec3(s.high.positions[i]) - c);
  raycast::Scene scene(&pos[0].x, pos.size(), s.high.position_index.data(), s.high.triangle_count());

  const int n = 16;
  const double margin = 0.02, side = 1.0 / 3.0 - 2 * margin;
  const glm::dvec3 faces[6][3] = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
                                  {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
                                  {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
  Mesh& m = s.low;
  m.source = s.name + " cube-sphere";
  std::map<std::array<int, 3>, std::uint32_t> welded;  // cube lattice point -> position index
  std::vector<double> radii;
  std::vector<glm::dvec3> dirs;
  for (int f = 0; f < 6; ++f) {
    const glm::dvec3 &nf = faces[f][0], &uf = faces[f][1], &vf = faces[f][2];
    const glm::dvec2 cell(margin + (f % 3) / 3.0, 1.0 - (f / 3 + 1) / 3.0 + margin);
    std::vector<std::uint32_t> pid((n + 1) * (n + 1)), uid((n + 1) * (n + 1));
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const glm::ivec3 q = glm::ivec3(nf) * n + glm::ivec3(uf) * (2 * i - n) + glm::ivec3(vf) * (2 * j - n);
        const std::array<int, 3> key{q.x, q.y, q.z};
        auto it = welded.find(key);
        if (it == welded.end()) {
          it = welded.emplace(key, std::uint32_t(dirs.size())).first;
          dirs.push_back(glm::normalize(glm::dvec3(q)));
        }
        pid[j * (n + 1) + i] = it->second;
        uid[j * (n + 1) + i] = std::uint32_t(m.uvs.size());
        m.uvs.push_back(glm::vec2(cell + side * glm::dvec2(double(i) / n, double(j) / n)));
      }
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int corner : {0, 1, 2, 0, 2, 3}) {
          const int ci = i + (corner == 1 || corner == 2), cj = j + (corner >= 2);
          m.position_index.push_back(pid[cj * (n + 1) + ci]);
          m.uv_index.push_back(uid[cj * (n + 1) + ci]);
        }
  }
  // Outermost surface along each direction: cast inward from outside the scan.
  m.positions.resize(dirs.size());
  std::vector<double> r(dirs.size(), -1.0);
  for (std::size_t v = 0; v < dirs.size(); ++v) {
    const raycast::Hit h = scene.intersect({glm::vec3(dirs[v] * reach), 0.0f, glm::vec3(-dirs[v]), float(reach)});
    if (h.hit()) r[v] = reach - double(h.t), radii.push_back(r[v]);
  }
  std::sort(radii.begin(), radii.end());
  const double fallback = radii.empty() ? 0.5 * reach : radii[radii.size() / 2];
  std::size_t missed = 0;
  for (std::size_t v = 0; v < dirs.size(); ++v) {
    missed += r[v] < 0;
    m.positions[v] = glm::vec3(c + dirs[v] * (r[v] < 0 ? fallback : r[v]));
  }
  m.source_face.assign(m.triangle_count(), 0);
  s.description = "meshes/cgal/" + file + ": " + std::to_string(s.high.triangle_count()) + " triangles over a " +
                  std::to_string(m.triangle_count()) + "-triangle cube-sphere projected onto it (" + std::to_string(missed) +
                  " of " + std::to_string(dirs.size()) + " vertices found no surface), auto ray distances";
  s.reference = "64-sample bake";
  s.sizes = quick ? std::vector<int>{128} : std::vector<int>{512, 1024, 2048};
  return s;
}

void write_scene_obj(const std::string& path, const Mesh& m) {
  std::ofstream f(path);
  char line[128];
  for (const glm::vec3& p : m.positions) f.write(line, std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", p.x, p.y, p.z));
  for (const glm::vec2& t : m.uvs) f.write(line, std::snprintf(line, sizeof line, "vt %.9g %.9g\n", t.x, t.y));
  for (const glm::vec3& n : m.normals) f.write(line, std::snprintf(line, sizeof line, "vn %.9g %.9g %.9g\n", n.x, n.y, n.z));
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    f << "f";
    for (int c = 0; c < 3; ++c) {
      f << ' ' << m.position_index[3 * t + c] + 1 << '/' << m.uv_index[3 * t + c] + 1;
      if (m.has_normals()) f << '/' << m.normal_index[3 * t + c] + 1;
    }
    f << '\n';
  }
  if (!f) throw OutputError(path + ": cannot write");
}

void write_scene_ply(const std::string& path, const Mesh& m) {
  std::ofstream f(path, std::ios::binary);
  f << "ply\nformat binary_little_endian 1.0\nelement vertex " << m.positions.size()
    << "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
    << "element face " << m.triangle_count() << "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<glm::vec3> normals(m.positions.size(), glm::vec3(0, 0, 1));
  for (std::size_t c = 0; c < m.position_index.size(); ++c) normals[m.position_index[c]] = m.normals[m.normal_index[c]];
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    f.write(reinterpret_cast<const char*>(&m.positions[i]), 12);
    f.write(reinterpret_cast<const char*>(&normals[i]), 12);
  }
  const unsigned char three = 3;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    f.write(reinterpret_cast<const char*>(&three), 1);
    f.write(reinterpret_cast<const char*>(&m.position_index[3 * t]), 12);
  }
  if (!f) throw OutputError(path + ": cannot write");
}

}  // namespace nmbake::bench
