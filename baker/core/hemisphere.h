// TEMPORARY stand-in (lead's), replaced by the helper's core/hemisphere.h at merge.
#pragma once
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
namespace nmbake {
class SampleStream {
 public:
  explicit SampleStream(std::uint64_t key) : state_(key * 0xD1B54A32D192ED03ull + 0x8BB84B93962EACC9ull) {}
  double next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return double(z >> 11) * (1.0 / 9007199254740992.0);
  }
 private:
  std::uint64_t state_;
};
inline glm::dvec3 cosine_direction(const glm::dvec3& n, double u1, double u2) {
  const double sign = n.z >= 0.0 ? 1.0 : -1.0;
  const double a = -1.0 / (sign + n.z), b = n.x * n.y * a;
  const glm::dvec3 t(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), bt(b, sign + n.y * n.y * a, -n.y);
  const double r = std::sqrt(u1), phi = 6.283185307179586 * u2;
  return r * std::cos(phi) * t + r * std::sin(phi) * bt + std::sqrt(std::max(0.0, 1.0 - u1)) * n;
}
}  // namespace nmbake
