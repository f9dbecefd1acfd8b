#include "thin_parts.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "procedural.h"

namespace nmbake::procedural {

namespace {

// One leg: a capsule around the bent axis c(s) = root + (splay f(s), bend f(s), s), f = (s/L)^2
// on the straight part, continued straight beyond (the caps follow the axis's tangent).
struct Leg {
  glm::dvec3 root;
  double radius, length, bend, splay;

  double f(double s) const {
    const double u = std::clamp(s, 0.0, length) / length;
    return u * u + (s > length ? 2.0 * (s - length) / length : 0.0);
  }
  double df(double s) const { return 2.0 * std::clamp(s, 0.0, length) / (length * length); }
  // Arc parameter a in [0, total()] (bottom pole to top pole) to the axis parameter s and the
  // profile's radius (over a cap, alpha is the angle from the pole).
  double total() const { return kPi * radius + length; }
  void profile(double a, double& s, double& rho) const {
    const double cap = 0.5 * kPi * radius;
    double alpha = 0.5 * kPi;
    if (a < cap) {
      alpha = a / radius;
      s = -radius * std::cos(alpha);
    } else if (a > cap + length) {
      alpha = (total() - a) / radius;
      s = length + radius * std::cos(alpha);
    } else {
      s = a - cap;
    }
    rho = radius * std::sin(alpha);
  }
  // The frame at s: tangent t, and e1, e2 across (e2 = t x e1).
  void frame(double s, glm::dvec3& t, glm::dvec3& e1, glm::dvec3& e2) const {
    t = glm::normalize(glm::dvec3(splay * df(s), bend * df(s), 1.0));
    e1 = glm::normalize(glm::dvec3(1, 0, 0) - t * t.x);
    e2 = glm::cross(t, e1);
  }
  glm::dvec3 axis(double s) const { return root + glm::dvec3(splay * f(s), bend * f(s), s); }
};

// The arc parameters of a low-poly's rows: the pole, cap rows, rings along the straight part,
// cap rows, the pole.
std::vector<double> low_rows(const Leg& leg, int cap_rows, int rings) {
  const double cap = 0.5 * kPi * leg.radius;
  std::vector<double> a{0.0};
  for (int k = 1; k <= cap_rows; ++k) a.push_back(cap * k / cap_rows);
  for (int k = 1; k <= rings; ++k) a.push_back(cap + leg.length * k / rings);
  for (int k = cap_rows - 1; k >= 0; --k) a.push_back(leg.total() - cap * k / cap_rows);
  return a;
}

// Appends one leg as rows of `around` corners between two poles (UVs: the island from uv0 of size
// uv_size, u around, v along).
void add_leg(Mesh& m, const Leg& leg, const std::vector<double>& rows, int around, double radial_scale, double bump, int phase,
             glm::dvec2 uv0, glm::dvec2 uv_size) {
  const std::uint32_t base = std::uint32_t(m.positions.size()), uv_base = std::uint32_t(m.uvs.size());
  const int R = int(rows.size()) - 1;
  for (int j = 0; j <= R; ++j) {
    double s = 0, rho = 0;
    leg.profile(rows[j], s, rho);
    glm::dvec3 t, e1, e2;
    leg.frame(s, t, e1, e2);
    const int count = (j == 0 || j == R) ? 1 : around;
    for (int i = 0; i < count; ++i) {
      const double theta = 2.0 * kPi * i / around;
      const glm::dvec3 radial = std::cos(theta) * e1 + std::sin(theta) * e2;
      const double detail = 1.0 + bump * std::sin(3.0 * theta + phase) * std::sin(2.0 * kPi * s / (0.13 + 0.02 * phase));
      m.positions.push_back(glm::vec3(leg.axis(s) + radial_scale * rho * detail * radial));
    }
    for (int i = 0; i <= around; ++i) {
      // A pole's UV per triangle, half way across its column (the last row's triangles reach the
      // pole from column i + 1, the first row's from column i).
      const double u = j == 0   ? (std::min(i, around - 1) + 0.5) / around
                       : j == R ? (std::max(i, 1) - 0.5) / around
                                : double(i) / around;
      m.uvs.push_back(glm::vec2(uv0 + uv_size * glm::dvec2(u, rows[j] / leg.total())));
    }
  }
  // Position of row j, column i (poles: one), and its UV.
  auto pos = [&](int i, int j) {
    if (j == 0) return base;
    if (j == R) return base + 1 + std::uint32_t((R - 1) * around);
    return base + 1 + std::uint32_t((j - 1) * around + i % around);
  };
  auto uv = [&](int i, int j) { return uv_base + std::uint32_t(j * (around + 1) + i); };
  auto corner = [&](int i, int j) {
    m.position_index.push_back(pos(i, j));
    m.uv_index.push_back(uv(i, j));
  };
  for (int j = 0; j < R; ++j)
    for (int i = 0; i < around; ++i) {  // (i, j) (i+1, j) (i+1, j+1) (i, j+1): counter-clockwise from outside
      if (j > 0) {
        corner(i, j), corner(i + 1, j), corner(i + 1, j + 1);
        m.source_face.push_back(std::uint32_t(m.source_face.size()));
      }
      if (j + 1 < R) {
        corner(i, j), corner(i + 1, j + 1), corner(i, j + 1);
        m.source_face.push_back(std::uint32_t(m.source_face.size()));
      }
    }
}

}  // namespace

ThinParts make_thin_parts(const ThinPartsSpec& spec) {
  std::vector<Leg> legs;
  double x = 0.0, width = 0.0, height = 0.0;
  for (int k = 0; k < spec.legs; ++k) {
    const double r =
        spec.legs > 1 ? spec.radius_min + (spec.radius_max - spec.radius_min) * k / (spec.legs - 1) : spec.radius_min;
    if (k > 0) x += legs.back().radius + spec.gap + r;
    legs.push_back({glm::dvec3(x, 0, 0), r, spec.length, spec.bend, (k % 2 ? -1.0 : 1.0) * spec.splay});
    width += 2.0 * kPi * r;
    height = std::max(height, legs.back().total());
  }
  for (Leg& l : legs) l.root.x -= 0.5 * x;
  // UV islands side by side, 0.02 apart, one scale for all (uniform texel density).
  const double margin = 0.02;
  const double scale = std::min((1.0 - margin * (spec.legs + 1)) / width, (1.0 - 2.0 * margin) / height);
  ThinParts out;
  out.low.source = out.high.source = spec.name;
  double u = margin;
  for (int k = 0; k < spec.legs; ++k) {
    const Leg& l = legs[std::size_t(k)];
    const glm::dvec2 uv0(u, margin), size(scale * 2.0 * kPi * l.radius, scale * l.total());
    add_leg(out.low, l, low_rows(l, spec.cap_rows_low, spec.rings_low), spec.sides_low, spec.low_scale, 0.0, k, uv0, size);
    std::vector<double> rows;
    for (int j = 0; j <= spec.rows_high; ++j) rows.push_back(l.total() * j / spec.rows_high);
    add_leg(out.high, l, rows, spec.around_high, 1.0, spec.bump, k, uv0, size);
    u += size.x + margin;
  }
  out.high.uvs.clear();
  out.high.uv_index.clear();
  return out;
}

double diagonal(const ThinParts& parts) {
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const Mesh* m : {&parts.low, &parts.high})
    for (const glm::vec3& p : m->positions) {
      lo = glm::min(lo, glm::dvec3(p));
      hi = glm::max(hi, glm::dvec3(p));
    }
  return glm::length(hi - lo);
}

