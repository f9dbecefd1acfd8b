// The texture set's defaults, measured (issue 35; docs/accuracy/map_defaults.md): curvature
// smoothing against the analytic mean curvature of a jittered sphere and torus and against the
// texel-scale noise of the sculpts' curvature maps; AO and thickness against their distance, as a
// share of the scene's diagonal, on the sculpts. Prints markdown tables on stdout. Run by hand:
//   nmbake_map_defaults SHARED_DATA [--size N] [--threads N] [--rays N] [--only analytic|curvature|distance]
//                       [--sculpts torus_demo,suz_L3,suz_L4] [--base on]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "bench_support.h"
#include "core/curvature.h"
#include "core/maps.h"
#include "io/mesh_io.h"
#include "pipeline/bake.h"

using namespace nmbake;
using bench::kPi;

namespace {

// A closed torus around +Z (major radius R, tube r), nu x nv quads split in two, wound outwards,
// one position per grid point; with `jitter` > 0 each point moves along the surface by up to that
// share of a grid step in each parameter (irregular triangles, every vertex still on the torus).
Mesh make_jittered_torus(int nu, int nv, double R, double r, double jitter, std::mt19937& rng) {
  std::uniform_real_distribution<double> d(-jitter, jitter);
  Mesh m;
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double a = 2.0 * kPi * (i + d(rng)) / nu, b = 2.0 * kPi * (j + d(rng)) / nv;
      m.positions.push_back(glm::vec3(float((R + r * std::cos(b)) * std::cos(a)), float((R + r * std::cos(b)) * std::sin(a)),
                                      float(r * std::sin(b))));
    }
  const auto at = [&](int i, int j) { return std::uint32_t(((i + nu) % nu) * nv + (j + nv) % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j)
      for (std::uint32_t v : {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)})
        m.position_index.push_back(v);
  return m;
}

// A sphere of radius `r` from a cube's six faces of n x n quads pushed out radially (irregular in
// itself: the cube's corners make small triangles), each point jittered along the surface by up to
// `jitter` of a grid step.
Mesh make_jittered_cube_sphere(int n, double r, double jitter, std::mt19937& rng) {
  std::uniform_real_distribution<double> d(-jitter, jitter);
  Mesh m;
  const auto index = [&](int f, int i, int j) { return std::uint32_t((f * (n + 1) + i) * (n + 1) + j); };
  const glm::dvec3 axes[6][3] = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                 {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}}, {{0, -1, 0}, {1, 0, 0}, {0, 0, 1}},
                                 {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, -1}, {1, 0, 0}, {0, 1, 0}}};
  // Border points of a face are shared with its neighbour: jitter by a hash of the point so both
  // faces move them alike, and never off the border (weld_positions joins them by value).
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) {
        const bool border = i == 0 || j == 0 || i == n || j == n;
        const double s = 2.0 * (i + (border ? 0.0 : d(rng))) / n - 1.0, t = 2.0 * (j + (border ? 0.0 : d(rng))) / n - 1.0;
        const glm::dvec3 p = axes[f][0] + s * axes[f][1] + t * axes[f][2];
        m.positions.push_back(glm::vec3(r * glm::normalize(p)));
      }
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const std::uint32_t a = index(f, i, j), b = index(f, i + 1, j), c = index(f, i + 1, j + 1), e = index(f, i, j + 1);
        // Wound outwards: the first triangle's normal along its corner's position.
        const glm::dvec3 pa(m.positions[a]), pb(m.positions[b]), pc(m.positions[c]);
        if (glm::dot(glm::cross(pb - pa, pc - pa), pa) > 0.0)
          for (std::uint32_t v : {a, b, c, a, c, e}) m.position_index.push_back(v);
        else
          for (std::uint32_t v : {a, c, b, a, e, c}) m.position_index.push_back(v);
      }
  return m;
}

struct ErrorRow {
  double mean_rel = 0.0, p95_rel = 0.0, bias = 0.0;  // |H - exact| / |exact| mean and 95th percentile; mean(H / exact) - 1
};

ErrorRow error_of(const Mesh& m, const std::vector<float>& h, const std::vector<double>& exact) {
  std::vector<double> rel;
  double bias = 0.0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    rel.push_back(std::fabs(h[i] - exact[i]) / std::fabs(exact[i]));
    bias += h[i] / exact[i] - 1.0;
  }
  (void)m;
  ErrorRow e;
  for (double x : rel) e.mean_rel += x;
  e.mean_rel /= double(rel.size());
  e.bias = bias / double(rel.size());
  const std::size_t k = std::size_t(0.95 * double(rel.size()));
  std::nth_element(rel.begin(), rel.begin() + std::ptrdiff_t(k), rel.end());
  e.p95_rel = rel[k];
  return e;
}

