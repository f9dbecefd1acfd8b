// Thin, close parts with a coarse low-poly (issue 34, item 1): a row of legs (or fingers, tails,
// antennae), each a bent capsule, with a finely tessellated bumpy high-poly and a low-poly of few
// sides and few rings that lies outside the high surface at its corners and inside it between
// them, as a decimated low-poly does. Neighbouring legs are closer than the low-poly lies from the
// high surface in places, so a cage limited to half the low-poly gap can start inside a leg's own
// high-poly. Object space, about one unit across.
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/mesh.h"

namespace nmbake::procedural {

struct ThinPartsSpec {
  std::string name;  // Mesh::source of both meshes; usable in file names
  int legs = 5;
  double radius_min = 0.02, radius_max = 0.04;  // the legs' radii, from the first leg to the last
  double gap = 0.008;                           // between neighbouring high-poly capsules (without bumps) at their roots
  double length = 0.6;                          // of each capsule's straight part (its caps add a radius at either end)
  double bend = 0.15;                           // every leg's tip moves this far along +y (a parabola: the legs stay parallel)
  double splay = 0.0;                           // and this far along x, alternately + and -: neighbours close in and part
  double bump = 0.08;                           // the high-poly's radial bumps, a share of the radius (both signs)
  double low_scale = 1.06;                      // the low-poly's corners lie at this share of the high-poly's radius
  int sides_low = 6, rings_low = 6, cap_rows_low = 1;  // rings along the straight part, rows per cap
  int around_high = 40, rows_high = 80;
};

struct ThinParts {
  Mesh low;   // UVs (one island per leg), no normals (as an OBJ of it has none: nmbake computes them)
  Mesh high;  // no UVs, no normals (nmbake computes them)
};

ThinParts make_thin_parts(const ThinPartsSpec& spec);

// The diagonal of both meshes' bounding box (what nmbake's distances are shares of).
double diagonal(const ThinParts& parts);

// The family the tests judge the automatic cage on: legs, fingers, antennae, tails, low-polys
// outside, inside and crossing the high surface, 1-5% of the high-poly's triangles.
std::vector<ThinPartsSpec> thin_parts_family();

}  // namespace nmbake::procedural