std::vector<ThinPartsSpec> thin_parts_family() {
  // name, legs, radius_min, radius_max, gap, length, bend, splay, bump, low_scale, sides_low,
  // rings_low, cap_rows_low, around_high, rows_high
  return {
      // six-sided legs whose corners stand out
      {"legs", 5, 0.02, 0.04, 0.008, 0.6, 0.15, 0.0, 0.08, 1.06, 6, 6, 1, 40, 80},
      // thick, close, the low-poly's corners on the high surface
      {"fingers", 4, 0.045, 0.06, 0.006, 0.6, 0.1, 0.0, 0.06, 1.0, 8, 5, 1, 40, 80},
      // long and thin, the low-poly mostly outside
      {"antennae", 5, 0.008, 0.014, 0.004, 0.8, 0.25, 0.0, 0.1, 1.15, 5, 8, 1, 40, 80},
      // the low-poly inside the high surface, legs closing in on each other
      {"inside", 5, 0.02, 0.04, 0.008, 0.6, 0.15, 0.003, 0.08, 0.92, 6, 6, 1, 40, 80},
      // few rings along a strong bend: the chords cut through it
      {"tails", 4, 0.025, 0.035, 0.007, 0.6, 0.35, 0.0, 0.08, 1.06, 8, 3, 1, 40, 80},
      // eight square legs, bumpier than they are apart, closing in
      {"spider", 8, 0.012, 0.03, 0.003, 0.6, 0.15, 0.001, 0.15, 1.0, 4, 5, 1, 32, 64},
      // three-sided legs whose tips cross (the high-polys intersect there)
      {"tripods", 6, 0.015, 0.03, 0.002, 0.6, 0.3, 0.004, 0.2, 1.0, 3, 6, 1, 32, 64},
  };
}

}  // namespace nmbake::procedural
