#include "hard_assets.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <numeric>
#include <unordered_map>
#include <utility>

namespace nmbake::procedural {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Patch boundaries are widened by this much: float vertices on an edge may lie 1e-8 outside.
constexpr double kEdgeSlack = 1e-6;
constexpr double kIslandMargin = 0.02;  // UV space, between islands and to the border

// ---- A value with its two partial derivatives, for detail functions and their exact normals ----

struct Jet {
  double v = 0.0, du = 0.0, dv = 0.0;
};
Jet operator+(Jet a, Jet b) { return {a.v + b.v, a.du + b.du, a.dv + b.dv}; }
Jet operator-(Jet a, Jet b) { return {a.v - b.v, a.du - b.du, a.dv - b.dv}; }
Jet operator*(Jet a, Jet b) { return {a.v * b.v, a.du * b.v + a.v * b.du, a.dv * b.v + a.v * b.dv}; }
Jet operator*(double k, Jet a) { return {k * a.v, k * a.du, k * a.dv}; }
Jet operator+(double k, Jet a) { return {k + a.v, a.du, a.dv}; }
Jet sin(Jet a) { return {std::sin(a.v), std::cos(a.v) * a.du, std::cos(a.v) * a.dv}; }
Jet cos(Jet a) { return {std::cos(a.v), -std::sin(a.v) * a.du, -std::sin(a.v) * a.dv}; }
Jet sin2(Jet a) { return sin(a) * sin(a); }
Jet abs(Jet a) { return a.v < 0 ? -1.0 * a : a; }
Jet u_param(double u) { return {u, 1.0, 0.0}; }
Jet v_param(double v) { return {v, 0.0, 1.0}; }

// cos^2(pi/2 t) on t in [0, 1]: 1 to 0 with zero slope at both ends (C1 joins).
Jet cos2_step(Jet t) {
  const double c = std::cos(0.5 * kPi * t.v), d = -0.5 * kPi * std::sin(kPi * t.v);
  return {c * c, d * t.du, d * t.dv};
}
// 1 for x <= a, 0 for x >= b, a cos^2 step between.
Jet ramp_down(Jet x, double a, double b) {
  if (x.v <= a) return {1.0, 0.0, 0.0};
  if (x.v >= b) return {};
  return cos2_step((1.0 / (b - a)) * (x - Jet{a, 0.0, 0.0}));
}
// A bump of height 1 at `centre`, 0 beyond `half_width`.
Jet window(Jet x, double centre, double half_width) { return ramp_down(abs(x - Jet{centre, 0.0, 0.0}), 0.0, half_width); }

Jet radius_jet(double x, double y) {
  const double r = std::hypot(x, y);
  return r > 0 ? Jet{r, x / r, y / r} : Jet{};
}

// ---- Analytic surface patches; a part is a few of them ----

class Patch {
 public:
  virtual ~Patch() = default;
  // Continuous along any line, > 0 just outside the solid, < 0 just inside, 0 on the surface.
  virtual double implicit(const glm::dvec3& x) const = 0;
  // Whether a point of the implicit surface belongs to this patch.
  virtual bool contains(const glm::dvec3& x) const = 0;
  virtual glm::dvec3 normal(const glm::dvec3& x) const = 0;  // unit outward, at a point of the patch
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
  glm::dvec3 normal(const glm::dvec3& x) const override {
    return normal_at(std::atan2(x.y - axis_.y, x.x - axis_.x), x.z);
  }
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

// Bisects [a, b] (g(a) = ga and g(b) of opposite signs) to 1e-13 relative.
double bisect(const Patch& f, const glm::dvec3& p, const glm::dvec3& dir, double a, double ga, double b) {
  for (int it = 0; it < 200 && std::abs(b - a) > 1e-15 + 1e-13 * std::abs(a); ++it) {
    const double m = 0.5 * (a + b), gm = f.implicit(p + m * dir);
    if (gm == 0) return m;
    if ((gm < 0) == (ga < 0))
      a = m, ga = gm;
    else
      b = m;
  }
  return 0.5 * (a + b);
}

SurfacePoint locate_on(const Part& part, const glm::dvec3& p, const glm::dvec3& dir, double max_s) {
  constexpr int kSteps = 256;
  constexpr std::size_t kMaxPatches = 8;
  constexpr double kTie = 1e-7;  // crossings this close are the same point (float vertices)
  assert(part.size() <= kMaxPatches);
  const double ds = max_s / kSteps;
  std::array<std::array<double, kMaxPatches>, 2> last{};  // g at the previous step, per direction and patch
  for (std::size_t i = 0; i < part.size(); ++i) last[0][i] = last[1][i] = part[i]->implicit(p);
  // Step outwards in both directions at once: the first step with a crossing on the part holds the
  // smallest |s| (its crossings on either side are all nearer than the next step's).
  for (int k = 0; k < kSteps; ++k) {
    SurfacePoint best;
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? 1.0 : -1.0, a = sign * k * ds, b = sign * (k + 1) * ds;
      for (std::size_t i = 0; i < part.size(); ++i) {
        const Patch& f = *part[i];
        const double ga = last[side][i], gb = f.implicit(p + b * dir);
        last[side][i] = gb;
        if (ga != 0 && (ga < 0) == (gb < 0)) continue;
        const double s = ga == 0 ? a : bisect(f, p, dir, a, ga, b);
        const glm::dvec3 x = p + s * dir;
        if (!f.contains(x)) continue;
        const glm::dvec3 n = f.normal(x);
        // On an edge between two patches (a vertex of the high-poly there, rounded to float) the
        // crossings coincide: take the patch the line meets most squarely.
        const bool tie = best.crossed && std::abs(std::abs(s) - std::abs(best.s)) <= kTie;
        if (best.crossed && !(tie ? std::abs(glm::dot(n, dir)) > std::abs(glm::dot(best.normal, dir))
                                  : std::abs(s) < std::abs(best.s)))
          continue;
        best = {true, s, x, n};
      }
    }
    if (best.crossed) return best;
  }
  SurfacePoint nearest;
  double nearest_d = std::numeric_limits<double>::infinity();
  for (const auto& f : part) {
    const glm::dvec3 q = f->closest(p);
    if (glm::distance(p, q) < nearest_d) nearest_d = glm::distance(p, q), nearest = {false, 0.0, q, f->normal(q)};
  }
  return nearest;
}

// Fills locate, expected_normal and max_s from the parts' patches.
void attach_surfaces(HardAsset& asset, std::vector<Part> parts, double max_s) {
  auto shared = std::make_shared<const std::vector<Part>>(std::move(parts));
  asset.max_s = max_s;
  asset.locate = [shared, max_s](const glm::dvec3& p, const glm::dvec3& dir, int part) {
    assert(part >= 0 && std::size_t(part) < shared->size());
    return locate_on((*shared)[std::size_t(part)], p, dir, max_s);
  };
  auto locate = asset.locate;
  asset.expected_normal = [locate](const glm::dvec3& p, const glm::dvec3& dir, int part) {
    return locate(p, dir, part).normal;
  };
}

// ---- Mesh building ----

struct Corner {
  std::uint32_t p = 0, n = 0, t = 0;  // position, normal, uv index
};
using Ring = std::vector<Corner>;  // a closed loop: the last corner repeats the first's position

class Builder {
 public:
  Builder(Mesh& mesh, std::vector<int>& parts, bool uvs) : m_(mesh), parts_(parts), uvs_(uvs) {}
  std::uint32_t position(const glm::dvec3& p) {
    m_.positions.push_back(glm::vec3(p));
    return std::uint32_t(m_.positions.size() - 1);
  }
  std::uint32_t normal(const glm::dvec3& n) {
    m_.normals.push_back(glm::vec3(n));
    return std::uint32_t(m_.normals.size() - 1);
  }
  std::uint32_t uv(const glm::dvec2& t) {
    if (!uvs_) return 0;
    m_.uvs.push_back(glm::vec2(t));
    return std::uint32_t(m_.uvs.size() - 1);
  }
  Corner corner(const glm::dvec3& p, const glm::dvec3& n, const glm::dvec2& t = glm::dvec2(0.0)) {
    return {position(p), normal(n), uv(t)};
  }
  void triangle(Corner a, Corner b, Corner c, int part) {
    add(a, b, c, part);
    ++face_;
  }
  void quad(Corner a, Corner b, Corner c, Corner d, int part) {  // a b c d counter-clockwise
    add(a, b, c, part);
    add(a, c, d, part);
    ++face_;
  }

