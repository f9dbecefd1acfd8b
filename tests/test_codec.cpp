// The one codec (core/codec.h) and the one normal rule (core/normals.h) as their users see them.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/codec.h"
#include "core/mesh_topology.h"
#include "core/normals.h"
#include "core/tangent_frames.h"
#include "nmdiff.h"
#include "test_support.h"

using namespace nmbake;

TEST(Codec, TexelsDecodeToUnitVectorsAndNothingBelowTheShortest) {
  // Also a regression test for GCC 12.2's SLP vectorizer (CMakeLists.txt): compiled with it, the
  // floats stored in rgb were read back as the doubles they were rounded from, and decode_texel
  // here disagreed with nmdiff's (compiled elsewhere) in the last bits.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    const glm::dvec3 n = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)));
    float rgb[3];
    for (int c = 0; c < 3; ++c) {
      double ch;
      codec::to_channel(ch, n[c]);
      rgb[c] = float(ch);
    }
    double back[3];
    ASSERT_TRUE(codec::decode_texel(rgb, back));
    EXPECT_NEAR(std::sqrt(back[0] * back[0] + back[1] * back[1] + back[2] * back[2]), 1.0, 1e-12);
    EXPECT_LT(test::angle_deg(glm::dvec3(back[0], back[1], back[2]), n), 1e-4);
    // nmdiff decodes with it: the same bits, green flipped for "down".
    double up[3], down[3];
    ASSERT_TRUE(diff::decode_normal(rgb, diff::GreenAxis::up, up));
    ASSERT_TRUE(diff::decode_normal(rgb, diff::GreenAxis::down, down));
    for (int c = 0; c < 3; ++c) EXPECT_EQ(up[c], back[c]);
    EXPECT_EQ(down[1], -back[1]);
  }
  const float flat_zero[3] = {0.5f, 0.5f, 0.5f};
  double n[3] = {7, 7, 7};
  EXPECT_FALSE(codec::decode_texel(flat_zero, n));
  EXPECT_EQ(n[0], 7.0);  // untouched
  const float nan_texel[3] = {std::nanf(""), 0.5f, 1.0f};
  EXPECT_FALSE(codec::decode_texel(nan_texel, n));
}

TEST(Codec, EncodingInvertsTheRenderersDecoding) {
  // encode_tangent_normal (the codec's steps for one sample) against decode_tangent_normal, in a
  // skewed, mirrored frame.
  PixelFrame f{{1.0, 0.2, 0.0}, {0.1, -1.0, 0.3}, {0.0, 0.1, 1.0}};
  const glm::dvec3 world = glm::normalize(glm::dvec3(0.3, -0.4, 0.8));
  const glm::dvec3 t = encode_tangent_normal(f, world);
  EXPECT_NEAR(glm::length(t), 1.0, 1e-12);
  EXPECT_LT(test::angle_deg(decode_tangent_normal(f, t), world), 1e-9);
  const PixelFrame singular{{1, 0, 0}, {2, 0, 0}, {0, 0, 1}};
  EXPECT_EQ(encode_tangent_normal(singular, world), glm::dvec3(0, 0, 1));
}

TEST(Normals, TheViewerShadesAHighPolyWithoutNormalsAsTheBakeDoes) {
  // ensure_normals (nmview's high-poly) gives the bake's corner normals, a face wound against its
  // neighbours included (compute_high_corner_normals turns it to its piece's winding).
  Mesh m = test::make_torus(12, 8);
  m.normals.clear();
  m.normal_index.clear();
  m.uvs.clear();
  m.uv_index.clear();
  std::swap(m.position_index[3], m.position_index[4]);  // triangle 1 wound the other way
  const std::vector<glm::vec3> bake = compute_high_corner_normals(m);
  Mesh viewer = m;
  ASSERT_TRUE(ensure_normals(viewer));
  ASSERT_EQ(viewer.normal_index.size(), m.position_index.size());
  for (std::size_t c = 0; c < bake.size(); ++c) ASSERT_EQ(viewer.normals[viewer.normal_index[c]], bake[c]) << "corner " << c;
  // The flipped triangle's corners get the normals of the mesh wound consistently.
  Mesh sound = m;
  std::swap(sound.position_index[3], sound.position_index[4]);
  const std::vector<glm::vec3> expect = compute_high_corner_normals(sound);
  for (int c = 0; c < 3; ++c) {
    const std::uint32_t p = m.position_index[3 + std::size_t(c)];
    for (std::size_t k = 0; k < sound.position_index.size(); ++k)
      if (sound.position_index[k] == p) {
        EXPECT_GT(glm::dot(viewer.normals[viewer.normal_index[3 + std::size_t(c)]], expect[k]), 0.9999f);
      }
  }
}
