#include "hard_asset_builder.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <numeric>

#include "hard_asset_jet.h"

namespace nmbake::procedural::detail {

constexpr double kIslandMargin = 0.02;  // UV space, between islands and to the border

Ring make_ring(Builder& out, int count, const std::function<Corner(double theta)>& corner,
               const std::function<glm::dvec2()>& seam_uv) {
  Ring ring;
  for (int k = 0; k < count; ++k) ring.push_back(corner(2 * kPi * k / count));
  Corner last = ring.front();
  if (seam_uv) last.t = out.uv(seam_uv());
  ring.push_back(last);
  return ring;
}

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
    up ? out.triangle(centre, previous[k], previous[k + 1], part) : out.triangle(centre, previous[k + 1], previous[k], part);
}

std::vector<Ring> add_wall(Builder& out, int around, int along, double z0, double z1,
                           const std::function<Corner(double theta, double z)>& corner,
                           const std::function<glm::dvec2(double z)>& seam_uv, bool bore, int part) {
  std::vector<Ring> rings;
  for (int j = 0; j <= along; ++j) {
    const double z = j == along ? z1 : z0 + (z1 - z0) * j / along;
    std::function<glm::dvec2()> seam;
    if (seam_uv) seam = [&] { return seam_uv(z); };
    rings.push_back(make_ring(
        out, around, [&](double theta) { return corner(theta, z); }, seam));
    if (j == 0) continue;
    const Ring &lower = rings[std::size_t(j - 1)], &upper = rings[std::size_t(j)];
    bore ? stitch(out, upper, lower, part) : stitch(out, lower, upper, part);
  }
  return rings;
}

Ring edge_ring(Builder& out, Ring ring, std::uint32_t n, const std::function<glm::dvec2(double theta)>& uv) {
  const std::size_t count = ring.size() - 1;
  for (std::size_t k = 0; k < count; ++k) ring[k] = {ring[k].p, n, out.uv(uv(2 * kPi * double(k) / double(count)))};
  ring.back() = ring.front();
  return ring;
}

void add_annulus(Builder& out, const Ring& outer, const Ring& inner, int segments, double r_outer, double r_inner,
                 const std::function<Corner(double rho, double theta)>& vertex, bool up, int part) {
  Ring previous = outer;
  for (int s = 1; s <= segments; ++s) {
    const double rho = r_outer + (r_inner - r_outer) * s / segments;
    const Ring ring =
        s == segments ? inner : make_ring(out, int(outer.size()) - 1, [&](double theta) { return vertex(rho, theta); });
    up ? stitch(out, previous, ring, part) : stitch(out, ring, previous, part);
    previous = ring;
  }
}

std::function<Corner(double, double)> flat_vertex(Builder& out, glm::dvec2 axis, double z, std::uint32_t n,
                                                  std::function<glm::dvec2(double x, double y)> uv) {
  return [&out, axis, z, n, uv](double rho, double theta) {
    const double x = rho * std::cos(theta), y = rho * std::sin(theta);
    return Corner{out.position({axis.x + x, axis.y + y, z}), n, out.uv(uv ? uv(x, y) : glm::dvec2(0.0))};
  };
}

void add_capped_cylinder(Builder& out, glm::dvec2 axis, double radius, double z0, double z1, int around, int along, int cap_rings,
                         const std::function<Corner(double theta, double z)>& side,
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

glm::dvec2 disc_uv(const Island& island, double radius, bool up, double x, double y) {
  return island((up ? x : -x) + radius, y + radius);
}

std::string format_name(const char* format, double a, double b) {
  char text[128];
  std::snprintf(text, sizeof text, format, a, b);
  return text;
}

void name_meshes(HardAsset& asset) { asset.low.source = asset.high.source = asset.name; }

double sagitta(double r, int count) { return r * (1 - std::cos(kPi / count)); }

}  // namespace nmbake::procedural::detail