 private:
  void add(Corner a, Corner b, Corner c, int part) {
    for (const Corner& k : {a, b, c}) {
      m_.position_index.push_back(k.p);
      m_.normal_index.push_back(k.n);
      if (uvs_) m_.uv_index.push_back(k.t);
    }
    m_.source_face.push_back(face_);
    parts_.push_back(part);
  }
  Mesh& m_;
  std::vector<int>& parts_;
  bool uvs_;
  std::uint32_t face_ = 0;
};

// count corners at theta = 2 pi k / count, then the first again; seam_uv, when given, is the last
// corner's own UV (an island's seam; the position and normal stay the first's).
Ring make_ring(Builder& out, int count, const std::function<Corner(double theta)>& corner,
               const std::function<glm::dvec2()>& seam_uv = nullptr) {
  Ring ring;
  for (int k = 0; k < count; ++k) ring.push_back(corner(2 * kPi * k / count));
  Corner last = ring.front();
  if (seam_uv) last.t = out.uv(seam_uv());
  ring.push_back(last);
  return ring;
}

// The band between closed rings a and b (corner counts may differ), wound like the quads
// (a_i, a_i+1, b_i+1, b_i): counter-clockwise seen from outside when a is the lower ring of an
// outward cylinder wall or the outer ring of an upward disc.
void stitch(Builder& out, const Ring& a, const Ring& b, int part) {
  const std::size_t na = a.size() - 1, nb = b.size() - 1;
  std::size_t i = 0, j = 0;
  while (i < na || j < nb) {
    // Advance on the ring whose next corner comes first in angle: (i+1)/na against (j+1)/nb.
    if (j == nb || (i < na && (i + 1) * nb <= (j + 1) * na)) {
      out.triangle(a[i], a[i + 1], b[j], part);
      ++i;
    } else {
      out.triangle(a[i], b[j + 1], b[j], part);
      ++j;
    }
  }
}

// The disc inside `outer` (angles increasing counter-clockwise seen from +z): rings - 1 inner rings
// at radius * j / rings with about (outer count) * j / rings corners, and a fan to the centre;
// vertex(rho, theta) makes the inner corners. `up`: the disc faces +z.
void fill_disc(Builder& out, const Ring& outer, int rings, double radius,
               const std::function<Corner(double rho, double theta)>& vertex, bool up, int part) {
  const int count = int(outer.size()) - 1;
  Ring previous = outer;
  for (int j = rings - 1; j >= 1; --j) {
    const int cj = std::max(3, int(std::lround(double(count) * j / rings)));
    const double rho = radius * j / rings;
    const Ring ring = make_ring(out, cj, [&](double theta) { return vertex(rho, theta); });
    up ? stitch(out, previous, ring, part) : stitch(out, ring, previous, part);
    previous = ring;
  }
  const Corner centre = vertex(0.0, 0.0);
  for (std::size_t k = 0; k + 1 < previous.size(); ++k)
    up ? out.triangle(centre, previous[k], previous[k + 1], part)
       : out.triangle(centre, previous[k + 1], previous[k], part);
}

// A wall of along + 1 rings from z0 to z1, of `around` corners made by corner(theta, z); seam_uv(z),
// when given, is the seam corner's own UV. `bore`: the wall faces the axis.
std::vector<Ring> add_wall(Builder& out, int around, int along, double z0, double z1,
                           const std::function<Corner(double theta, double z)>& corner,
                           const std::function<glm::dvec2(double z)>& seam_uv, bool bore, int part) {
  std::vector<Ring> rings;
  for (int j = 0; j <= along; ++j) {
    const double z = j == along ? z1 : z0 + (z1 - z0) * j / along;
    std::function<glm::dvec2()> seam;
    if (seam_uv) seam = [&] { return seam_uv(z); };
    rings.push_back(make_ring(out, around, [&](double theta) { return corner(theta, z); }, seam));
    if (j == 0) continue;
    const Ring &lower = rings[std::size_t(j - 1)], &upper = rings[std::size_t(j)];
    bore ? stitch(out, upper, lower, part) : stitch(out, lower, upper, part);
  }
  return rings;
}

// A ring's positions with normal n and UVs uv(theta): the edge of a flat face (a hard edge).
Ring edge_ring(Builder& out, Ring ring, std::uint32_t n, const std::function<glm::dvec2(double theta)>& uv) {
  const std::size_t count = ring.size() - 1;
  for (std::size_t k = 0; k < count; ++k) ring[k] = {ring[k].p, n, out.uv(uv(2 * kPi * double(k) / double(count)))};
  ring.back() = ring.front();
  return ring;
}

// The flat annulus at height z around `axis` between `outer` (radius r_outer) and `inner` (radius
// r_inner, same corner count), in `segments` bands; vertex(rho, theta) makes the corners between.
void add_annulus(Builder& out, const Ring& outer, const Ring& inner, int segments, double r_outer, double r_inner,
                 const std::function<Corner(double rho, double theta)>& vertex, bool up, int part) {
  Ring previous = outer;
  for (int s = 1; s <= segments; ++s) {
    const double rho = r_outer + (r_inner - r_outer) * s / segments;
    const Ring ring = s == segments ? inner : make_ring(out, int(outer.size()) - 1, [&](double theta) {
      return vertex(rho, theta);
    });
    up ? stitch(out, previous, ring, part) : stitch(out, ring, previous, part);
    previous = ring;
  }
}

// The corners of a flat face at height z around `axis` with normal n and UVs uv(x, y) (relative to
// the axis) for fill_disc and add_annulus.
std::function<Corner(double, double)> flat_vertex(Builder& out, glm::dvec2 axis, double z, std::uint32_t n,
                                                  std::function<glm::dvec2(double x, double y)> uv) {
  return [&out, axis, z, n, uv](double rho, double theta) {
    const double x = rho * std::cos(theta), y = rho * std::sin(theta);
    return Corner{out.position({axis.x + x, axis.y + y, z}), n, out.uv(uv ? uv(x, y) : glm::dvec2(0.0))};
  };
}

// A closed cylinder around `axis` from z0 to z1 whose wall, made by side(theta, z), ends in circles
// of `radius`; flat caps of cap_rings rings with their own normals. cap_uv(top, x, y) gives a cap
// corner's UV from its position relative to the axis (nullptr: no UVs).
void add_capped_cylinder(Builder& out, glm::dvec2 axis, double radius, double z0, double z1, int around, int along,
                         int cap_rings, const std::function<Corner(double theta, double z)>& side,
                         const std::function<glm::dvec2(double z)>& seam_uv,
                         const std::function<glm::dvec2(bool top, double x, double y)>& cap_uv, int part) {
  const std::vector<Ring> rings = add_wall(out, around, along, z0, z1, side, seam_uv, false, part);
  for (bool top : {true, false}) {
    std::function<glm::dvec2(double, double)> uv;
    if (cap_uv) uv = [&cap_uv, top](double x, double y) { return cap_uv(top, x, y); };
    const std::uint32_t n = out.normal({0.0, 0.0, top ? 1.0 : -1.0});
    const Ring outer = edge_ring(out, top ? rings.back() : rings.front(), n, [&](double theta) {
      return uv ? uv(radius * std::cos(theta), radius * std::sin(theta)) : glm::dvec2(0.0);
    });
    fill_disc(out, outer, cap_rings, radius, flat_vertex(out, axis, top ? z1 : z0, n, uv), top, part);
  }
}

// UV islands side by side at one common scale (object units to UV), kIslandMargin apart and from
// the border: shelves of islands sorted by height, the largest scale that fits.
struct Island {
  glm::dvec2 origin{0.0};
  double scale = 1.0;
  glm::dvec2 operator()(double u, double v) const { return origin + scale * glm::dvec2(u, v); }
};

std::vector<Island> pack_islands(const std::vector<glm::dvec2>& sizes) {
  std::vector<std::size_t> order(sizes.size());
  std::iota(order.begin(), order.end(), std::size_t(0));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return sizes[a].y > sizes[b].y; });
  std::vector<Island> islands(sizes.size());
  auto place = [&](double scale) {
    double x = kIslandMargin, y = kIslandMargin, row = 0;
    for (std::size_t i : order) {
      const glm::dvec2 size = scale * sizes[i];
      if (x + size.x + kIslandMargin > 1 && x > kIslandMargin) x = kIslandMargin, y += row + kIslandMargin, row = 0;
      if (x + size.x + kIslandMargin > 1) return false;
      islands[i] = {{x, y}, scale};
      x += size.x + kIslandMargin;
      row = std::max(row, size.y);
    }
    return y + row + kIslandMargin <= 1;
  };
  double lo = 0, hi = 16;
  for (int it = 0; it < 60; ++it) (place(0.5 * (lo + hi)) ? lo : hi) = 0.5 * (lo + hi);
  place(lo);
  return islands;
}

