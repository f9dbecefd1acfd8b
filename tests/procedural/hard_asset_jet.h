// Internal to the hard assets (hard_assets.cpp and its helpers): a value carried with its two
// partial derivatives, from which the detail functions get their exact normals.
#pragma once

#include <cmath>

#include "procedural.h"

namespace nmbake::procedural::detail {

struct Jet {
  double v = 0.0, du = 0.0, dv = 0.0;
};
inline Jet operator+(Jet a, Jet b) { return {a.v + b.v, a.du + b.du, a.dv + b.dv}; }
inline Jet operator-(Jet a, Jet b) { return {a.v - b.v, a.du - b.du, a.dv - b.dv}; }
inline Jet operator*(Jet a, Jet b) { return {a.v * b.v, a.du * b.v + a.v * b.du, a.dv * b.v + a.v * b.dv}; }
inline Jet operator*(double k, Jet a) { return {k * a.v, k * a.du, k * a.dv}; }
inline Jet operator+(double k, Jet a) { return {k + a.v, a.du, a.dv}; }
inline Jet sin(Jet a) { return {std::sin(a.v), std::cos(a.v) * a.du, std::cos(a.v) * a.dv}; }
inline Jet cos(Jet a) { return {std::cos(a.v), -std::sin(a.v) * a.du, -std::sin(a.v) * a.dv}; }
inline Jet sin2(Jet a) { return sin(a) * sin(a); }
inline Jet abs(Jet a) { return a.v < 0 ? -1.0 * a : a; }
inline Jet u_param(double u) { return {u, 1.0, 0.0}; }
inline Jet v_param(double v) { return {v, 0.0, 1.0}; }

// cos^2(pi/2 t) on t in [0, 1]: 1 to 0 with zero slope at both ends (C1 joins).
inline Jet cos2_step(Jet t) {
  const double c = std::cos(0.5 * kPi * t.v), d = -0.5 * kPi * std::sin(kPi * t.v);
  return {c * c, d * t.du, d * t.dv};
}
// 1 for x <= a, 0 for x >= b, a cos^2 step between.
inline Jet ramp_down(Jet x, double a, double b) {
  if (x.v <= a) return {1.0, 0.0, 0.0};
  if (x.v >= b) return {};
  return cos2_step((1.0 / (b - a)) * (x - Jet{a, 0.0, 0.0}));
}
// A bump of height 1 at `centre`, 0 beyond `half_width`.
inline Jet window(Jet x, double centre, double half_width) { return ramp_down(abs(x - Jet{centre, 0.0, 0.0}), 0.0, half_width); }

inline Jet radius_jet(double x, double y) {
  const double r = std::hypot(x, y);
  return r > 0 ? Jet{r, x / r, y / r} : Jet{};
}

}  // namespace nmbake::procedural::detail