void analytic_tables() {
  std::printf("## Curvature smoothing against the analytic mean curvature\n\n");
  std::printf("| surface | jitter | rings | mean rel. error | p95 rel. error | mean bias |\n|---|---|---|---|---|---|\n");
  for (double jitter : {0.0, 0.3}) {
    std::mt19937 rng(12111);
    const double R = 1.0, r = 0.35;
    const Mesh torus = make_jittered_torus(192, 64, R, r, jitter, rng);
    std::vector<double> exact_t;
    for (const glm::vec3& p : torus.positions) {
      const double rho = std::hypot(double(p.x), double(p.y)), cb = (rho - R) / r;
      exact_t.push_back((R + 2.0 * r * cb) / (2.0 * r * (R + r * cb)));
    }
    const Mesh coarse = make_jittered_torus(48, 16, R, r, jitter, rng);
    std::vector<double> exact_c;
    for (const glm::vec3& p : coarse.positions) {
      const double rho = std::hypot(double(p.x), double(p.y)), cb = (rho - R) / r;
      exact_c.push_back((R + 2.0 * r * cb) / (2.0 * r * (R + r * cb)));
    }
    const Mesh sphere = make_jittered_cube_sphere(32, 1.0, jitter, rng);
    const std::vector<double> exact_s(sphere.positions.size(), 1.0);
    for (int rings = 0; rings <= 4; ++rings) {
      for (const auto& [name, mesh, exact] :
           {std::tuple<const char*, const Mesh&, const std::vector<double>&>{"torus 192x64 (R 1, r 0.35)", torus, exact_t},
            {"torus 48x16 (R 1, r 0.35)", coarse, exact_c},
            {"cube-sphere 6x32^2 (r 1)", sphere, exact_s}}) {
        const ErrorRow e = error_of(mesh, vertex_mean_curvature(mesh, CurvatureOptions{rings}), exact);
        std::printf("| %s | %.1f | %d | %.2f%% | %.2f%% | %+.2f%% |\n", name, jitter, rings, 100.0 * e.mean_rel,
                    100.0 * e.p95_rel, 100.0 * e.bias);
      }
    }
  }
  std::printf("\n");
}

BakeOptions base_options(int size, int threads) {
  BakeOptions o;
  o.width = o.height = size;
  o.samples = 1;
  o.padding = 0;
  o.threads = threads;
  return o;
}

const BakedMap& find_map(const BakeResult& r, MapKind k) {
  for (const BakedMap& m : r.maps)
    if (m.kind == k) return m;
  std::fprintf(stderr, "map missing\n");
  std::exit(3);
}

struct Sculpt {
  std::string name;
  Mesh low, high;
};

// Texel-scale noise of a curvature map (decoded to 1/units, times the diagonal): the mean of
// |texel - mean of its 8 neighbours| over texels whose 3x3 block is covered; and the spread
// (standard deviation) of the same texels.
void curvature_tables(const std::vector<Sculpt>& sculpts, const std::vector<double>& diagonals, int size, int threads) {
  std::printf("## Curvature smoothing on the sculpts (%d^2, curvature x diagonal)\n\n", size);
  std::printf("| sculpt | rings | texel noise | spread | noise / spread | noise vs 0 rings | spread vs 0 rings |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  for (std::size_t s = 0; s < sculpts.size(); ++s) {
    double noise0 = 0.0, spread0 = 0.0;
    for (int rings = 0; rings <= 4; ++rings) {
      BakeOptions o = base_options(size, threads);
      o.maps.maps = {MapKind::curvature};
      o.maps.curvature_smoothing = rings;
      o.maps.curvature_scale = 1e6 / diagonals[s];  // no clamping: decode exactly
      const BakeResult r = bake_normal_map(sculpts[s].low, sculpts[s].high, nullptr, o);
      const BakedMap& m = find_map(r, MapKind::curvature);
      const Image& im = m.image;
      const auto c = [&](int x, int y) {
        return (double(im.pixels[std::size_t(y) * std::size_t(size) + std::size_t(x)]) - 0.5) * 2.0 * m.range_max * diagonals[s];
      };
      const auto cov = [&](int x, int y) { return r.coverage[std::size_t(y) * std::size_t(size) + std::size_t(x)] != 0; };
      double noise = 0.0, sum = 0.0, sq = 0.0, n = 0.0;
      for (int y = 1; y + 1 < size; ++y)
        for (int x = 1; x + 1 < size; ++x) {
          bool all = true;
          double nb = 0.0;
          for (int dy = -1; dy <= 1 && all; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              if (!cov(x + dx, y + dy)) {
                all = false;
                break;
              }
              if (dx || dy) nb += c(x + dx, y + dy);
            }
          if (!all) continue;
          const double v = c(x, y);
          noise += std::fabs(v - nb / 8.0), sum += v, sq += v * v, n += 1.0;
        }
      noise /= n;
      const double mean = sum / n, spread = std::sqrt(std::max(0.0, sq / n - mean * mean));
      if (rings == 0) noise0 = noise, spread0 = spread;
      std::printf("| %s | %d | %.3f | %.3f | %.3f | %.2f | %.2f |\n", sculpts[s].name.c_str(), rings, noise, spread,
                  noise / spread, noise / noise0, spread / spread0);
      std::fflush(stdout);
    }
  }
  std::printf("\n");
}

