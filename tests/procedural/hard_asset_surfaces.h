// Internal to the hard assets: the analytic surface patches their parts are made of, and the
// locate / expected_normal functions built on them (hard_assets.h states the contract).
#pragma once

#include <algorithm>
#include <functional>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "hard_asset_jet.h"
#include "hard_assets.h"

namespace nmbake::procedural::detail {

// Patch boundaries are widened by this much: float vertices on an edge may lie 1e-8 outside.
constexpr double kEdgeSlack = 1e-6;

class Patch {
 public:
  virtual ~Patch() = default;
  // Continuous along any line, > 0 just outside the solid, < 0 just inside, 0 on the surface.
  virtual double implicit(const glm::dvec3& x) const = 0;
  // Whether a point of the implicit surface belongs to this patch.
  virtual bool contains(const glm::dvec3& x) const = 0;
  virtual glm::dvec3 normal(const glm::dvec3& x) const = 0;   // unit outward, at a point of the patch
  virtual glm::dvec3 closest(const glm::dvec3& p) const = 0;  // the patch point nearest to p
};
using Part = std::vector<std::shared_ptr<const Patch>>;

// The point of a parametric patch S(u, v), (u, v) in [lo, hi], nearest to p: the best of a 32 x 32
// grid of samples, refined by Gauss-Newton steps, each halved until it gets nearer. `eval` gives S,
// S_u and S_v; `clamp` keeps (u, v) in the domain (a height field's disc).
template <typename Eval, typename Clamp>
glm::dvec3 project(const glm::dvec3& p, glm::dvec2 lo, glm::dvec2 hi, Eval eval, Clamp clamp) {
  constexpr int kGrid = 32;
  glm::dvec3 s, su, sv;
  glm::dvec2 uv = lo;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i < kGrid; ++i)
    for (int j = 0; j < kGrid; ++j) {
      glm::dvec2 t = lo + (hi - lo) * glm::dvec2((i + 0.5) / kGrid, (j + 0.5) / kGrid);
      clamp(t.x, t.y);
      eval(t.x, t.y, s, su, sv);
      if (glm::dot(p - s, p - s) < best) best = glm::dot(p - s, p - s), uv = t;
    }
  for (int it = 0; it < 50; ++it) {
    eval(uv.x, uv.y, s, su, sv);
    const glm::dvec3 d = p - s;
    const double a = glm::dot(su, su), b = glm::dot(su, sv), c = glm::dot(sv, sv), det = a * c - b * b;
    if (!(det > 0)) break;
    const glm::dvec2 step((c * glm::dot(su, d) - b * glm::dot(sv, d)) / det, (a * glm::dot(sv, d) - b * glm::dot(su, d)) / det);
    bool nearer = false;
    for (double f = 1; f > 1e-6 && !nearer; f *= 0.5) {
      glm::dvec2 t = uv + f * step;
      clamp(t.x, t.y);
      eval(t.x, t.y, s, su, sv);
      if (glm::dot(p - s, p - s) < best) best = glm::dot(p - s, p - s), uv = t, nearer = true;
    }
    if (!nearer) break;
  }
  eval(uv.x, uv.y, s, su, sv);
  return s;
}

// rho = radius(theta, z) around the axis through `axis` along z, for z0 <= z <= z1. `bore`: the
// solid is outside (a hole's wall), so the outward normal points to the axis.
class RadialSurface final : public Patch {
 public:
  // du = d/dtheta, dv = d/dz; called with theta in [-pi, pi] (a window need not be periodic).
  using Radius = std::function<Jet(double theta, double z)>;
  RadialSurface(glm::dvec2 axis, double z0, double z1, bool bore, Radius radius)
      : axis_(axis), z0_(z0), z1_(z1), bore_(bore), radius_(std::move(radius)) {}

