// Procedural "hard assets" with exact answers, for the tests and the accuracy bench of robust hits:
// known-answer models where a ray from one part of the low-poly can land on a neighbouring part
// (tubes a gap apart, the two faces of a thin shell, a rod in a bore, a bevelled box's corners,
// a high-poly exported with its winding flipped).
//
// Every part's high-poly surface is analytic (a radial displacement of a cylinder, a height field
// over a disc, a torus, a rounded-box SDF, planes); the high mesh samples that same surface, with
// the analytic normals as vertex normals, and `locate` intersects a line with the analytic surface
// itself, so the reference does not depend on the high mesh's tessellation. Object space, units
// as the meshes (the models are about one unit across).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/mesh.h"

namespace nmbake::procedural {

// Where the line {p + s dir} meets one part's analytic high-poly surface.
struct SurfacePoint {
  bool crossed = false;    // false: no crossing with |s| <= max_s; point is then the part's point nearest to p
  double s = 0.0;          // line parameter of the crossing (0 when !crossed)
  glm::dvec3 point{0.0};   // object space, on the analytic surface
  glm::dvec3 normal{0.0};  // unit, outward from the solid
};

struct HardAsset {
  std::string name;  // also Mesh::source of both meshes; no spaces or slashes (usable in file names)
  // Low-poly: UVs (islands inside [0,1]^2, not overlapping, >= 0.02 apart), smooth per-vertex normals
  // (split at the hard edges each case names), triangles counter-clockwise seen from outside, closed.
  Mesh low;
  // High-poly: dense, analytic unit outward per-vertex normals, counter-clockwise from outside,
  // closed; no UVs.
  Mesh high;
  std::vector<int> low_part;   // per low triangle: id of the part it belongs to
  std::vector<int> high_part;  // per high triangle: id of the part (same ids as low_part)

  // The crossing of {p + s dir} with part `part`'s analytic surface with the smallest |s|,
  // |s| <= max_s (p: a point on the low-poly, dir: unit direction, the bake's ray direction there).
  // The line is scanned in steps of max_s / 256 and each sign change of the part's implicit function
  // refined by bisection to 1e-13 relative, so two crossings closer together than a step (a line
  // grazing a ripple) may be missed. Patch boundaries are widened by 1e-6 so that float vertices on
  // an edge count as on the patch; crossings within 1e-7 of each other (on a hard edge) go to the
  // patch whose normal is most nearly along dir. Without a crossing: the part's point nearest to p,
  // exact on planes, the torus rim and the rounded box; on displaced patches the best of a 32 x 32
  // grid of samples refined by Gauss-Newton (global as far as the grid resolves the surface, which
  // it does on these; not proven). Thread-safe.
  std::function<SurfacePoint(const glm::dvec3& p, const glm::dvec3& dir, int part)> locate;
  // locate(p, dir, part).normal.
  std::function<glm::dvec3(const glm::dvec3& p, const glm::dvec3& dir, int part)> expected_normal;
  // The largest |s| locate searches: 3 x (largest displacement of the high-poly from the low-poly's
  // base shape + largest chord error of the low-poly).
  double max_s = 0.0;
};

// Five parallel closed tubes ("fingers") of radius 0.05 and length 0.6 along z, centred on the x
// axis in a row along x, `gap` apart surface to surface. Each tube's side is r(theta, z) = 0.05 +
// ripple + bump: the ripple is inward only, -0.0015 sin^2(k theta / 2) sin^2((k_z z + phase) / 2)
// with k even and a different k and phase per tube, so it vanishes on the sides facing the
// neighbours (theta = 0, pi) and the high tubes are exactly `gap` apart there; the middle tube
// (part 2) has a smooth bump of height `bulge` on its +y side (cos^2 window, half-widths 0.9 rad
// and 0.15 in z), whose top (theta = pi/2, z = 0) is exactly at r = 0.05 + bulge. Ripple and bump
// vanish within 0.015 of the ends, so the caps are exact discs (normals +-z). Low-poly: plain
// cylinders of around_low x along_low quads plus fan caps, normals split at the caps' edges; UVs:
// one island per side (unrolled) and per cap. Parts: tube index 0..4 from -x to +x.
// around_high must be a multiple of 4 and along_high even (vertices on the facing lines and the top).
// Defaults: 199,680 high triangles.
HardAsset make_close_tubes(double gap = 0.012, double bulge = 0.04, int around_low = 24, int along_low = 8, int around_high = 192,
                           int along_high = 96);

// An "ear": a closed slab over the disc of radius 0.4 in xy, top z = thickness/2 + d_top(x, y),
// bottom z = -thickness/2 - d_bottom(x, y) (egg-crate on top, diagonal waves below, amplitude
// thickness/4, fading to 0 between radius 0.28 and 0.37), closed by a rim that is the outer half of
// a torus (tube radius thickness/2), tangent to both faces. Parts: 0 top face, 1 bottom face, 2 rim.
// The rim's crossings are exact too, but a line from the low-poly's rim near its edges may cross
// the top or bottom face instead of the rim (the low rim's chords lie inside radius 0.4), so for
// those points locate(.., 2) falls back to the nearest rim point, which is only close to where the
// bake lands. Low-poly: the slab without detail (rings_low rings, around_low corners on the rim,
// 4 segments across the rim), smooth normals throughout; UVs: top and bottom discs and the rim
// strip. Defaults: 129,024 high triangles.
HardAsset make_thin_shell(double thickness = 0.01, int around_low = 48, int rings_low = 4, int around_high = 576,
                          int rings_high = 96);

// A rod in a bore: part 0 is a thick-walled pipe (outer radius 0.3, inner 0.2, z in [-0.25, 0.25],
// closed by flat end rings), part 1 a coaxial rod of radius 0.2 - gap, z in [-0.26, 0.26], with flat
// caps. Detail of amplitude gap/5, fading to 0 near the ends: dimples pushed into the pipe's bore
// wall, a helical groove cut into the rod, so the clearance is never less than `gap`. The bore
// wall's normals point to the axis. Low-poly: plain cylinders and rings, normals split at the end
// rings and caps; UVs: one island per wall, ring and cap. Defaults: 111,616 high triangles.
HardAsset make_cavity(double gap = 0.01, int around_low = 32, int along_low = 4, int around_high = 256, int along_high = 96);

// A box of half-size `half` whose high-poly has every edge and corner rounded with radius `bevel`
// (the rounded-box SDF; flat_high quads across each face's flat part, bevel_high across each
// bevel on each side, evenly in angle). Low-poly: the plain box, 24 corners, normals split per
// face, one UV island per face. One part (0). Defaults: 92,928 high triangles.
HardAsset make_bevelled_box(double half = 0.3, double bevel = 0.03, int flat_high = 64, int bevel_high = 12);

// The same asset with every high-poly triangle wound the other way (a broken STL or scan export);
// keep_normals = false also removes the high-poly's normals (normals and normal_index cleared), as
// STL has none. The name (and Mesh::source) gets "_flipped" or "_flipped_no_normals".
HardAsset flip_high_winding(HardAsset asset, bool keep_normals);

// The set the accuracy bench loops over: close_tubes (gap 0.012, bulge 0.04), close_tubes (gap
// 0.004, bulge 0.04), close_tubes (gap 0.012, bulge 0.14), thin_shell, cavity, bevelled_box and the
// thin shell flipped without normals.
std::vector<HardAsset> hard_asset_set();

}  // namespace nmbake::procedural