// The UV in a disc island (of a disc of `radius`) of the point (x, y) from the disc's centre; seen
// from below (a face with normal -z), x runs the other way.
glm::dvec2 disc_uv(const Island& island, double radius, bool up, double x, double y) {
  return island((up ? x : -x) + radius, y + radius);
}

std::string format_name(const char* format, double a, double b = 0) {
  char text[128];
  std::snprintf(text, sizeof text, format, a, b);
  return text;
}

void name_meshes(HardAsset& asset) { asset.low.source = asset.high.source = asset.name; }

// The chord error of a regular polygon with `count` corners on a circle of radius r.
double sagitta(double r, int count) { return r * (1 - std::cos(kPi / count)); }

}  // namespace

// ---- Close tubes ----

HardAsset make_close_tubes(double gap, double bulge, int around_low, int along_low, int around_high, int along_high) {
  assert(around_high % 4 == 0 && along_high % 2 == 0 && gap > 0 && bulge >= 0);
  constexpr int kTubes = 5;
  constexpr double R = 0.05, L = 0.6, kRipple = 0.0015;
  const double z0 = -L / 2, z1 = L / 2;
  HardAsset asset;
  asset.name = format_name("close_tubes_gap%g_bulge%g", gap, bulge);

  std::vector<Part> parts;
  std::vector<std::shared_ptr<const RadialSurface>> sides;
  std::vector<glm::dvec2> axes;
  for (int i = 0; i < kTubes; ++i) {
    const glm::dvec2 axis((i - kTubes / 2) * (2 * R + gap), 0.0);
    // k even: the ripple vanishes at theta = 0 and pi, facing the neighbours. The middle tube's
    // phase 0 puts a zero of the ripple under the bump's top.
    const double k_theta = std::array<double, kTubes>{4, 6, 8, 6, 4}[std::size_t(i)];
    const double phase = std::array<double, kTubes>{1.1, 2.3, 0.0, 3.7, 5.1}[std::size_t(i)];
    const double k_z = 2 * kPi * 5 / L, b = i == kTubes / 2 ? bulge : 0.0;
    auto radius = [=](double theta, double z) {
      const Jet t = u_param(theta), h = v_param(z);
      const Jet ends = ramp_down(abs(h), z1 - 0.06, z1 - 0.015);
      Jet r = R + (-kRipple) * sin2(0.5 * k_theta * t) * sin2(0.5 * (k_z * h + Jet{phase, 0, 0})) * ends;
      if (b > 0) r = r + b * window(t, kPi / 2, 0.9) * window(h, 0.0, 0.15);
      return r;
    };
    axes.push_back(axis);
    sides.push_back(std::make_shared<RadialSurface>(axis, z0, z1, false, radius));
    parts.push_back({sides.back(), std::make_shared<FlatRing>(glm::dvec3(axis, z1), 0.0, R, true),
                     std::make_shared<FlatRing>(glm::dvec3(axis, z0), 0.0, R, false)});
  }

  {
    Builder out(asset.high, asset.high_part, false);
    for (int i = 0; i < kTubes; ++i) {
      const RadialSurface& side = *sides[std::size_t(i)];
      auto corner = [&](double theta, double z) { return out.corner(side.point(theta, z), side.normal_at(theta, z)); };
      add_capped_cylinder(out, axes[std::size_t(i)], R, z0, z1, around_high, along_high, std::max(1, around_high / 24),
                          corner, nullptr, nullptr, i);
    }
  }
  {
    std::vector<glm::dvec2> sizes;
    for (int i = 0; i < kTubes; ++i) sizes.insert(sizes.end(), {{2 * kPi * R, L}, {2 * R, 2 * R}, {2 * R, 2 * R}});
    const std::vector<Island> islands = pack_islands(sizes);
    Builder out(asset.low, asset.low_part, true);
    for (int i = 0; i < kTubes; ++i) {
      const glm::dvec2 axis = axes[std::size_t(i)];
      const Island& side_uv = islands[std::size_t(3 * i)];
      auto corner = [&](double theta, double z) {
        const glm::dvec3 e(std::cos(theta), std::sin(theta), 0.0);
        return out.corner(glm::dvec3(axis, z) + R * e, e, side_uv(theta * R, z - z0));
      };
      auto seam_uv = [&](double z) { return side_uv(2 * kPi * R, z - z0); };
      auto cap_uv = [&](bool top, double x, double y) {
        return disc_uv(islands[std::size_t(3 * i + (top ? 1 : 2))], R, top, x, y);
      };
      add_capped_cylinder(out, axis, R, z0, z1, around_low, along_low, 1, corner, seam_uv, cap_uv, i);
    }
  }
  const double displacement = std::max(bulge, kRipple) + sagitta(R, around_low);
  attach_surfaces(asset, std::move(parts), 3 * displacement);
  name_meshes(asset);
  return asset;
}

