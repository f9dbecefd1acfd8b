// Tangent frames: known frames on simple layouts, MikkTSpace grouping rules, encode/decode.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/tangent_frames.h"
#include "test_support.h"

using namespace nmbake;

namespace {

void expect_valid_frames(const TangentFrames& f) {
  for (std::size_t c = 0; c < f.normal.size(); ++c) {
    const glm::dvec3 n(f.normal[c]), t(f.tangent[c]);
    ASSERT_TRUE(std::isfinite(n.x) && std::isfinite(t.x) && std::isfinite(f.tangent[c].w)) << "corner " << c;
    EXPECT_NEAR(glm::length(n), 1.0, 1e-6) << "corner " << c;
    EXPECT_NEAR(glm::length(t), 1.0, 1e-6) << "corner " << c;
    EXPECT_NEAR(glm::dot(n, t), 0.0, 1e-6) << "corner " << c;
    EXPECT_EQ(std::abs(f.tangent[c].w), 1.0f) << "corner " << c;
  }
}

}  // namespace

TEST(TangentFrames, PlanarGridHasAxisFrame) {
  const Mesh m = test::make_grid(4, 3);
  const TangentFrames f = compute_tangent_frames(m);
  expect_valid_frames(f);
  for (std::size_t c = 0; c < f.tangent.size(); ++c) {
    EXPECT_NEAR(f.tangent[c].x, 1.0f, 1e-6f);
    EXPECT_EQ(f.tangent[c].w, 1.0f);
  }
  EXPECT_EQ(f.degenerate_uv_triangles, 0u);
}

TEST(TangentFrames, MirroredUVsFlipTheSignOnly) {
  Mesh m = test::make_grid(2, 2);
  for (glm::vec2& uv : m.uvs) uv.x = 1.0f - uv.x;  // mirror u
  const TangentFrames f = compute_tangent_frames(m);
  expect_valid_frames(f);
  for (std::size_t c = 0; c < f.tangent.size(); ++c) {
    EXPECT_NEAR(f.tangent[c].x, -1.0f, 1e-6f);  // +u now runs along -x
    EXPECT_EQ(f.tangent[c].w, -1.0f);           // B = -cross(N, T) = +y: v still runs along +y
  }
}

TEST(TangentFrames, RotatedUVsRotateTheTangent) {
  Mesh m = test::make_grid(2, 2);
  for (glm::vec2& uv : m.uvs) uv = {1.0f - uv.y, uv.x};  // rotate the layout by 90 degrees
  const TangentFrames f = compute_tangent_frames(m);
  expect_valid_frames(f);
  for (std::size_t c = 0; c < f.tangent.size(); ++c) {
    EXPECT_NEAR(f.tangent[c].y, -1.0f, 1e-6f);  // u = 1 - v_old grows towards -y
    EXPECT_EQ(f.tangent[c].w, 1.0f);
  }
}

TEST(TangentFrames, MirroredHalvesDoNotShareTangentsAtTheSeam) {
  // Left half u = x+1 on [-1,0], right half mirrored; the seam vertices have the same position,
  // normal and UV on both sides, so only the orientation keeps the two groups apart.
  Mesh m = test::make_grid(4, 2);
  for (std::size_t i = 0; i < m.positions.size(); ++i) m.uvs[i].x = 1.0f - std::abs(m.positions[i].x);
  const TangentFrames f = compute_tangent_frames(m);
  expect_valid_frames(f);
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    glm::vec3 centre(0.0f);
    for (int c = 0; c < 3; ++c) centre += m.corner_position(t, c) / 3.0f;
    for (int c = 0; c < 3; ++c) {
      const glm::vec4 tg = f.tangent[3 * t + c];
      EXPECT_NEAR(tg.x, centre.x < 0 ? 1.0f : -1.0f, 1e-6f) << "triangle " << t;
      EXPECT_EQ(tg.w, centre.x < 0 ? 1.0f : -1.0f) << "triangle " << t;
    }
  }
}

TEST(TangentFrames, DegenerateTrianglesGiveFiniteFrames) {
  Mesh m = test::make_grid(2, 2);
  // Zero UV area on triangle 0, all three UVs equal on triangle 3, zero 3D area on triangle 5.
  m.uvs.push_back({0.5f, 0.5f});
  const std::uint32_t same = std::uint32_t(m.uvs.size() - 1);
  m.uv_index[0] = m.uv_index[1] = m.uv_index[2] = same;
  m.uvs.push_back({0.1f, 0.1f});
  m.uvs.push_back({0.2f, 0.2f});
  m.uvs.push_back({0.3f, 0.3f});
  m.uv_index[9] = same + 1;
  m.uv_index[10] = same + 2;
  m.uv_index[11] = same + 3;
  m.position_index[16] = m.position_index[15];
  m.position_index[17] = m.position_index[15];
  const TangentFrames f = compute_tangent_frames(m);
  expect_valid_frames(f);
  EXPECT_EQ(f.degenerate_uv_triangles, 2u);
  EXPECT_EQ(f.degenerate_3d_triangles, 1u);
}

TEST(TangentFrames, TorusFramesAreOrthonormalAndFollowU) {
  const Mesh m = test::make_torus(32, 16);
  const TangentFrames f = compute_tangent_frames(m);
  expect_valid_frames(f);
  EXPECT_EQ(f.corners_without_tangent, 0u);
  // u runs around the major circle: the tangent is close to the circle's direction (-sin a, cos a, 0).
  // Not exactly: each triangle's dP/du is a chord half a step (5.6 deg) off the vertex, and the
  // corner angles that weight the chords differ on the two sides of the diagonal split; on the UV
  // seam each side sees only its own chords, so the bound is the half step itself.
  for (std::size_t c = 0; c < f.tangent.size(); ++c) {
    const glm::vec3 p = m.positions[m.position_index[c]];
    const glm::dvec3 dir = glm::normalize(glm::dvec3(-p.y, p.x, 0.0));
    EXPECT_GT(glm::dot(dir, glm::dvec3(f.tangent[c])), std::cos(5.7 * 3.14159265 / 180)) << "corner " << c;
  }
}

TEST(TangentFrames, EncodeIsTheExactInverseOfDecode) {
  std::mt19937 rng(12111);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 2000; ++i) {
    PixelFrame fr{{1.0 + 0.3 * u(rng), 0.3 * u(rng), 0.2 * u(rng)},
                  {0.25 * u(rng), 0.8 + 0.3 * u(rng), 0.2 * u(rng)},
                  {0.2 * u(rng), 0.2 * u(rng), 1.1 + 0.2 * u(rng)}};
    if (i % 2) fr.b = -fr.b;  // a mirrored frame: det < 0
    glm::dvec3 t(u(rng), u(rng), 0.2 + std::abs(u(rng)));
    t = glm::normalize(t);
    // The world direction at any length (the encoding normalizes): from 1e-9 to 1e3.
    const glm::dvec3 world = decode_tangent_normal(fr, t) * std::pow(10.0, -3.0 + 6.0 * u(rng));
    const glm::dvec3 back = encode_tangent_normal(fr, world);
    EXPECT_LT(glm::length(back - t), 1e-12) << "sample " << i;
  }
  // A singular frame falls back to the flat normal instead of NaN.
  const PixelFrame singular{{1, 0, 0}, {1, 0, 0}, {0, 0, 1}};
  const glm::dvec3 flat = encode_tangent_normal(singular, {0, 1, 0});
  EXPECT_EQ(flat, glm::dvec3(0, 0, 1));
}
