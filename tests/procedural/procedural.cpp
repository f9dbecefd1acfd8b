#include "procedural.h"

#include <cmath>
#include <cstdint>
#include <vector>

namespace nmbake::procedural {

Mesh make_sphere(int nphi, int ntheta, const std::function<double(double, double)>& radius,
                 const std::function<glm::dvec3(double, double)>& normal) {
  Mesh m;
  m.source = "sphere";
  for (int j = 0; j <= ntheta; ++j)
    for (int i = 0; i <= nphi; ++i) {
      const double theta = kPi * j / ntheta, phi = 2 * kPi * (i % nphi) / nphi;
      const glm::dvec3 dir(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
      m.positions.push_back(glm::vec3(dir * radius(theta, phi)));
      m.normals.push_back(glm::vec3(normal(theta, phi)));
      m.uvs.push_back({float(i) / float(nphi), 1.0f - float(j) / float(ntheta)});
    }
  auto id = [&](int i, int j) { return std::uint32_t(j * (nphi + 1) + i); };
  for (int j = 0; j < ntheta; ++j)
    for (int i = 0; i < nphi; ++i) {
      const std::uint32_t a = id(i, j), b = id(i, j + 1), c = id(i + 1, j + 1), d = id(i + 1, j);
      std::vector<std::uint32_t> tri;
      if (j == 0) tri = {a, b, c};                // a and d are the north pole
      else if (j == ntheta - 1) tri = {a, b, d};  // b and c are the south pole
      else tri = {a, b, d, b, c, d};
      for (std::uint32_t v : tri) {
        m.position_index.push_back(v);
        m.uv_index.push_back(v);
        m.normal_index.push_back(v);
      }
    }
  m.source_face.assign(m.triangle_count(), 0);
  return m;
}

double displaced_sphere_radius(double a, double k, double th, double ph) { return 1.0 + a * std::sin(k * th) * std::sin(k * ph); }

glm::dvec3 displaced_sphere_normal(double a, double k, double th, double ph) {
  const glm::dvec3 er(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
  const glm::dvec3 et(std::cos(th) * std::cos(ph), std::cos(th) * std::sin(ph), -std::sin(th));
  const glm::dvec3 ep(-std::sin(ph), std::cos(ph), 0.0);
  const double r_t = a * k * std::cos(k * th) * std::sin(k * ph);
  const double s = std::sin(th);
  const double ratio = std::abs(s) > 1e-9 ? std::sin(k * th) / s : k * std::cos(k * th) / std::cos(th);
  const double r_p_over_s = a * k * ratio * std::cos(k * ph);
  return glm::normalize(displaced_sphere_radius(a, k, th, ph) * er - r_t * et - r_p_over_s * ep);
}

}  // namespace nmbake::procedural
