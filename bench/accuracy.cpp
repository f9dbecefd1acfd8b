// nmbake_accuracy: angular error against run time for map sizes and samples per texel.
//
// For every scene and setting it bakes in-process (bake_normal_map), takes the stage times from
// BakeStats, measures the angular error of the float map at every texel centre (both the bake and
// the reference decoded with the low-poly's tangent frame there), and writes accuracy.csv,
// accuracy.md (with the machine, date and commit) and accuracy.png (error against seconds).
//  - Analytic scenes: the reference is the exact normal, averaged over the texel with a 4x4
//    Gauss-Legendre rule in the low-poly tangent frame (the value an infinitely sampled bake of the
//    analytic surface would hold), so both the sampling error and the high-poly's tessellation
//    show.
//  - Real scenes: the reference is a 64-sample bake at the same size.
//  - Appearance: nmview --compare RMSE of the written map, when nmview is given.
//  - Hard assets (accuracy_hard_assets.h): known-answer models where rays can land on the wrong
//    part, with four hit settings; hard_assets.csv and a section of accuracy.md (hard_assets.md
//    when they run alone).
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "accuracy_hard_assets.h"
#include "accuracy_plot.h"
#include "pipeline/bake.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "core/parallel.h"
#include "procedural.h"
#include "core/rasterize.h"
#include "raycast.h"
#include "core/tangent_frames.h"

using namespace nmbake;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = 180.0 / kPi;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double angle_deg(const glm::dvec3& a, const glm::dvec3& b) { return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * kDeg; }

glm::dvec3 decode_rgb(const float* c) {
  const glm::dvec3 v(2.0 * c[0] - 1.0, 2.0 * c[1] - 1.0, 2.0 * c[2] - 1.0);
  const double len = glm::length(v);
  return len > 0.0 ? v / len : glm::dvec3(0, 0, 1);
}

// As image_io writes integer formats: round half away from zero, clamp.
float quantize(float c, int bits) {
  const double scale = double((1u << bits) - 1u);
  return float(std::clamp(std::round(double(c) * scale), 0.0, scale) / scale);
}

// ---- Scenes ----

// World normal of the analytic surface where the bake's ray from low-poly point `p` meets it.
using AnalyticNormal = std::function<glm::dvec3(const glm::dvec3& p)>;

struct Scene {
  std::string name, description, reference;
  Mesh low, high;
  float front = -1, rear = -1;  // < 0: measured by the bake
  AnalyticNormal analytic;      // empty for real scenes
  std::vector<int> sizes;
  bool quantization_runs = false;  // also measure 8- and 16-bit output
  std::string low_file, high_file;  // on disk, for nmview (written for generated meshes)
};

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


Scene height_field_scene(bool quick) {
  // z = 0.05 sin(2 pi x) sin(3 pi y) on [-1,1]^2, 513 x 513 vertices, analytic normals (issue 2).
  auto h = [](double x, double y) { return 0.05 * std::sin(2 * kPi * x) * std::sin(3 * kPi * y); };
  auto n = [](double x, double y) {
    const double hx = 0.05 * 2 * kPi * std::cos(2 * kPi * x) * std::sin(3 * kPi * y);
    const double hy = 0.05 * 3 * kPi * std::sin(2 * kPi * x) * std::cos(3 * kPi * y);
    return glm::normalize(glm::dvec3(-hx, -hy, 1.0));
  };
  Scene s;
  s.name = "height_field";
  s.description = "z = 0.05 sin(2 pi x) sin(3 pi y) on [-1,1]^2, 513x513 grid with analytic normals, over one quad";
  s.reference = "analytic";
  s.high = make_height_field(512, 512, h, n);
  s.low = make_height_field(1, 1, [](double, double) { return 0.0; }, [](double, double) { return glm::dvec3(0, 0, 1); });
  s.front = s.rear = 0.06f;
  // Rays run along -z from (x, y, 0): the surface is met at (x, y, h(x, y)).
  s.analytic = [n](const glm::dvec3& p) { return n(p.x, p.y); };
  s.sizes = quick ? std::vector<int>{64, 128} : std::vector<int>{512, 1024, 2048, 4096};
  return s;
}