// ---- Thin shell ----

HardAsset make_thin_shell(double thickness, int around_low, int rings_low, int around_high, int rings_high) {
  constexpr double Rd = 0.4;
  const double t2 = thickness / 2, amplitude = thickness / 4;
  HardAsset asset;
  asset.name = format_name("thin_shell_t%g", thickness);

  auto fade = [](double x, double y) { return ramp_down(radius_jet(x, y), 0.28, 0.37); };
  auto top_height = [=](double x, double y) {
    const Jet u = u_param(x), v = v_param(y);
    const double w = 2 * kPi / 0.1;
    return t2 + amplitude * fade(x, y) * sin(w * u) * sin(w * v);  // egg-crate
  };
  auto bottom_height = [=](double x, double y) {
    const Jet u = u_param(x), v = v_param(y);
    const double w = 2 * kPi / 0.07;
    return -1.0 * (t2 + amplitude * fade(x, y) * cos(w * (0.8 * u + 0.6 * v)));  // diagonal waves
  };
  const auto top = std::make_shared<HeightDisc>(Rd, true, top_height);
  const auto bottom = std::make_shared<HeightDisc>(Rd, false, bottom_height);
  const auto rim = std::make_shared<TorusRim>(Rd, t2);

  // Both meshes: the faces' outer rings, the discs inside them, the rim between them. face(k)
  // makes a corner of disc k (0 top, 1 bottom) at (x, y); rim_corner one of the rim's inner rings;
  // rim_reuse re-uses a corner (a face's outer corner, or the first of a ring at the seam) on the
  // rim at (theta, phi), with its own UV on the low-poly.
  auto build = [&](Builder& out, int around, int rings, int rim_segments,
                   const std::function<Corner(int k, double x, double y)>& face,
                   const std::function<Corner(double theta, double phi)>& rim_corner,
                   const std::function<Corner(const Corner&, double theta, double phi)>& rim_reuse) {
    std::array<Ring, 2> outer;
    for (int k = 0; k < 2; ++k) {
      outer[std::size_t(k)] =
          make_ring(out, around, [&](double theta) { return face(k, Rd * std::cos(theta), Rd * std::sin(theta)); });
      auto vertex = [&](double rho, double theta) { return face(k, rho * std::cos(theta), rho * std::sin(theta)); };
      fill_disc(out, outer[std::size_t(k)], rings, Rd, vertex, k == 0, k);
    }
    // The rim from the top (phi = pi/2) down to the bottom; outward, so the lower ring comes first.
    std::vector<Ring> band;
    for (int m = 0; m <= rim_segments; ++m) {
      const double phi = kPi / 2 - kPi * m / rim_segments;
      Ring ring;
      for (int k = 0; k <= around; ++k) {
        const double theta = 2 * kPi * k / around;
        if (m == 0 || m == rim_segments)
          ring.push_back(rim_reuse(outer[m == 0 ? 0 : 1][std::size_t(k)], theta, phi));
        else
          ring.push_back(k < around ? rim_corner(theta, phi) : rim_reuse(ring.front(), theta, phi));
      }
      band.push_back(ring);
      if (m > 0) stitch(out, band[std::size_t(m)], band[std::size_t(m - 1)], 2);
    }
  };

  {
    Builder out(asset.high, asset.high_part, false);
    auto face = [&](int k, double x, double y) {
      const HeightDisc& d = k == 0 ? *top : *bottom;
      return out.corner(d.point(x, y), d.normal_at(x, y));
    };
    auto rim_corner = [&](double theta, double phi) {
      return out.corner(rim->point(theta, phi), TorusRim::normal_at(theta, phi));
    };
    auto rim_reuse = [](const Corner& c, double, double) { return c; };
    build(out, around_high, rings_high, 16, face, rim_corner, rim_reuse);
  }
  {
    const std::vector<Island> islands = pack_islands({{2 * Rd, 2 * Rd}, {2 * Rd, 2 * Rd}, {2 * kPi * Rd, kPi * t2}});
    Builder out(asset.low, asset.low_part, true);
    const std::array<std::uint32_t, 2> face_normal = {out.normal({0, 0, 1}), out.normal({0, 0, -1})};
    auto face = [&](int k, double x, double y) {
      const glm::dvec2 uv = disc_uv(islands[std::size_t(k)], Rd, k == 0, x, y);
      return Corner{out.position({x, y, k == 0 ? t2 : -t2}), face_normal[std::size_t(k)], out.uv(uv)};
    };
    auto rim_uv = [&](double theta, double phi) { return islands[2](theta * Rd, (phi + kPi / 2) * t2); };
    auto rim_corner = [&](double theta, double phi) {
      return out.corner(rim->point(theta, phi), TorusRim::normal_at(theta, phi), rim_uv(theta, phi));
    };
    auto rim_reuse = [&](const Corner& c, double theta, double phi) {
      return Corner{c.p, c.n, out.uv(rim_uv(theta, phi))};
    };
    build(out, around_low, rings_low, 4, face, rim_corner, rim_reuse);
  }
  const double displacement = amplitude + std::max(sagitta(Rd, around_low), sagitta(t2, 8));
  attach_surfaces(asset, {{top}, {bottom}, {rim}}, 3 * displacement);
  name_meshes(asset);
  return asset;
}