  glm::dvec3 point(double theta, double z) const {
    const double r = radius(theta, z).v;
    return {axis_.x + r * std::cos(theta), axis_.y + r * std::sin(theta), z};
  }
  glm::dvec3 normal_at(double theta, double z) const {
    // Gradient of rho - r(theta, z): e_rho - (r_theta / rho) e_theta - r_z e_z, with rho = r.
    const Jet r = radius(theta, z);
    const double c = std::cos(theta), s = std::sin(theta), k = r.du / r.v;
    const glm::dvec3 n = glm::normalize(glm::dvec3(c + k * s, s - k * c, -r.dv));
    return bore_ ? -n : n;
  }
  double implicit(const glm::dvec3& x) const override {
    const double rho = std::hypot(x.x - axis_.x, x.y - axis_.y);
    const double r = radius(std::atan2(x.y - axis_.y, x.x - axis_.x), x.z).v;
    return bore_ ? r - rho : rho - r;
  }
  bool contains(const glm::dvec3& x) const override { return x.z >= z0_ - kEdgeSlack && x.z <= z1_ + kEdgeSlack; }
  glm::dvec3 normal(const glm::dvec3& x) const override { return normal_at(std::atan2(x.y - axis_.y, x.x - axis_.x), x.z); }
  glm::dvec3 closest(const glm::dvec3& p) const override {
    auto eval = [&](double theta, double z, glm::dvec3& s, glm::dvec3& su, glm::dvec3& sv) {
      const Jet r = radius(theta, z);
      const glm::dvec3 er(std::cos(theta), std::sin(theta), 0.0), et(-er.y, er.x, 0.0);
      s = glm::dvec3(axis_, z) + r.v * er;
      su = r.du * er + r.v * et;
      sv = r.dv * er + glm::dvec3(0, 0, 1);
    };
    auto clamp = [&](double&, double& z) { z = std::clamp(z, z0_, z1_); };
    return project(p, {-kPi, z0_}, {kPi, z1_}, eval, clamp);
  }

 private:
  Jet radius(double theta, double z) const { return radius_(std::remainder(theta, 2 * kPi), z); }
  glm::dvec2 axis_;
  double z0_, z1_;
  bool bore_;
  Radius radius_;
};

// z = height(x, y) over the disc x^2 + y^2 <= radius^2; `up`: the solid is below (normal +z side).
class HeightDisc final : public Patch {
 public:
  using Height = std::function<Jet(double x, double y)>;  // du = d/dx, dv = d/dy
  HeightDisc(double radius, bool up, Height height) : radius_(radius), up_(up), height_(std::move(height)) {}

  glm::dvec3 point(double x, double y) const { return {x, y, height_(x, y).v}; }
  glm::dvec3 normal_at(double x, double y) const {
    const Jet h = height_(x, y);
    const glm::dvec3 n = glm::normalize(glm::dvec3(-h.du, -h.dv, 1.0));
    return up_ ? n : -n;
  }
  double implicit(const glm::dvec3& x) const override {
    const double d = x.z - height_(x.x, x.y).v;
    return up_ ? d : -d;
  }
  bool contains(const glm::dvec3& x) const override { return std::hypot(x.x, x.y) <= radius_ + kEdgeSlack; }
  glm::dvec3 normal(const glm::dvec3& x) const override { return normal_at(x.x, x.y); }
  glm::dvec3 closest(const glm::dvec3& p) const override {
    auto clamp = [&](double& x, double& y) {
      const double r = std::hypot(x, y);
      if (r > radius_) x *= radius_ / r, y *= radius_ / r;
    };
    auto eval = [&](double x, double y, glm::dvec3& s, glm::dvec3& su, glm::dvec3& sv) {
      const Jet h = height_(x, y);
      s = {x, y, h.v};
      su = {1.0, 0.0, h.du};
      sv = {0.0, 1.0, h.dv};
    };
    return project(p, glm::dvec2(-radius_), glm::dvec2(radius_), eval, clamp);
  }

 private:
  double radius_;
  bool up_;
  Height height_;
};

// The flat disc or annulus r_min <= rho <= r_max around (centre.x, centre.y) in the plane
// z = centre.z, facing +z when `up`.
class FlatRing final : public Patch {
 public:
  FlatRing(glm::dvec3 centre, double r_min, double r_max, bool up) : c_(centre), r0_(r_min), r1_(r_max), up_(up) {}
  double implicit(const glm::dvec3& x) const override { return up_ ? x.z - c_.z : c_.z - x.z; }
  bool contains(const glm::dvec3& x) const override {
    const double rho = std::hypot(x.x - c_.x, x.y - c_.y);
    return rho >= r0_ - kEdgeSlack && rho <= r1_ + kEdgeSlack;
  }
  glm::dvec3 normal(const glm::dvec3&) const override { return {0.0, 0.0, up_ ? 1.0 : -1.0}; }
  glm::dvec3 closest(const glm::dvec3& p) const override {
    const glm::dvec2 d(p.x - c_.x, p.y - c_.y);
    const double rho = glm::length(d);
    const glm::dvec2 dir = rho > 0 ? d / rho : glm::dvec2(1.0, 0.0);
    return glm::dvec3(glm::dvec2(c_) + std::clamp(rho, r0_, r1_) * dir, c_.z);
  }

