#include "hard_asset_surfaces.h"

#include <array>
#include <cassert>
#include <cmath>
#include <cstddef>

namespace nmbake::procedural::detail {
namespace {

// Bisects [a, b] (g(a) = ga and g(b) of opposite signs) to 1e-13 relative.
double bisect(const Patch& f, const glm::dvec3& p, const glm::dvec3& dir, double a, double ga, double b) {
  for (int it = 0; it < 200 && std::abs(b - a) > 1e-15 + 1e-13 * std::abs(a); ++it) {
    const double m = 0.5 * (a + b), gm = f.implicit(p + m * dir);
    if (gm == 0) return m;
    if ((gm < 0) == (ga < 0)) a = m, ga = gm;
    else b = m;
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
        if (best.crossed &&
            !(tie ? std::abs(glm::dot(n, dir)) > std::abs(glm::dot(best.normal, dir)) : std::abs(s) < std::abs(best.s)))
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

}  // namespace

void attach_surfaces(HardAsset& asset, std::vector<Part> parts, double max_s) {
  auto shared = std::make_shared<const std::vector<Part>>(std::move(parts));
  asset.max_s = max_s;
  asset.locate = [shared, max_s](const glm::dvec3& p, const glm::dvec3& dir, int part) {
    assert(part >= 0 && std::size_t(part) < shared->size());
    return locate_on((*shared)[std::size_t(part)], p, dir, max_s);
  };
  auto locate = asset.locate;
  asset.expected_normal = [locate](const glm::dvec3& p, const glm::dvec3& dir, int part) { return locate(p, dir, part).normal; };
}

}  // namespace nmbake::procedural::detail