Scene displaced_sphere_scene(bool quick) {
  const double a = 0.03, k = 41;  // k odd (procedural.h)
  auto radius = [=](double th, double ph) { return procedural::displaced_sphere_radius(a, k, th, ph); };
  auto normal = [=](double th, double ph) { return procedural::displaced_sphere_normal(a, k, th, ph); };
  auto unit = [](double th, double ph) { return glm::dvec3(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)); };
  Scene s;
  s.name = "displaced_sphere";
  const int nphi = quick ? 512 : 2048;
  s.description = "r = 1 + 0.03 sin(41 theta) sin(41 phi), " + std::to_string(nphi) + "x" + std::to_string(nphi / 2) +
                  " lat-long grid with analytic normals, over a 48x24 lat-long sphere";
  s.reference = "analytic";
  s.high = procedural::make_sphere(nphi, nphi / 2, radius, normal);
  s.low = procedural::make_sphere(48, 24, [](double, double) { return 1.0; }, unit);
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

Scene sculpt_scene(const std::string& data, const std::string& name, bool quick) {
  Scene s;
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
Scene scan_scene(const std::string& data, const std::string& file, bool quick) {
  Scene s;
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
  const glm::dvec3 faces[6][3] = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},  {{-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
                                  {{0, 1, 0}, {0, 0, 1}, {1, 0, 0}},  {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
                                  {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}},  {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}}};
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

// ---- Writing meshes for nmview ----

void write_obj(const std::string& path, const Mesh& m) {
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

// Binary PLY with per-vertex normals (normals must be indexed like positions).
void write_ply(const std::string& path, const Mesh& m) {
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

// ---- Reference per texel ----

// Per texel: the low-poly triangle and barycentrics at its centre (tri < 0: excluded), and the
// reference tangent-space unit vector.
struct TexelRef {
  glm::vec3 ref{0.0f};
  std::int32_t tri = -1;
  float b1 = 0, b2 = 0;
};

// Texel centres (and, with `analytic`, the 4x4 Gauss-Legendre points) against the low-poly's UV
// layout, the lowest triangle index winning as in the bake. With `analytic`, a texel is kept only
// when all 16 points are covered, and ref is the weighted mean of the analytic normal's tangent-
// space vectors, renormalized.
std::vector<TexelRef> texel_references(const Mesh& low, const TangentFrames& frames, int W, int H,
                                       const AnalyticNormal* analytic) {
  static const double g[4] = {0.5 - 0.5 * 0.8611363115940526, 0.5 - 0.5 * 0.3399810435848563,
                              0.5 + 0.5 * 0.3399810435848563, 0.5 + 0.5 * 0.8611363115940526};
  static const double gw[4] = {0.1739274225687269, 0.3260725774312731, 0.3260725774312731, 0.1739274225687269};
  const int points = analytic ? 17 : 1;  // point 16 (or 0) is the centre
  std::vector<TexelRef> out(std::size_t(W) * H);
  constexpr int kBand = 16;
  const int bands = (H + kBand - 1) / kBand;
  std::vector<TexelTriangle> tt(low.triangle_count());
  std::vector<std::vector<std::uint32_t>> band_tris(static_cast<std::size_t>(bands));
  for (std::size_t t = 0; t < low.triangle_count(); ++t) {
    tt[t] = setup_texel_triangle(low.corner_uv(t, 0), low.corner_uv(t, 1), low.corner_uv(t, 2), W, H);
    if (!tt[t].valid() || tt[t].xmax < tt[t].xmin || tt[t].ymax < tt[t].ymin) continue;
    for (int b = tt[t].ymin / kBand; b <= tt[t].ymax / kBand; ++b) band_tris[std::size_t(b)].push_back(std::uint32_t(t));
  }
  parallel_chunks(0, std::size_t(bands), 1, [&](std::size_t b0, std::size_t b1) {
    std::vector<std::uint32_t> mask;
    std::vector<glm::dvec3> acc;
    for (std::size_t band = b0; band < b1; ++band) {
      const int y0 = int(band) * kBand, y1 = std::min(H, y0 + kBand);
      mask.assign(std::size_t(y1 - y0) * W, 0u);
      acc.assign(std::size_t(y1 - y0) * W, glm::dvec3(0.0));
      for (std::uint32_t t : band_tris[band]) {
        const TexelTriangle& tri = tt[t];
        for (int y = std::max(y0, tri.ymin); y <= std::min(y1 - 1, tri.ymax); ++y)
          for (int x = tri.xmin; x <= tri.xmax; ++x) {
            const std::size_t li = std::size_t(y - y0) * W + x;
            for (int k = 0; k < points; ++k) {
              if (mask[li] & (1u << k)) continue;
              const bool centre = k == points - 1;
              const double ox = centre ? 0.5 : g[k % 4], oy = centre ? 0.5 : g[k / 4];
              double b[3];
              if (!covers(tri, sample_point(x, y, ox, oy), b)) continue;
              mask[li] |= 1u << k;
              if (centre) {
                TexelRef& r = out[std::size_t(y) * W + x];
                r.tri = std::int32_t(t);
                r.b1 = float(b[1]);
                r.b2 = float(b[2]);
                continue;
              }
              glm::dvec3 p(0.0);
              for (int c = 0; c < 3; ++c) p += b[c] * glm::dvec3(low.corner_position(t, c));
              const glm::dvec3 world = (*analytic)(p);
              acc[li] += gw[k % 4] * gw[k / 4] * encode_tangent_normal(interpolate_frame(frames, t, b), world);
            }
          }
      }
      for (int y = y0; y < y1; ++y)
        for (int x = 0; x < W; ++x) {
          const std::size_t li = std::size_t(y - y0) * W + x;
          TexelRef& r = out[std::size_t(y) * W + x];
          if (!analytic) continue;
          if (mask[li] != (1u << points) - 1u || glm::length(acc[li]) == 0.0) {
            r.tri = -1;
            continue;
          }
          r.ref = glm::vec3(glm::normalize(acc[li]));
        }
    }
  });
  return out;
}

// ---- Error statistics ----

struct ErrorStats {
  double mean = 0, rms = 0, p95 = 0, max = 0, over1 = 0;
  std::size_t texels = 0;
};

// The bake's map (quantised to `bits` unless 32) against the references, both decoded with the
// low-poly frame at the texel centre. `ref_map` (real scenes) overrides TexelRef::ref.
ErrorStats measure(const Image& map, const std::vector<std::uint8_t>& coverage, const std::vector<TexelRef>& refs,
                   const Image* ref_map, const TangentFrames& frames, int bits) {
  std::vector<float> err(refs.size(), -1.0f);
  parallel_chunks(0, refs.size(), 4096, [&](std::size_t i0, std::size_t i1) {
    for (std::size_t i = i0; i < i1; ++i) {
      const TexelRef& r = refs[i];
      if (r.tri < 0 || !coverage[i]) continue;
      float c[3] = {map.pixels[3 * i], map.pixels[3 * i + 1], map.pixels[3 * i + 2]};
      if (bits != 32)
        for (float& v : c) v = quantize(v, bits);
      const double b[3] = {1.0 - double(r.b1) - double(r.b2), double(r.b1), double(r.b2)};
      const PixelFrame f = interpolate_frame(frames, std::size_t(r.tri), b);
      const glm::dvec3 ref = ref_map ? decode_rgb(&ref_map->pixels[3 * i]) : glm::dvec3(r.ref);
      err[i] = float(angle_deg(decode_tangent_normal(f, decode_rgb(c)), decode_tangent_normal(f, ref)));
    }
  });
  err.erase(std::remove(err.begin(), err.end(), -1.0f), err.end());
  ErrorStats s;
  s.texels = err.size();
  if (err.empty()) return s;
  double sum = 0, sum2 = 0;
  std::size_t over = 0;
  for (float e : err) sum += e, sum2 += double(e) * e, over += e > 1.0f, s.max = std::max(s.max, double(e));
  s.mean = sum / double(err.size());
  s.rms = std::sqrt(sum2 / double(err.size()));
  s.over1 = double(over) / double(err.size());
  const std::size_t k = std::min(err.size() - 1, std::size_t(0.95 * double(err.size() - 1) + 0.5));
  std::nth_element(err.begin(), err.begin() + std::ptrdiff_t(k), err.end());
  s.p95 = err[k];
  return s;
}

// Mean angle between the reference and its own value rounded to `bits`: the floor that bit depth
// puts under any bake of the scene.
double quantization_floor(const std::vector<TexelRef>& refs, const TangentFrames& frames, int bits) {
  double sum = 0;
  std::size_t n = 0;
  for (const TexelRef& r : refs) {
    if (r.tri < 0) continue;
    float c[3];
    for (int k = 0; k < 3; ++k) c[k] = quantize(float(double(r.ref[k]) * 0.5 + 0.5), bits);
    const double b[3] = {1.0 - double(r.b1) - double(r.b2), double(r.b1), double(r.b2)};
    const PixelFrame f = interpolate_frame(frames, std::size_t(r.tri), b);
    sum += angle_deg(decode_tangent_normal(f, decode_rgb(c)), decode_tangent_normal(f, glm::dvec3(r.ref)));
    ++n;
  }
  return n ? sum / double(n) : 0.0;
}

// ---- Appearance: nmview --compare ----

std::string run_capture(const std::string& cmd) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  for (std::size_t n; (n = fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
  pclose(p);
  return out;
}

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// RMSE from the last "psnr=... rmse=... within2=..." line, or < 0 when nmview failed.
double appearance_rmse(const std::string& nmview, const std::string& low, const std::string& map, const std::string& high) {
  // nmview --compare leaves nmview-compare-worst.png in its working folder: run it beside the map.
  const std::string out = run_capture("cd " + quote(fs::path(map).parent_path().string()) + " && " + quote(nmview) + " " +
                                      quote(fs::absolute(low).string()) + " " + quote(fs::absolute(map).string()) + " " +
                                      quote(fs::absolute(high).string()) +
                                      " --compare --size 800x400 2>/dev/null");
  const auto pos = out.rfind("rmse=");
  if (pos == std::string::npos || out.rfind("psnr=") == std::string::npos) return -1.0;
  return std::atof(out.c_str() + pos + 5);
}

// ---- Machine, date, commit ----

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

// The 1, 5 and 15 minute load averages: timings taken while other programs ran are slower.
std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return in ? a + " " + b + " " + c : std::string("unknown");
}

std::string git_commit() {
  std::string c = run_capture("git -C " + quote(NMBAKE_SOURCE_DIR) + " describe --always --dirty --abbrev=12 2>/dev/null");
  while (!c.empty() && (c.back() == '\n' || c.back() == '\r')) c.pop_back();
  return c.empty() ? "unknown (not a git checkout)" : c;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", std::gmtime(&t));
  return buf;
}

// ---- Rows ----

struct Row {
  std::string scene, reference;
  int size = 0, samples = 0, bits = 32;
  ErrorStats err;
  std::uint64_t rays = 0, misses = 0;
  double prepare = 0, bvh = 0, distances = 0, trace = 0, padding = 0, total = 0;
  double reference_seconds = 0;  // building the reference (not part of the bake)
  double appearance = -1;       // nmview RMSE, < 0: not measured
};

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

struct Args {
  bool quick = false;
  bool check = false;  // exit 1 unless every analytic scene's error falls from the first setting to the last
  std::vector<std::string> scenes;
  std::string out = "docs/accuracy", data = NMBAKE_SHARED_DATA, nmview = NMBAKE_NMVIEW;
  std::string font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
};

const char* kUsage =
    "usage: nmbake_accuracy [--quick] [--scenes a,b] [--out DIR] [--data DIR] [--nmview PATH|none] [--font TTF]\n"
    "Bakes every scene at sizes 512, 1024, 2048 (height_field also 4096) with 1, 4 and 16 samples and writes\n"
    "DIR/accuracy.csv, DIR/accuracy.md and DIR/accuracy.png (default DIR: docs/accuracy).\n"
    "Scenes: height_field, displaced_sphere (analytic), suz_L4, torus_s3 (sculpts), bunny00 (scan; needs --data),\n"
    "hard_assets (the known-answer models of tests/procedural at 512 and 1024 with 1 sample and four hit settings;\n"
    "writes DIR/hard_assets.csv and a section of accuracy.md, or DIR/hard_assets.md when it runs alone).\n"
    "--quick: sizes 64 and 128 (real scenes 128, hard assets 256), samples 1 and 4, a coarse sphere: a smoke check of seconds.\n"
    "--check: exit 1 unless on every analytic scene the float error of the largest size and samples is below a\n"
    "quarter of the smallest's (the smoke test in ctest).\n";

}  // namespace

int main(int argc, char** argv) {
  Args a;
  const std::string load_at_start = load_average();
  std::string command = "nmbake_accuracy";
  for (int i = 1; i < argc; ++i) {
    const std::string s = argv[i];
    command += " " + s;
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "error: %s needs a value\n%s", s.c_str(), kUsage);
        std::exit(1);
      }
      command += std::string(" ") + argv[i + 1];
      return argv[++i];
    };
    if (s == "--quick") a.quick = true;
    else if (s == "--check") a.check = true;
    else if (s == "--scenes") {
      std::stringstream ss(value());
      for (std::string t; std::getline(ss, t, ',');)
        if (!t.empty()) a.scenes.push_back(t);
    } else if (s == "--out") a.out = value();
    else if (s == "--data") a.data = value();
    else if (s == "--nmview") a.nmview = value();
    else if (s == "--font") a.font = value();
    else if (s == "--help" || s == "-h") {
      std::printf("%s", kUsage);
      return 0;
    } else {
      std::fprintf(stderr, "error: unknown argument %s\n%s", s.c_str(), kUsage);
      return 1;
    }
  }
  if (a.nmview == "none") a.nmview.clear();
  if (!a.nmview.empty() && ::access(a.nmview.c_str(), X_OK) != 0) {
    std::fprintf(stderr, "nmbake_accuracy: %s not executable: no appearance figures\n", a.nmview.c_str());
    a.nmview.clear();
  }
  const bool default_scenes = a.scenes.empty();
  if (default_scenes)
    a.scenes = a.quick ? std::vector<std::string>{"height_field", "displaced_sphere", "hard_assets"}
                       : std::vector<std::string>{"height_field", "displaced_sphere", "suz_L4", "torus_s3", "bunny00", "hard_assets"};
  const std::vector<int> sample_counts = a.quick ? std::vector<int>{1, 4} : std::vector<int>{1, 4, 16};
  const auto start = Clock::now();
  const std::string commit = git_commit(), date = utc_now();
  try {
    fs::create_directories(a.out);
    const std::string work = (fs::path(a.out) / ".work").string();
    if (!a.nmview.empty()) fs::create_directories(work);
    std::vector<Row> rows;
    std::vector<std::string> notes;
    std::map<std::string, double> floor8, floor16;  // per analytic scene, mean over its sizes
    double appearance_seconds = 0;  // nmview runs
    std::vector<bench::HardAssetRow> hard_rows;
    std::vector<std::string> hard_notes;
    double hard_seconds = 0;
    for (const std::string& name : a.scenes) {
      Scene sc;
      auto t0 = Clock::now();
      if (name == "hard_assets") {
        hard_rows = bench::run_hard_assets(a.quick ? std::vector<int>{256} : std::vector<int>{512, 1024}, hard_notes);
        hard_seconds = since(t0);
        std::fprintf(stderr, "nmbake_accuracy: hard_assets done in %.0f s, %.0f s since the start\n", hard_seconds, since(start));
        continue;
      }
      if (name == "height_field") sc = height_field_scene(a.quick);
      else if (name == "displaced_sphere") sc = displaced_sphere_scene(a.quick);
      else if (name == "suz_L4" || name == "torus_s3" || name == "suz_L3" || name == "torus_demo") {
        if (!fs::exists(a.data + "/sculpts/" + name)) {
          std::fprintf(stderr, "nmbake_accuracy: skipping %s: %s/sculpts/%s not found\n", name.c_str(), a.data.c_str(), name.c_str());
          continue;
        }
        sc = sculpt_scene(a.data, name, a.quick);
      } else if (fs::exists(a.data + "/meshes/cgal/" + name + ".off")) {
        sc = scan_scene(a.data, name + ".off", a.quick);
      } else {
        std::fprintf(stderr, "nmbake_accuracy: skipping %s: unknown scene or data not found under %s\n", name.c_str(), a.data.c_str());
        continue;
      }
      std::fprintf(stderr, "nmbake_accuracy: %s: %s (set up in %.1f s)\n", sc.name.c_str(), sc.description.c_str(), since(t0));
      notes.push_back("`" + sc.name + "`: " + sc.description + "; reference: " + sc.reference + ".");
      if (!a.nmview.empty()) {
        if (sc.low_file.empty()) write_obj(sc.low_file = work + "/" + sc.name + "_low.obj", sc.low);
        if (sc.high_file.empty()) write_ply(sc.high_file = work + "/" + sc.name + "_high.ply", sc.high);
      }
      const TangentFrames frames = compute_tangent_frames(sc.low);
      double f8 = 0, f16 = 0;
      for (int size : sc.sizes) {
        BakeOptions o;
        o.width = o.height = size;
        o.front = sc.front;
        o.rear = sc.rear;
        // Reference.
        t0 = Clock::now();
        BakeResult reference_bake;
        std::vector<TexelRef> refs;
        if (sc.analytic) {
          refs = texel_references(sc.low, frames, size, size, &sc.analytic);
          f8 += quantization_floor(refs, frames, 8) / double(sc.sizes.size());
          f16 += quantization_floor(refs, frames, 16) / double(sc.sizes.size());
        } else {
          BakeOptions ro = o;
          ro.samples = 64;
          reference_bake = bake_normal_map(sc.low, sc.high, nullptr, ro);
          refs = texel_references(sc.low, frames, size, size, nullptr);
        }
        const double ref_seconds = since(t0);
        for (int samples : sample_counts) {
          if (size >= 4096 && samples > 4) continue;  // 268M rays: minutes on 2 cores for a point that says nothing new
          o.samples = samples;
          t0 = Clock::now();
          BakeResult r = bake_normal_map(sc.low, sc.high, nullptr, o);
          const double wall = since(t0);
          Row row;
          row.scene = sc.name;
          row.reference = sc.reference;
          row.size = size;
          row.samples = samples;
          row.rays = r.stats.rays;
          row.misses = r.stats.misses;
          row.prepare = r.stats.seconds_prepare;
          row.bvh = r.stats.seconds_bvh;
          row.distances = r.stats.seconds_distances;
          row.trace = r.stats.seconds_trace;
          row.padding = r.stats.seconds_padding;
          row.total = wall;
          row.reference_seconds = ref_seconds;
          const Image* ref_map = sc.analytic ? nullptr : &reference_bake.map;
          if (!a.nmview.empty() && !sc.high_file.empty()) {
            const std::string map_path = work + "/map.png";
            WriteOptions wo;
            wo.bits = 16;
            write_image(map_path, r.map, wo);
            t0 = Clock::now();
            row.appearance = appearance_rmse(a.nmview, sc.low_file, map_path, sc.high_file);
            appearance_seconds += since(t0);
          }
          for (int bits : sc.quantization_runs ? std::vector<int>{32, 16, 8} : std::vector<int>{32}) {
            row.bits = bits;
            row.err = measure(r.map, r.coverage, refs, ref_map, frames, bits);
            rows.push_back(row);
            std::fprintf(stderr,
                         "  %-16s %4d x %-2d %2d-bit  mean %.4f  rms %.4f  p95 %.4f  max %.3f deg  >1deg %.2f%%  misses %llu  "
                         "trace %.2f s  total %.2f s  %.2f Mrays/s%s\n",
                         sc.name.c_str(), size, samples, bits, row.err.mean, row.err.rms, row.err.p95, row.err.max,
                         100 * row.err.over1, (unsigned long long)row.misses, row.trace, row.total,
                         row.trace > 0 ? 1e-6 * double(row.rays) / row.trace : 0.0,
                         row.appearance >= 0 ? (" appearance rmse " + fmt("%.5f", row.appearance)).c_str() : "");
          }
        }
      }
      if (sc.analytic) floor8[sc.name] = f8, floor16[sc.name] = f16;
      std::fprintf(stderr, "nmbake_accuracy: %s done, %.0f s since the start\n", sc.name.c_str(), since(start));
    }
    if (!a.nmview.empty()) fs::remove_all(work);
    const double run_seconds = since(start);

    // CSV.
    if (!hard_rows.empty()) bench::write_hard_assets_csv((fs::path(a.out) / "hard_assets.csv").string(), hard_rows);
    if (!rows.empty()) {
      std::ofstream f(fs::path(a.out) / "accuracy.csv");
      f << "scene,reference,size,samples,bits,texels,mean_deg,rms_deg,p95_deg,max_deg,share_over_1deg,misses,rays,"
           "prepare_s,bvh_s,distances_s,trace_s,padding_s,total_s,rays_per_s,reference_s,appearance_rmse\n";
      for (const Row& r : rows)
        f << r.scene << ',' << r.reference << ',' << r.size << ',' << r.samples << ',' << r.bits << ',' << r.err.texels << ','
          << fmt("%.6f", r.err.mean) << ',' << fmt("%.6f", r.err.rms) << ',' << fmt("%.6f", r.err.p95) << ','
          << fmt("%.6f", r.err.max) << ',' << fmt("%.6f", r.err.over1) << ',' << r.misses << ',' << r.rays << ','
          << fmt("%.4f", r.prepare) << ',' << fmt("%.4f", r.bvh) << ',' << fmt("%.4f", r.distances) << ','
          << fmt("%.4f", r.trace) << ',' << fmt("%.4f", r.padding) << ',' << fmt("%.4f", r.total) << ','
          << fmt("%.0f", r.trace > 0 ? double(r.rays) / r.trace : 0.0) << ',' << fmt("%.3f", r.reference_seconds) << ','
          << (r.appearance >= 0 ? fmt("%.6f", r.appearance) : std::string()) << '\n';
      if (!f) throw OutputError((fs::path(a.out) / "accuracy.csv").string() + ": cannot write");
    }
    // Markdown: accuracy.md, or hard_assets.md when only the hard assets ran (so that run does
    // not overwrite the accuracy table).
    const std::string md_name = rows.empty() && !hard_rows.empty() ? "hard_assets.md" : "accuracy.md";
    {
      std::ofstream f(fs::path(a.out) / md_name);
      f << "Written by `" << command << "` on " << date << ", commit `" << commit << "`, "
        << std::thread::hardware_concurrency() << " cores (" << cpu_model() << "); the whole run took "
        << fmt("%.0f", run_seconds) << " s"
        << (a.nmview.empty() ? std::string() : " (" + fmt("%.0f", appearance_seconds) + " s of it in nmview)")
        << "; load average " << load_at_start << " at the start, " << load_average() << " at the end.\n\n";
      if (!rows.empty()) {
        f << "Angular error in degrees over the texels whose centre lies in the UV layout (analytic scenes: whose 4x4 "
             "Gauss-Legendre points all do), the map and the reference both decoded with the low-poly tangent frame at the "
             "texel centre. Float map unless `bits` says 8 or 16 (the map rounded as the PNG/TIFF writer rounds it). "
             "Reference `analytic`: the exact normal of the analytic surface where the bake's ray meets it, averaged over "
             "the texel (4x4 Gauss-Legendre, in the tangent frame), i.e. what an infinitely sampled bake of the exact surface "
             "would hold; reference `64-sample bake`: a bake with 64 samples per texel at the same size. Seconds are the "
             "in-process bake (`bake_normal_map`: prepare, BVH, ray distances, trace, padding; no file loading or writing), "
             "rays/s = rays / trace seconds. The 4096^2 size is baked with 1 and 4 samples only.";
        if (!a.nmview.empty()) f << " `view rmse`: `nmview --compare` RMSE (0..1) of the map written as 16-bit PNG, 800x400, 10 views.";
        f << "\n\n";
        for (const std::string& n : notes) f << "- " << n << "\n";
        for (const auto& [scene, v] : floor8)
          f << "- Quantisation floor of `" << scene << "` (its reference rounded and decoded): 8-bit " << fmt("%.4f", v)
            << " deg mean, 16-bit " << fmt("%.5f", floor16[scene]) << " deg mean.\n";
        f << "\n| scene | reference | size | samples | bits | mean | RMS | p95 | max | >1 deg | misses | prepare s | bvh s | "
             "distances s | trace s | padding s | total s | Mrays/s |"
          << (a.nmview.empty() ? "" : " view rmse |") << "\n";
        f << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|" << (a.nmview.empty() ? "" : "---|") << "\n";
        for (const Row& r : rows) {
          f << "| " << r.scene << " | " << r.reference << " | " << r.size << " | " << r.samples << " | "
            << (r.bits == 32 ? std::string("float") : std::to_string(r.bits)) << " | " << fmt("%.4f", r.err.mean) << " | "
            << fmt("%.4f", r.err.rms) << " | " << fmt("%.4f", r.err.p95) << " | " << fmt("%.3f", r.err.max) << " | "
            << fmt("%.2f%%", 100 * r.err.over1) << " | " << r.misses << " | " << fmt("%.3f", r.prepare) << " | "
            << fmt("%.3f", r.bvh) << " | " << fmt("%.3f", r.distances) << " | " << fmt("%.3f", r.trace) << " | "
            << fmt("%.3f", r.padding) << " | " << fmt("%.3f", r.total) << " | "
            << fmt("%.2f", r.trace > 0 ? 1e-6 * double(r.rays) / r.trace : 0.0) << " |";
          if (!a.nmview.empty()) f << ' ' << (r.appearance >= 0 ? fmt("%.5f", r.appearance) : std::string("-")) << " |";
          f << "\n";
        }
      }
      if (!hard_rows.empty()) f << (rows.empty() ? "" : "\n") << bench::hard_assets_markdown(hard_rows, hard_notes, hard_seconds);
      if (!f) throw OutputError((fs::path(a.out) / md_name).string() + ": cannot write");
    }
    // Plot: mean error against bake seconds, one polyline per scene and size (samples 1 -> 4 -> 16).
    if (!rows.empty()) {
      std::vector<bench::PlotSeries> series;
      std::map<std::string, std::size_t> index;
      for (const Row& r : rows) {
        if (r.bits == 16) continue;
        const std::string key = r.scene + (r.bits == 8 ? " 8-bit" : "") + (r.reference == "analytic" ? "" : " (vs 64 spp)");
        if (!index.count(key)) {
          index[key] = series.size();
          series.push_back({key, {}, r.bits == 8});
        }
        bench::PlotSeries& s = series[index[key]];
        if (s.lines.empty() || s.lines.back().front().label.rfind(std::to_string(r.size) + "x", 0) != 0) s.lines.emplace_back();
        s.lines.back().push_back({r.total, std::max(r.err.mean, 1e-6), std::to_string(r.size) + "x" + std::to_string(r.samples)});
      }
      std::vector<bench::PlotHLine> hl;
      for (const auto& [scene, v] : floor8)
        if (scene == "displaced_sphere" || floor8.size() == 1) hl.push_back({v, "8-bit quantisation floor (" + fmt("%.3f", v) + " deg)"});
      bench::write_log_log_plot((fs::path(a.out) / "accuracy.png").string(),
                                "nmbake: mean angular error against bake time (labels: size x samples)",
                                "bake seconds (in-process, log)", "mean error, degrees (log)", series, hl,
                                date + ", commit " + commit + ", " + std::to_string(std::thread::hardware_concurrency()) +
                                    " cores, " + cpu_model(),
                                a.font);
    }
    std::fprintf(stderr, "nmbake_accuracy: wrote %s/%s; %zu rows%s in %.0f s\n", a.out.c_str(),
                 rows.empty() ? md_name.c_str() : "accuracy.{csv,md,png}", rows.size(),
                 hard_rows.empty() ? "" : (", hard_assets.csv (" + std::to_string(hard_rows.size()) + " rows)").c_str(), run_seconds);
    if (a.check) {
      std::map<std::string, std::pair<double, double>> first_last;  // analytic scene -> (first, last) float mean error
      for (const Row& r : rows)
        if (r.reference == "analytic" && r.bits == 32) {
          auto it = first_last.find(r.scene);
          if (it == first_last.end()) first_last[r.scene] = {r.err.mean, r.err.mean};
          else it->second.second = r.err.mean;
        }
      if (first_last.empty()) {
        std::fprintf(stderr, "check failed: no analytic scene was run\n");
        return 1;
      }
      for (const auto& [scene, fl] : first_last)
        if (!(fl.second < 0.25 * fl.first) || !(fl.second > 0.0)) {
          std::fprintf(stderr, "check failed: %s: error %.5f deg at the last setting, %.5f at the first\n", scene.c_str(), fl.second,
                       fl.first);
          return 1;
        }
      std::fprintf(stderr, "check passed: the analytic scenes' error falls with size and samples\n");
    }
  } catch (const Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return int(e.code());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 0;
}