// ---- Rod in a bore ----

HardAsset make_cavity(double gap, int around_low, int along_low, int around_high, int along_high) {
  assert(gap > 0 && gap < 0.1);
  constexpr double kOuter = 0.3, kInner = 0.2, kPipeHalf = 0.25, kRodHalf = 0.26;
  const double rod = kInner - gap, amplitude = gap / 5;
  HardAsset asset;
  asset.name = format_name("cavity_gap%g", gap);

  // Dimples pushed into the bore wall (16 around, 5 along) and a 10-start helical groove cut into
  // the rod: both move away from the clearance, which stays >= gap.
  auto bore_radius = [=](double theta, double z) {
    const Jet t = u_param(theta), h = v_param(z);
    const Jet ends = ramp_down(abs(h), kPipeHalf - 0.05, kPipeHalf - 0.015);
    return kInner + amplitude * sin2(8.0 * t) * sin2((kPi / 0.1) * h) * ends;
  };
  auto rod_radius = [=](double theta, double z) {
    const Jet t = u_param(theta), h = v_param(z);
    const Jet ends = ramp_down(abs(h), kRodHalf - 0.05, kRodHalf - 0.015);
    return rod + (-amplitude) * sin2(0.5 * (10.0 * t + (2 * kPi / 0.06) * h)) * ends;
  };
  const glm::dvec2 axis(0.0);
  const auto outer_wall = std::make_shared<RadialSurface>(axis, -kPipeHalf, kPipeHalf, false,
                                                          [](double, double) { return Jet{kOuter, 0, 0}; });
  const auto bore_wall = std::make_shared<RadialSurface>(axis, -kPipeHalf, kPipeHalf, true, bore_radius);
  const auto rod_side = std::make_shared<RadialSurface>(axis, -kRodHalf, kRodHalf, false, rod_radius);
  std::vector<Part> parts = {
      {outer_wall, bore_wall, std::make_shared<FlatRing>(glm::dvec3(0, 0, kPipeHalf), kInner, kOuter, true),
       std::make_shared<FlatRing>(glm::dvec3(0, 0, -kPipeHalf), kInner, kOuter, false)},
      {rod_side, std::make_shared<FlatRing>(glm::dvec3(0, 0, kRodHalf), 0.0, rod, true),
       std::make_shared<FlatRing>(glm::dvec3(0, 0, -kRodHalf), 0.0, rod, false)}};

  // The pipe's end rings between the outer wall's and the bore's end rings; ring_uv(top, x, y)
  // may be null.
  auto add_end_rings = [&](Builder& out, const std::vector<Ring>& outer, const std::vector<Ring>& bore, int segments,
                           const std::function<glm::dvec2(bool top, double x, double y)>& ring_uv) {
    for (bool top : {true, false}) {
      std::function<glm::dvec2(double, double)> uv;
      if (ring_uv) uv = [&ring_uv, top](double x, double y) { return ring_uv(top, x, y); };
      auto edge_uv = [&](double radius) {
        return [&uv, radius](double theta) {
          return uv ? uv(radius * std::cos(theta), radius * std::sin(theta)) : glm::dvec2(0.0);
        };
      };
      const std::uint32_t n = out.normal({0.0, 0.0, top ? 1.0 : -1.0});
      add_annulus(out, edge_ring(out, top ? outer.back() : outer.front(), n, edge_uv(kOuter)),
                  edge_ring(out, top ? bore.back() : bore.front(), n, edge_uv(kInner)), segments, kOuter, kInner,
                  flat_vertex(out, axis, top ? kPipeHalf : -kPipeHalf, n, uv), top, 0);
    }
  };

  {
    Builder out(asset.high, asset.high_part, false);
    auto corner = [&](const RadialSurface& s) {
      return [&out, &s](double theta, double z) { return out.corner(s.point(theta, z), s.normal_at(theta, z)); };
    };
    // The outer wall is a plain cylinder: dense around only.
    const auto outer = add_wall(out, around_high, 8, -kPipeHalf, kPipeHalf, corner(*outer_wall), nullptr, false, 0);
    const auto bore = add_wall(out, around_high, along_high, -kPipeHalf, kPipeHalf, corner(*bore_wall), nullptr, true, 0);
    add_end_rings(out, outer, bore, 4, nullptr);
    add_capped_cylinder(out, axis, rod, -kRodHalf, kRodHalf, around_high, along_high, std::max(1, around_high / 24),
                        corner(*rod_side), nullptr, nullptr, 1);
  }
  {
    const std::vector<Island> islands =
        pack_islands({{2 * kPi * kOuter, 2 * kPipeHalf}, {2 * kPi * kInner, 2 * kPipeHalf}, {2 * kOuter, 2 * kOuter},
                      {2 * kOuter, 2 * kOuter}, {2 * kPi * rod, 2 * kRodHalf}, {2 * rod, 2 * rod}, {2 * rod, 2 * rod}});
    Builder out(asset.low, asset.low_part, true);
    // A plain wall of radius r unrolled into `island`; the bore's runs against theta, so that its
    // UVs keep the winding of faces that face the axis.
    auto plain = [&](double r, bool bore, const Island& island, double z0) {
      return [&out, r, bore, island, z0](double theta, double z) {
        const glm::dvec3 e(std::cos(theta), std::sin(theta), 0.0);
        return out.corner(glm::dvec3(0, 0, z) + r * e, bore ? -e : e,
                          island((bore ? 2 * kPi - theta : theta) * r, z - z0));
      };
    };
    auto seam = [&](double r, bool bore, const Island& island, double z0) {
      return [r, bore, island, z0](double z) { return island(bore ? 0.0 : 2 * kPi * r, z - z0); };
    };
    const auto outer = add_wall(out, around_low, along_low, -kPipeHalf, kPipeHalf,
                                plain(kOuter, false, islands[0], -kPipeHalf), seam(kOuter, false, islands[0], -kPipeHalf),
                                false, 0);
    const auto bore = add_wall(out, around_low, along_low, -kPipeHalf, kPipeHalf,
                               plain(kInner, true, islands[1], -kPipeHalf), seam(kInner, true, islands[1], -kPipeHalf),
                               true, 0);
    add_end_rings(out, outer, bore, 1,
                  [&](bool top, double x, double y) { return disc_uv(islands[top ? 2 : 3], kOuter, top, x, y); });
    add_capped_cylinder(out, axis, rod, -kRodHalf, kRodHalf, around_low, along_low, 2,
                        plain(rod, false, islands[4], -kRodHalf), seam(rod, false, islands[4], -kRodHalf),
                        [&](bool top, double x, double y) { return disc_uv(islands[top ? 5 : 6], rod, top, x, y); }, 1);
  }
  const double displacement = amplitude + sagitta(kOuter, around_low);
  attach_surfaces(asset, std::move(parts), 3 * displacement);
  name_meshes(asset);
  return asset;
}

