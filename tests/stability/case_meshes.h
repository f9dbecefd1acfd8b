// The meshes of make_stability_cases (make_cases.cpp), built procedurally in double: grids and
// height fields, the bump fields and their analytic normals, flat meshes from corner lists,
// spheres.
#pragma once

#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace stability {

inline constexpr double kPi = 3.14159265358979323846;

struct ObjMesh {
  std::vector<glm::dvec3> v, vn;
  std::vector<glm::dvec2> vt;
  // Per triangle corner: position, uv, normal index (0-based; -1 = none).
  struct Corner {
    int v, vt, vn;
  };
  std::vector<std::array<Corner, 3>> f;
  std::string comment;
};

using Height = std::function<double(double, double)>;
using Normal = std::function<glm::dvec3(double, double)>;

// A grid of nx x ny quads over [x0,x1] x [y0,y1], z = h(x, y), per-vertex normals n(x, y) (none when
// n is empty), UVs mapping the rectangle [u0,u1] x [v0,v1] (none when `uvs` is false).
inline ObjMesh height_field(int nx, int ny, double x0, double x1, double y0, double y1, const Height& h, const Normal& n,
                            bool uvs = true, glm::dvec4 uv_rect = {0, 1, 0, 1}) {
  ObjMesh m;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const double s = double(i) / nx, t = double(j) / ny;
      const double x = x0 + (x1 - x0) * s, y = y0 + (y1 - y0) * t;
      m.v.push_back({x, y, h(x, y)});
      if (n) m.vn.push_back(glm::normalize(n(x, y)));
      if (uvs) m.vt.push_back({uv_rect[0] + (uv_rect[1] - uv_rect[0]) * s, uv_rect[2] + (uv_rect[3] - uv_rect[2]) * t});
    }
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
      for (auto tri : {std::array<int, 3>{a, b, c}, std::array<int, 3>{a, c, d}}) {
        std::array<ObjMesh::Corner, 3> f;
        for (int k = 0; k < 3; ++k) f[k] = {tri[k], uvs ? tri[k] : -1, n ? tri[k] : -1};
        m.f.push_back(f);
      }
    }
  return m;
}

const Normal no_normal;  // empty: a mesh without normals

inline double zero(double, double) { return 0.0; }
inline glm::dvec3 up(double, double) { return {0, 0, 1}; }

// The bump field of the flat cases: z = 0.03 sin(2 pi x) sin(3 pi y) and its analytic normal.
inline double bumps(double x, double y) { return 0.03 * std::sin(2 * kPi * x) * std::sin(3 * kPi * y); }
inline glm::dvec3 bumps_normal(double x, double y) {
  const double hx = 0.03 * 2 * kPi * std::cos(2 * kPi * x) * std::sin(3 * kPi * y);
  const double hy = 0.03 * 3 * kPi * std::sin(2 * kPi * x) * std::cos(3 * kPi * y);
  return glm::normalize(glm::dvec3(-hx, -hy, 1.0));
}
// A dome z = 0.15 - 0.075 (x^2 + y^2) (curved low-poly, non-trivial tangent frames).
inline double dome(double x, double y) { return 0.15 - 0.075 * (x * x + y * y); }
inline glm::dvec3 dome_normal(double x, double y) { return glm::normalize(glm::dvec3(0.15 * x, 0.15 * y, 1.0)); }
inline double dome_bumps(double x, double y) { return dome(x, y) + bumps(x, y); }
inline glm::dvec3 dome_bumps_normal(double x, double y) {
  const double hx = -0.15 * x + 0.03 * 2 * kPi * std::cos(2 * kPi * x) * std::sin(3 * kPi * y);
  const double hy = -0.15 * y + 0.03 * 3 * kPi * std::sin(2 * kPi * x) * std::cos(3 * kPi * y);
  return glm::normalize(glm::dvec3(-hx, -hy, 1.0));
}

// Triangles of a flat mesh from explicit corner lists: positions p (z = 0, normal +Z), uvs t.
inline ObjMesh flat_mesh(const std::vector<glm::dvec2>& p, const std::vector<glm::dvec2>& t,
                         const std::vector<std::array<int, 3>>& tris, const std::vector<std::array<int, 3>>& uv_tris) {
  ObjMesh m;
  for (auto q : p) m.v.push_back({q.x, q.y, 0.0});
  m.vt = t;
  m.vn.push_back({0, 0, 1});
  for (std::size_t i = 0; i < tris.size(); ++i) {
    std::array<ObjMesh::Corner, 3> f;
    for (int k = 0; k < 3; ++k) f[k] = {tris[i][k], uv_tris[i][k], 0};
    m.f.push_back(f);
  }
  return m;
}

// A latitude-longitude sphere of radius r with nphi x ntheta quads, radial normals, u = phi / 2 pi,
// v = 1 - theta / pi.
inline ObjMesh sphere(int nphi, int ntheta, double r, bool uvs) {
  ObjMesh m;
  for (int j = 0; j <= ntheta; ++j)
    for (int i = 0; i <= nphi; ++i) {
      const double th = kPi * j / ntheta, ph = 2 * kPi * (i % nphi) / nphi;
      const glm::dvec3 d(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      m.v.push_back(r * d);
      m.vn.push_back(d);
      if (uvs) m.vt.push_back({double(i) / nphi, 1.0 - double(j) / ntheta});
    }
  auto id = [&](int i, int j) { return j * (nphi + 1) + i; };
  auto add = [&](int a, int b, int c) {
    std::array<ObjMesh::Corner, 3> f;
    const int t[3] = {a, b, c};
    for (int k = 0; k < 3; ++k) f[k] = {t[k], uvs ? t[k] : -1, t[k]};
    m.f.push_back(f);
  };
  for (int j = 0; j < ntheta; ++j)
    for (int i = 0; i < nphi; ++i) {
      const int a = id(i, j), b = id(i, j + 1), c = id(i + 1, j + 1), d = id(i + 1, j);
      if (j != 0) add(a, b, d);
      if (j != ntheta - 1) add(b, c, d);
    }
  return m;
}

inline void transform(ObjMesh& m, double scale, glm::dvec3 offset) {
  for (auto& p : m.v) p = p * scale + offset;
}

}  // namespace stability
