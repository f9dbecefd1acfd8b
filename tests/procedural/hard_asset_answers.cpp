#include "hard_asset_answers.h"

#include <algorithm>
#include <cmath>

#include "core/rasterize.h"
#include "core/tangent_frames.h"
#include "core/parallel.h"

namespace nmbake::procedural {

namespace {

double angle_deg(const glm::dvec3& a, const glm::dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b)) * (180.0 / 3.14159265358979323846);
}

}  // namespace

glm::dvec3 known_normal(const HardAsset& a, const glm::dvec3& p, const glm::dvec3& dir, int part) {
  SurfacePoint sp = a.locate(p, dir, part);
  if (sp.crossed && glm::dot(sp.normal, dir) < 0.0) {
    const SurfacePoint other = a.locate(p - 2.0 * sp.s * dir, dir, part);
    if (other.crossed && glm::dot(other.normal, dir) > 0.0) sp = other;
  }
  return sp.normal;
}

std::vector<KnownTexel> known_texels(const HardAsset& a, int size) {
  const std::vector<glm::vec3> ray_n = low_ray_normals(a.low);
  const std::vector<std::int32_t> owner = rasterize_texel_triangles(a.low, size, size);
  std::vector<KnownTexel> out;
  for (std::size_t i = 0; i < owner.size(); ++i)
    if (owner[i] >= 0)
      out.push_back({std::uint32_t(i), std::uint32_t(owner[i]), {0, 0, 0}, a.low_part[std::size_t(owner[i])], {}});
  std::vector<std::uint8_t> keep(out.size(), 0);
  parallel_chunks(0, out.size(), 512, [&](std::size_t k0, std::size_t k1) {
    for (std::size_t k = k0; k < k1; ++k) {
      KnownTexel& kt = out[k];
      const std::size_t t = kt.tri;
      const int x = int(kt.texel % std::uint32_t(size)), y = int(kt.texel / std::uint32_t(size));
      const TexelTriangle tri =
          setup_texel_triangle(a.low.corner_uv(t, 0), a.low.corner_uv(t, 1), a.low.corner_uv(t, 2), size, size);
      if (!covers(tri, sample_point(x, y, 0.5, 0.5), kt.b)) continue;
      glm::dvec3 p(0.0), dir(0.0);
      for (int c = 0; c < 3; ++c) {
        p += kt.b[c] * glm::dvec3(a.low.corner_position(t, c));
        dir += kt.b[c] * glm::dvec3(ray_n[a.low.position_index[3 * t + c]]);
      }
      kt.normal = known_normal(a, p, glm::normalize(dir), kt.part);
      keep[k] = 1;
    }
  });
  std::size_t n = 0;
  for (std::size_t k = 0; k < out.size(); ++k)
    if (keep[k]) out[n++] = out[k];
  out.resize(n);
  return out;
}

KnownErrors measure_against_known(const HardAsset& a, const std::vector<KnownTexel>& known, const BakeResult& r,
                                  const std::vector<int>& parts) {
  const TangentFrames frames = compute_tangent_frames(a.low);
  std::vector<float> err(known.size(), -1.0f);
  parallel_chunks(0, known.size(), 4096, [&](std::size_t k0, std::size_t k1) {
    for (std::size_t k = k0; k < k1; ++k) {
      const KnownTexel& kt = known[k];
      if (!r.coverage[kt.texel]) continue;
      if (!parts.empty() && std::find(parts.begin(), parts.end(), kt.part) == parts.end()) continue;
      const float* c = &r.map.pixels[3 * std::size_t(kt.texel)];
      const glm::dvec3 t(codec::from_channel(c[0]), codec::from_channel(c[1]), codec::from_channel(c[2]));
      const glm::dvec3 world = decode_tangent_normal(interpolate_frame(frames, kt.tri, kt.b), t);
      err[k] = float(angle_deg(world, kt.normal));
    }
  });
  KnownErrors e;
  std::size_t over1 = 0;
  for (float v : err) {
    if (v < 0.0f) continue;
    e.mean_deg += v;
    over1 += v > 1.0f;
    e.over60_texels += v > 60.0f;
    e.other_surface += v > 120.0f;
    e.worst_deg = std::max(e.worst_deg, double(v));
    ++e.texels;
  }
  if (e.texels) {
    e.mean_deg /= double(e.texels);
    e.over1 = double(over1) / double(e.texels);
    e.over60 = double(e.over60_texels) / double(e.texels);
  }
  return e;
}

}  // namespace nmbake::procedural
