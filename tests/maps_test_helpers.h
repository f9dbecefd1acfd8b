// What the texture-set tests (test_maps.cpp, test_maps_auto.cpp) share: the bake options they start
// from, a map of a result by kind, and the analytic AO beside a wall.
#pragma once

#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "pipeline/bake.h"
#include "test_support.h"

namespace nmbake::test {

// A size x size bake of `maps`, ray distances front/rear, no padding, two threads.
inline BakeOptions map_options(int size, std::vector<MapKind> maps, float front = 0.1f, float rear = 0.1f) {
  BakeOptions o;
  o.width = o.height = size;
  o.front = front;
  o.rear = rear;
  o.padding = 0;
  o.threads = 2;
  o.maps.maps = std::move(maps);
  return o;
}

// The map of `kind` in `r`; throws when the bake made none.
inline const BakedMap& baked(const BakeResult& r, MapKind kind) {
  for (const BakedMap& m : r.maps)
    if (m.kind == kind) return m;
  throw std::runtime_error("no such map");
}

// AO beside an infinite wall with the distance limit r, at the distance d from it (notes: maps.md):
// the share of the cosine-weighted hemisphere the wall leaves open.
inline double wall_ao(double d, double r) {
  const double a = d / r;
  return a >= 1.0 ? 1.0 : 1.0 - (std::acos(a) - a * std::sqrt(1.0 - a * a)) / kPi;
}

}  // namespace nmbake::test