void distance_tables(const std::vector<Sculpt>& sculpts, const std::vector<double>& diagonals, int size, int threads, int rays) {
  std::printf("## AO and thickness against their distance (%d^2, %d rays, distance x diagonal)\n\n", size, rays);
  std::printf(
      "| sculpt | distance | mean AO | AO spread | AO < 0.98 | AO < 0.9 | mean thickness | thickness spread | thickness < 0.98 | "
      "thickness < 0.5 |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (std::size_t s = 0; s < sculpts.size(); ++s)
    for (double k : {0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0}) {
      BakeOptions o = base_options(size, threads);
      o.maps.maps = {MapKind::ao, MapKind::thickness};
      o.maps.ao_rays = rays;
      o.maps.ao_distance = o.maps.thickness_distance = k * diagonals[s];
      const BakeResult r = bake_normal_map(sculpts[s].low, sculpts[s].high, nullptr, o);
      const Image& ao = find_map(r, MapKind::ao).image;
      const Image& th = find_map(r, MapKind::thickness).image;
      double n = 0, ao_sum = 0, ao_sq = 0, ao98 = 0, ao90 = 0, th_sum = 0, th_sq = 0, th98 = 0, th50 = 0;
      for (std::size_t i = 0; i < r.coverage.size(); ++i) {
        if (!r.coverage[i]) continue;
        const double a = ao.pixels[i], t = th.pixels[i];
        n += 1, ao_sum += a, ao_sq += a * a, ao98 += a < 0.98, ao90 += a < 0.9;
        th_sum += t, th_sq += t * t, th98 += t < 0.98, th50 += t < 0.5;
      }
      const auto spread = [&](double sum, double sq) { return std::sqrt(std::max(0.0, sq / n - (sum / n) * (sum / n))); };
      std::printf("| %s | %.2f | %.3f | %.3f | %.1f%% | %.1f%% | %.3f | %.3f | %.1f%% | %.1f%% |\n", sculpts[s].name.c_str(), k,
                  ao_sum / n, spread(ao_sum, ao_sq), 100 * ao98 / n, 100 * ao90 / n, th_sum / n, spread(th_sum, th_sq),
                  100 * th98 / n, 100 * th50 / n);
      std::fflush(stdout);
    }
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: nmbake_map_defaults SHARED_DATA [--size N] [--threads N] [--rays N] [--only "
                 "analytic|curvature|distance]\n    [--sculpts torus_demo,suz_L3,suz_L4] [--base on]\n");
    return 1;
  }
  const std::string data = argv[1];
  int size = 512, threads = 2, rays = 64;
  std::string only;
  bool base = false;  // --base on: the low-poly baked onto itself (the base shape's own occlusion, no sculpted detail)
  std::vector<std::string> names = {"torus_demo", "suz_L3", "suz_L4"};
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--size") size = std::atoi(argv[i + 1]);
    else if (a == "--threads") threads = std::atoi(argv[i + 1]);
    else if (a == "--rays") rays = std::atoi(argv[i + 1]);
    else if (a == "--only") only = argv[i + 1];
    else if (a == "--base") base = std::string(argv[i + 1]) == "on";
    else if (a == "--sculpts") {
      names.clear();
      for (std::size_t at = 0, comma; at <= std::string(argv[i + 1]).size(); at = comma + 1) {
        const std::string list = argv[i + 1];
        comma = list.find(',', at);
        if (comma == std::string::npos) comma = list.size();
        names.push_back(list.substr(at, comma - at));
      }
    }
  }
  if (only.empty() || only == "analytic") analytic_tables();
  if (only == "analytic") return 0;
  std::vector<Sculpt> sculpts;
  std::vector<double> diagonals;
  for (const std::string& n : names) {
    LoadOptions lo;
    lo.require_uvs = true;
    Sculpt s{n, load_mesh(data + "/sculpts/" + n + "/low.obj", lo), load_mesh(data + "/sculpts/" + n + "/high.ply")};
    // The scene's diagonal as the bake sees it: its automatic AO distance over kAutoAoDistance.
    BakeOptions o = base_options(16, threads);
    o.maps.maps = {MapKind::ao};
    o.maps.ao_rays = 1;
    diagonals.push_back(find_map(bake_normal_map(s.low, s.high, nullptr, o), MapKind::ao).distance / kAutoAoDistance);
    std::fprintf(stderr, "%s: diagonal %.4f\n", n.c_str(), diagonals.back());
    if (base) s.high = s.low, s.name += " base (low onto itself)";  // distances still of the sculpt's diagonal
    sculpts.push_back(std::move(s));
  }
  if (only.empty() || only == "curvature") curvature_tables(sculpts, diagonals, size, threads);
  if (only.empty() || only == "distance") distance_tables(sculpts, diagonals, size, threads, rays);
  return 0;
}
