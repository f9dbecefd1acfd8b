// Helpers of the stiff and extreme geometry tests (test_stability*.cpp): loading the cases in
// data/stability, bake options, recording measured figures, comparing maps.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <gtest/gtest.h>

#include "io/mesh_io.h"
#include "pipeline/bake.h"
#include "raycast.h"
#include "test_support.h"

namespace nmbake::stability_test {

using test::angle_deg;
using test::CliRun;
using test::contains;
using test::decode_rgb;
using test::run_nmbake;

inline Mesh load(const std::string& name, bool uvs = false) {
  LoadOptions lo;
  lo.require_uvs = uvs;
  return load_mesh(test::data_path("stability/" + name), lo);
}
inline Mesh load_low(const std::string& name) { return load(name, true); }

inline BakeOptions options(int size, float distance) {
  BakeOptions o;
  o.width = o.height = size;
  o.padding = 0;
  o.front = o.rear = distance;
  return o;
}

inline long quantize8(float c) { return std::lround(double(c) * 255.0); }

inline void measured(const std::string& key, double value) {
  ::testing::Test::RecordProperty(key, std::to_string(value));
  std::printf("measured: %s = %.6g\n", key.c_str(), value);
}

inline bool all_finite(const Image& img) {
  for (float v : img.pixels)
    if (!std::isfinite(v)) return false;
  return true;
}

// The high-poly's interpolated normal where the ray from `origin` along `dir` first meets it.
struct HighProbe {
  explicit HighProbe(const Mesh& m)
      : mesh(m), pos(m.positions), scene(&pos[0].x, pos.size(), m.position_index.data(), m.triangle_count()) {}
  bool normal_at(const glm::dvec3& origin, const glm::dvec3& dir, float reach, glm::dvec3& n) const {
    const raycast::Hit h = scene.intersect({glm::vec3(origin), 0.0f, glm::vec3(dir), reach});
    if (!h.hit()) return false;
    const double w[3] = {1.0 - double(h.u) - double(h.v), double(h.u), double(h.v)};
    n = glm::dvec3(0.0);
    for (int c = 0; c < 3; ++c) n += w[c] * glm::dvec3(mesh.corner_normal(h.triangle, c));
    n = glm::normalize(n);
    return true;
  }
  const Mesh& mesh;
  std::vector<glm::vec3> pos;
  raycast::Scene scene;
};

// Largest angle (degrees) between two maps' texels, both decoded with the same layout.
inline double max_texel_angle(const BakeResult& a, const BakeResult& b, double* mean = nullptr) {
  double worst = 0.0, sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.coverage.size(); ++i) {
    if (!a.coverage[i] || !b.coverage[i]) continue;
    const double e = angle_deg(decode_rgb(&a.map.pixels[3 * i]), decode_rgb(&b.map.pixels[3 * i]));
    worst = std::max(worst, e);
    sum += e;
    ++n;
  }
  if (mean) *mean = n ? sum / double(n) : 0.0;
  return worst;
}

// Absolute path of a case in data/stability, for run_nmbake's command lines.
inline std::string data(const std::string& name) { return test::data_path("stability/" + name); }

}  // namespace nmbake::stability_test