 private:
  glm::dvec3 c_;
  double r0_, r1_;
  bool up_;
};

// The outer half (rho >= ring) of the torus around the z axis with major radius `ring` and tube
// radius `tube`: the rim of a slab of thickness 2 tube.
class TorusRim final : public Patch {
 public:
  TorusRim(double ring, double tube) : ring_(ring), tube_(tube) {}
  glm::dvec3 point(double theta, double phi) const {
    const double rho = ring_ + tube_ * std::cos(phi);
    return {rho * std::cos(theta), rho * std::sin(theta), tube_ * std::sin(phi)};
  }
  static glm::dvec3 normal_at(double theta, double phi) {
    return {std::cos(phi) * std::cos(theta), std::cos(phi) * std::sin(theta), std::sin(phi)};
  }
  double implicit(const glm::dvec3& x) const override { return std::hypot(std::hypot(x.x, x.y) - ring_, x.z) - tube_; }
  bool contains(const glm::dvec3& x) const override { return std::hypot(x.x, x.y) >= ring_ - kEdgeSlack; }
  glm::dvec3 normal(const glm::dvec3& x) const override {
    const double rho = std::hypot(x.x, x.y);
    return normal_at(std::atan2(x.y, x.x), std::atan2(x.z, std::max(rho - ring_, 0.0)));
  }
  glm::dvec3 closest(const glm::dvec3& p) const override {
    const double rho = std::hypot(p.x, p.y);
    const double phi = std::atan2(p.z, std::max(rho - ring_, 0.0));  // in [-pi/2, pi/2]: the outer half
    return point(std::atan2(p.y, p.x), phi);
  }

 private:
  double ring_, tube_;
};

// The box [-half, half]^3 with every edge and corner rounded with radius `bevel`: the points at
// distance `bevel` from the inner box [-e, e]^3, e = half - bevel.
class RoundedBox final : public Patch {
 public:
  RoundedBox(double half, double bevel) : e_(half - bevel), b_(bevel) {}
  // The surface point above a point q of the box [-half, half]^3's surface, and its normal.
  std::pair<glm::dvec3, glm::dvec3> map(const glm::dvec3& q) const {
    const glm::dvec3 inner = glm::clamp(q, -e_, e_), n = glm::normalize(q - inner);
    return {inner + b_ * n, n};
  }
  double implicit(const glm::dvec3& x) const override {
    const glm::dvec3 q = glm::abs(x) - e_;
    return glm::length(glm::max(q, 0.0)) + std::min(std::max({q.x, q.y, q.z}), 0.0) - b_;
  }
  bool contains(const glm::dvec3&) const override { return true; }
  glm::dvec3 normal(const glm::dvec3& x) const override {
    const glm::dvec3 d = x - glm::clamp(x, -e_, e_);
    if (glm::dot(d, d) > 0) return glm::normalize(d);
    return face_normal(x);
  }
  glm::dvec3 closest(const glm::dvec3& p) const override {
    const glm::dvec3 inner = glm::clamp(p, -e_, e_), d = p - inner;
    if (glm::dot(d, d) > 0) return inner + b_ * glm::normalize(d);
    return p + (e_ + b_ - glm::dot(glm::abs(p), glm::abs(face_normal(p)))) * face_normal(p);  // inside: nearest face
  }

 private:
  static glm::dvec3 face_normal(const glm::dvec3& x) {
    const glm::dvec3 a = glm::abs(x);
    const int k = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    glm::dvec3 n(0.0);
    n[k] = x[k] < 0 ? -1.0 : 1.0;
    return n;
  }
  double e_, b_;
};

// Fills locate, expected_normal and max_s from the parts' patches.
void attach_surfaces(HardAsset& asset, std::vector<Part> parts, double max_s);

}  // namespace nmbake::procedural::detail