// ---- Bevelled box ----

HardAsset make_bevelled_box(double half, double bevel, int flat_high, int bevel_high) {
  assert(bevel > 0 && bevel < half && flat_high >= 1 && bevel_high >= 1);
  HardAsset asset;
  asset.name = format_name("bevelled_box_h%g_b%g", half, bevel);
  const auto box = std::make_shared<RoundedBox>(half, bevel);
  const double e = half - bevel;

  // The six faces: normal axis, its sign, and tangent axes (u, v) with e_u x e_v = the normal.
  struct Face {
    int axis;
    bool positive;
    int u, v;
  };
  constexpr std::array<Face, 6> kFaces = {
      {{0, true, 1, 2}, {0, false, 2, 1}, {1, true, 2, 0}, {1, false, 0, 2}, {2, true, 0, 1}, {2, false, 1, 0}}};

  {
    // Grid coordinates along every axis of the box [-half, half]^3: bevel_high steps over each
    // bevel, evenly in angle once mapped onto the rounded edge, and flat_high across the flat part.
    // Faces share these values, so the grids meet exactly on the box's edges.
    std::vector<double> t;
    for (int k = bevel_high; k >= 1; --k) t.push_back(-(e + bevel * std::tan(kPi / 4 * k / bevel_high)));
    t.front() = -half;
    for (int k = 0; k <= flat_high; ++k) t.push_back(k == flat_high ? e : -e + 2 * e * k / flat_high);
    for (int k = 1; k <= bevel_high; ++k) t.push_back(k == bevel_high ? half : e + bevel * std::tan(kPi / 4 * k / bevel_high));
    const std::size_t n = t.size();
    Builder out(asset.high, asset.high_part, false);
    std::unordered_map<std::size_t, Corner> shared;  // by grid index (ix, iy, iz)
    for (const Face& f : kFaces) {
      std::vector<Corner> grid;
      for (std::size_t j = 0; j < n; ++j)
        for (std::size_t i = 0; i < n; ++i) {
          std::array<std::size_t, 3> index{};
          index[std::size_t(f.axis)] = f.positive ? n - 1 : 0;
          index[std::size_t(f.u)] = i;
          index[std::size_t(f.v)] = j;
          const std::size_t key = (index[0] * n + index[1]) * n + index[2];
          auto it = shared.find(key);
          if (it == shared.end()) {
            const auto [p, normal] = box->map({t[index[0]], t[index[1]], t[index[2]]});
            it = shared.emplace(key, out.corner(p, normal)).first;
          }
          grid.push_back(it->second);
        }
      for (std::size_t j = 0; j + 1 < n; ++j)
        for (std::size_t i = 0; i + 1 < n; ++i)
          out.quad(grid[j * n + i], grid[j * n + i + 1], grid[(j + 1) * n + i + 1], grid[(j + 1) * n + i], 0);
    }
  }
  {
    const std::vector<Island> islands = pack_islands(std::vector<glm::dvec2>(6, glm::dvec2(2 * half)));
    Builder out(asset.low, asset.low_part, true);
    std::array<std::uint32_t, 8> corners{};  // by sign bits x 4 + y 2 + z 1
    for (std::size_t c = 0; c < 8; ++c)
      corners[c] = out.position(half * glm::dvec3(c & 4 ? 1 : -1, c & 2 ? 1 : -1, c & 1 ? 1 : -1));
    for (std::size_t k = 0; k < kFaces.size(); ++k) {
      const Face& f = kFaces[k];
      glm::dvec3 normal(0.0);
      normal[f.axis] = f.positive ? 1.0 : -1.0;
      const std::uint32_t nn = out.normal(normal);
      std::array<Corner, 4> quad{};
      const std::array<std::array<int, 2>, 4> square = {{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
      for (std::size_t q = 0; q < 4; ++q) {
        std::array<int, 3> sign{};
        sign[std::size_t(f.axis)] = f.positive;
        sign[std::size_t(f.u)] = square[q][0];
        sign[std::size_t(f.v)] = square[q][1];
        const glm::dvec2 uv = islands[k](2 * half * square[q][0], 2 * half * square[q][1]);
        quad[q] = {corners[std::size_t(sign[0] * 4 + sign[1] * 2 + sign[2])], nn, out.uv(uv)};
      }
      out.quad(quad[0], quad[1], quad[2], quad[3], 0);
    }
  }
  attach_surfaces(asset, {{box}}, 3 * bevel * (std::sqrt(3.0) - 1));
  name_meshes(asset);
  return asset;
}

// ---- Broken exports and the set ----

HardAsset flip_high_winding(HardAsset asset, bool keep_normals) {
  for (std::vector<std::uint32_t>* index : {&asset.high.position_index, &asset.high.normal_index, &asset.high.uv_index})
    for (std::size_t i = 0; i + 2 < index->size(); i += 3) std::swap((*index)[i + 1], (*index)[i + 2]);
  if (!keep_normals) {
    asset.high.normals.clear();
    asset.high.normal_index.clear();
  }
  asset.name += keep_normals ? "_flipped" : "_flipped_no_normals";
  name_meshes(asset);
  return asset;
}

std::vector<HardAsset> hard_asset_set() {
  std::vector<HardAsset> set;
  set.push_back(make_close_tubes(0.012, 0.04));
  set.push_back(make_close_tubes(0.004, 0.04));
  set.push_back(make_close_tubes(0.012, 0.14));
  set.push_back(make_thin_shell());
  set.push_back(make_cavity());
  set.push_back(make_bevelled_box());
  set.push_back(flip_high_winding(make_thin_shell(), false));
  return set;
}

}  // namespace nmbake::procedural
