// Procedural meshes shared by the tests and the benchmarks (no test framework here, so the bench
// programs can link it with the tests switched off).
#pragma once

#include <functional>

#include <glm/glm.hpp>

#include "core/mesh.h"

namespace nmbake::procedural {

constexpr double kPi = 3.14159265358979323846;

// A latitude-longitude sphere: nphi x ntheta quads (triangles at the poles), u = phi / 2 pi,
// v = 1 - theta / pi, with radius(theta, phi) and per-vertex normal(theta, phi).
Mesh make_sphere(int nphi, int ntheta, const std::function<double(double theta, double phi)>& radius,
                 const std::function<glm::dvec3(double theta, double phi)>& normal);

// The displaced sphere r = 1 + a sin(k theta) sin(k phi), k odd, and its exact unit normal
// (n ~ r e_r - r_theta e_theta - (r_phi / sin theta) e_phi; at the poles sin(k theta) / sin theta
// takes its limit).
double displaced_sphere_radius(double a, double k, double theta, double phi);
glm::dvec3 displaced_sphere_normal(double a, double k, double theta, double phi);

}  // namespace nmbake::procedural
