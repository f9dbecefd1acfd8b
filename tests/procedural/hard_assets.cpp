#include "hard_assets.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <unordered_map>
#include <utility>

#include "hard_asset_builder.h"
#include "hard_asset_jet.h"
#include "hard_asset_surfaces.h"

namespace nmbake::procedural {

using namespace detail;

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
      add_capped_cylinder(out, axes[std::size_t(i)], R, z0, z1, around_high, along_high, std::max(1, around_high / 24), corner,
                          nullptr, nullptr, i);
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
        if (m == 0 || m == rim_segments) ring.push_back(rim_reuse(outer[m == 0 ? 0 : 1][std::size_t(k)], theta, phi));
        else ring.push_back(k < around ? rim_corner(theta, phi) : rim_reuse(ring.front(), theta, phi));
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
    auto rim_reuse = [&](const Corner& c, double theta, double phi) { return Corner{c.p, c.n, out.uv(rim_uv(theta, phi))}; };
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
  const auto outer_wall = std::make_shared<RadialSurface>(axis, -kPipeHalf, kPipeHalf, false, [](double, double) {
    return Jet{kOuter, 0, 0};
  });
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
        return
            [&uv, radius](double theta) { return uv ? uv(radius * std::cos(theta), radius * std::sin(theta)) : glm::dvec2(0.0); };
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
    const std::vector<Island> islands = pack_islands({{2 * kPi * kOuter, 2 * kPipeHalf},
                                                      {2 * kPi * kInner, 2 * kPipeHalf},
                                                      {2 * kOuter, 2 * kOuter},
                                                      {2 * kOuter, 2 * kOuter},
                                                      {2 * kPi * rod, 2 * kRodHalf},
                                                      {2 * rod, 2 * rod},
                                                      {2 * rod, 2 * rod}});
    Builder out(asset.low, asset.low_part, true);
    // A plain wall of radius r unrolled into `island`; the bore's runs against theta, so that its
    // UVs keep the winding of faces that face the axis.
    auto plain = [&](double r, bool bore, const Island& island, double z0) {
      return [&out, r, bore, island, z0](double theta, double z) {
        const glm::dvec3 e(std::cos(theta), std::sin(theta), 0.0);
        return out.corner(glm::dvec3(0, 0, z) + r * e, bore ? -e : e, island((bore ? 2 * kPi - theta : theta) * r, z - z0));
      };
    };
    auto seam = [&](double r, bool bore, const Island& island, double z0) {
      return [r, bore, island, z0](double z) { return island(bore ? 0.0 : 2 * kPi * r, z - z0); };
    };
    const auto outer = add_wall(out, around_low, along_low, -kPipeHalf, kPipeHalf, plain(kOuter, false, islands[0], -kPipeHalf),
                                seam(kOuter, false, islands[0], -kPipeHalf), false, 0);
    const auto bore = add_wall(out, around_low, along_low, -kPipeHalf, kPipeHalf, plain(kInner, true, islands[1], -kPipeHalf),
                               seam(kInner, true, islands[1], -kPipeHalf), true, 0);
    add_end_rings(out, outer, bore, 1,
                  [&](bool top, double x, double y) { return disc_uv(islands[top ? 2 : 3], kOuter, top, x, y); });
    add_capped_cylinder(
        out, axis, rod, -kRodHalf, kRodHalf, around_low, along_low, 2, plain(rod, false, islands[4], -kRodHalf),
        seam(rod, false, islands[4], -kRodHalf),
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
