// nmdiff_core: known answers for the angular comparison of normal maps, masks, alpha, resampling,
// the convention-mistake warnings and the verdict on the conventions the maps' metadata state.
#include "nmdiff.h"

#include "conventions.h"

#include <cmath>
#include <functional>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "test_support.h"

using nmbake::Image;
namespace diff = nmbake::diff;

namespace {

using nmbake::test::kPi;

struct N3 {
  double x, y, z;
};

N3 normalized(N3 v) {
  const double l = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  return {v.x / l, v.y / l, v.z / l};
}

// A float map with the normal fn(x, y) encoded as n * 0.5 + 0.5.
Image make_map(int w, int h, const std::function<N3(int, int)>& fn, int channels = 3) {
  Image img(w, h, channels, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const N3 n = normalized(fn(x, y));
      float* p = img.at(x, y);
      p[0] = float(n.x * 0.5 + 0.5);
      p[1] = float(n.y * 0.5 + 0.5);
      p[2] = float(n.z * 0.5 + 0.5);
    }
  return img;
}

// Random normals within 60 degrees of +Z, the range real bakes have, from a fixed seed.
Image random_map(int w, int h, unsigned seed = 12111) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g;
  return make_map(w, h, [&](int, int) {
    for (;;) {
      N3 n = normalized({g(rng), g(rng), std::abs(g(rng))});
      if (n.z > 0.5) return n;
    }
  });
}

Image quantized(const Image& img, double levels) {
  Image q = img;
  for (float& v : q.pixels) v = float(std::round(double(v) * levels) / levels);
  return q;
}

// Rotates the normal at texel (x, y) by `deg` about an axis perpendicular to it.
void rotate_texel(Image& img, int x, int y, double deg) {
  float* p = img.at(x, y);
  N3 n = normalized({p[0] * 2.0 - 1, p[1] * 2.0 - 1, p[2] * 2.0 - 1});
  // axis = n x ref, with ref a coordinate axis far from n.
  const N3 ref = std::abs(n.z) < 0.9 ? N3{0, 0, 1} : N3{1, 0, 0};
  const N3 axis = normalized({n.y * ref.z - n.z * ref.y, n.z * ref.x - n.x * ref.z, n.x * ref.y - n.y * ref.x});
  const double c = std::cos(deg * kPi / 180), s = std::sin(deg * kPi / 180);
  // Rodrigues with axis . n = 0: n' = n cos + (axis x n) sin.
  N3 k{axis.y * n.z - axis.z * n.y, axis.z * n.x - axis.x * n.z, axis.x * n.y - axis.y * n.x};
  N3 r{n.x * c + k.x * s, n.y * c + k.y * s, n.z * c + k.z * s};
  p[0] = float(r.x * 0.5 + 0.5);
  p[1] = float(r.y * 0.5 + 0.5);
  p[2] = float(r.z * 0.5 + 0.5);
}

}  // namespace

TEST(Nmdiff, MapAgainstItselfIsZero) {
  const Image a = random_map(32, 16);
  const diff::DiffStats s = diff::compare_normal_maps(a, a);
  EXPECT_EQ(s.texels_compared, 32u * 16u);
  EXPECT_EQ(s.mean_deg, 0.0);
  EXPECT_EQ(s.max_deg, 0.0);
  EXPECT_EQ(s.p99_deg, 0.0);
  EXPECT_TRUE(s.within);
  EXPECT_TRUE(s.warnings.empty());
  EXPECT_EQ(diff::summary_line(s), "mean=0.0000 p99=0.0000 max=0.0000 texels=512 within=1");
}

TEST(Nmdiff, OneTexelRotatedByTenDegrees) {
  const Image a = random_map(8, 8);
  Image b = a;
  rotate_texel(b, 3, 5, 10.0);
  const diff::DiffStats s = diff::compare_normal_maps(a, b);
  // Float encoding of the rotated normal costs ~1e-5 deg.
  EXPECT_NEAR(s.max_deg, 10.0, 1e-3);
  EXPECT_NEAR(s.mean_deg, 10.0 / 64, 1e-4);
  EXPECT_NEAR(s.rms_deg, 10.0 / 8, 1e-3);  // sqrt(100 / 64)
  EXPECT_NEAR(s.p99_deg, 10.0, 1e-3);      // nearest rank: the 64th of 64 values
  EXPECT_EQ(s.p95_deg, 0.0);               // the 61st of 64
  EXPECT_EQ(s.worst_x, 3);
  EXPECT_EQ(s.worst_y, 5);
  EXPECT_DOUBLE_EQ(s.over_5deg, 1.0 / 64);
  EXPECT_DOUBLE_EQ(s.over_1deg, 1.0 / 64);
  EXPECT_FALSE(s.within);  // max 10 > 2
  diff::DiffOptions loose;
  loose.tolerances.max_deg = 10.5;
  loose.tolerances.max_p99_deg = 10.5;
  EXPECT_TRUE(diff::compare_normal_maps(a, b, loose).within);
}

TEST(Nmdiff, PercentilesAreNearestRank) {
  // 100 texels whose differences are 0.05, 0.15, ... 9.95 degrees.
  const Image a = make_map(100, 1, [](int, int) { return N3{0, 0, 1}; });
  Image b = a;
  for (int x = 0; x < 100; ++x) rotate_texel(b, x, 0, 0.1 * x + 0.05);
  const diff::DiffStats s = diff::compare_normal_maps(a, b);
  EXPECT_NEAR(s.p95_deg, 9.45, 1e-3);  // the 95th smallest
  EXPECT_NEAR(s.p99_deg, 9.85, 1e-3);
  EXPECT_NEAR(s.max_deg, 9.95, 1e-3);
  EXPECT_NEAR(s.mean_deg, 5.0, 1e-3);
  EXPECT_DOUBLE_EQ(s.over_1deg, 0.9);
  EXPECT_DOUBLE_EQ(s.over_5deg, 0.5);
  EXPECT_EQ(s.worst_x, 99);
}

TEST(Nmdiff, EightBitRoundingOfAFloatMapIsWithinTheDefaults) {
  const Image a = random_map(256, 256);
  const diff::DiffStats s = diff::compare_normal_maps(quantized(a, 255), a);
  EXPECT_TRUE(s.within) << diff::summary_line(s);
  // The worst case is sqrt(3)/255 rad = 0.389 deg (each decoded component off by <= 1/255).
  EXPECT_LT(s.max_deg, 0.39);
  EXPECT_GT(s.max_deg, 0.3);
  EXPECT_NEAR(s.mean_deg, 0.17, 0.02);
  EXPECT_TRUE(s.warnings.empty());

  // A flat map is off by 0.318 deg in every texel: 128 decodes to 1/255, not 0.
  const Image flat = make_map(16, 16, [](int, int) { return N3{0, 0, 1}; });
  const diff::DiffStats f = diff::compare_normal_maps(quantized(flat, 255), flat);
  EXPECT_NEAR(f.mean_deg, std::atan(std::sqrt(2.0) / 255) * 180 / kPi, 1e-4);
  EXPECT_TRUE(f.within);

  // Two 8-bit roundings of float maps 0.05 deg apart: at most 0.78 deg.
  Image nudged = a;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) rotate_texel(nudged, x, y, 0.05);
  const diff::DiffStats t = diff::compare_normal_maps(quantized(nudged, 255), quantized(a, 255));
  EXPECT_TRUE(t.within) << diff::summary_line(t);
  EXPECT_LT(t.max_deg, 0.8);
}

TEST(Nmdiff, SixteenBitRoundingIsNegligible) {
  const Image a = random_map(64, 64);
  const diff::DiffStats s = diff::compare_normal_maps(quantized(a, 65535), a);
  EXPECT_LT(s.max_deg, 0.39 / 257 * 1.01);
}

TEST(Nmdiff, GreenFlipIsDetectedAndTheConventionOptionUndoesIt) {
  const Image a = random_map(64, 64);
  Image b = a;
  for (int i = 0; i < 64 * 64; ++i) b.pixels[i * 3 + 1] = 1.0f - b.pixels[i * 3 + 1];
  const diff::DiffStats s = diff::compare_normal_maps(a, b);
  EXPECT_FALSE(s.within);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("green flip"), std::string::npos) << s.warnings[0];

  diff::DiffOptions down;
  down.green_b = diff::GreenAxis::down;
  const diff::DiffStats d = diff::compare_normal_maps(a, b, down);
  EXPECT_TRUE(d.within);
  EXPECT_LT(d.max_deg, 1e-3);

  // Still recognised when B was also rounded to 8 bits.
  const diff::DiffStats q = diff::compare_normal_maps(a, quantized(b, 255));
  ASSERT_FALSE(q.warnings.empty());
  EXPECT_NE(q.warnings[0].find("green flip"), std::string::npos);
}

TEST(Nmdiff, RedGreenSwapIsDetected) {
  const Image a = random_map(64, 64);
  Image b = a;
  for (int i = 0; i < 64 * 64; ++i) std::swap(b.pixels[i * 3], b.pixels[i * 3 + 1]);
  const diff::DiffStats s = diff::compare_normal_maps(a, b);
  EXPECT_FALSE(s.within);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("red/green swap"), std::string::npos) << s.warnings[0];
}

TEST(Nmdiff, AnUnrelatedMapGivesNoConventionWarning) {
  const diff::DiffStats s = diff::compare_normal_maps(random_map(64, 64, 1), random_map(64, 64, 2));
  EXPECT_FALSE(s.within);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
}

TEST(Nmdiff, MaskLimitsTheComparedTexelsUnlessPaddingIsIncluded) {
  const Image a = random_map(8, 8);
  Image b = a;
  for (int y = 0; y < 8; ++y) rotate_texel(b, 6, y, 30.0);  // differences only in column 6
  diff::DiffOptions o;
  o.mask.assign(64, 0);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 4; ++x) o.mask[y * 8 + x] = 1;  // left half
  const diff::DiffStats s = diff::compare_normal_maps(a, b, o);
  EXPECT_EQ(s.texels_compared, 32u);
  EXPECT_EQ(s.skipped_mask, 32u);
  EXPECT_TRUE(s.within);

  o.include_padding = true;
  const diff::DiffStats p = diff::compare_normal_maps(a, b, o);
  EXPECT_EQ(p.texels_compared, 64u);
  EXPECT_EQ(p.padding_compared, 32u);
  EXPECT_NEAR(p.max_deg, 30.0, 1e-3);
  EXPECT_EQ(p.worst_x, 6);
  EXPECT_FALSE(p.within);

  o.mask.resize(10);
  EXPECT_THROW(diff::compare_normal_maps(a, b, o), nmbake::InputError);
}

TEST(Nmdiff, UvLayoutMaskUsesTheBakersRasterizer) {
  nmbake::Mesh low = nmbake::test::make_grid(2, 2);
  for (auto& uv : low.uvs) uv.x *= 0.5f;  // the layout covers u in [0, 0.5]
  const std::vector<std::uint8_t> mask = diff::uv_layout_mask(low, 8, 4);
  ASSERT_EQ(mask.size(), 32u);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) EXPECT_EQ(mask[y * 8 + x], x < 4 ? 1 : 0) << x << "," << y;

  nmbake::Mesh no_uvs = low;
  no_uvs.uv_index.clear();
  EXPECT_THROW(diff::uv_layout_mask(no_uvs, 8, 4), nmbake::InputError);
}

TEST(Nmdiff, AlphaIsCoverage) {
  Image a = make_map(
      4, 4,
      [](int x, int) {
        return N3{0.1 * x, 0, 1};
      },
      4);
  Image b = make_map(
      4, 4,
      [](int x, int) {
        return N3{x == 3 ? 0.9 : 0.1 * x, 0, 1};
      },
      4);
  for (int y = 0; y < 4; ++y) b.at(3, y)[3] = 0.0f;  // column 3 differs but is not covered in B
  diff::DiffOptions o;
  const diff::DiffStats s = diff::compare_normal_maps(a, b, o);
  EXPECT_EQ(s.skipped_alpha, 4u);
  EXPECT_EQ(s.texels_compared, 12u);
  EXPECT_TRUE(s.within);
  o.use_alpha = false;
  EXPECT_FALSE(diff::compare_normal_maps(a, b, o).within);
}

TEST(Nmdiff, ZeroVectorsAreCountedNotCompared) {
  const Image a = random_map(4, 4);
  Image b = a;
  float* p = b.at(1, 2);
  p[0] = p[1] = p[2] = 0.5f;  // decodes to (0, 0, 0)
  const diff::DiffStats s = diff::compare_normal_maps(a, b);
  EXPECT_EQ(s.invalid_b, 1u);
  EXPECT_EQ(s.invalid_a, 0u);
  EXPECT_EQ(s.texels_compared, 15u);
  EXPECT_TRUE(s.within);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("zero vector"), std::string::npos);
  EXPECT_FALSE(std::isnan(s.mean_deg));
}

TEST(Nmdiff, NothingComparedIsNotWithin) {
  const Image a = random_map(4, 4);
  diff::DiffOptions o;
  o.mask.assign(16, 0);
  const diff::DiffStats s = diff::compare_normal_maps(a, a, o);
  EXPECT_EQ(s.texels_compared, 0u);
  EXPECT_FALSE(s.within);
  EXPECT_EQ(s.worst_x, -1);
  EXPECT_EQ(s.mean_deg, 0.0);
}

TEST(Nmdiff, MismatchedAndUnusableInputsThrow) {
  const Image a = random_map(8, 8), b = random_map(16, 16);
  EXPECT_THROW(diff::compare_normal_maps(a, b), nmbake::InputError);
  EXPECT_THROW(diff::compare_normal_maps(a, Image(8, 8, 1, 0.5f)), nmbake::InputError);
  EXPECT_THROW(diff::compare_normal_maps(Image(), a), nmbake::InputError);
  try {
    diff::compare_normal_maps(a, b);
  } catch (const nmbake::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("8x8 vs 16x16"), std::string::npos) << e.what();
  }
}

TEST(Nmdiff, ResamplingBringsBOntoAsGrid) {
  // B at twice A's resolution, every 2x2 block one normal of A.
  const Image a = random_map(8, 8);
  Image b(16, 16, 3);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      for (int k = 0; k < 3; ++k) b.at(x, y)[k] = a.at(x / 2, y / 2)[k];
  for (diff::Resample mode : {diff::Resample::nearest, diff::Resample::box}) {
    diff::DiffOptions o;
    o.resample = mode;
    const diff::DiffStats s = diff::compare_normal_maps(a, b, o);
    EXPECT_EQ(s.texels_compared, 64u);
    EXPECT_LT(s.max_deg, 1e-4);
  }
  // Bilinear interpolation of a constant map is exact.
  const Image flat_a = make_map(8, 8, [](int, int) { return N3{0.3, -0.2, 1}; });
  const Image flat_b = make_map(13, 5, [](int, int) { return N3{0.3, -0.2, 1}; });
  diff::DiffOptions o;
  o.resample = diff::Resample::bilinear;
  EXPECT_LT(diff::compare_normal_maps(flat_a, flat_b, o).max_deg, 1e-4);
}

TEST(Nmdiff, HeatmapShowsDifferencesOnARampWithALegend) {
  const Image a = random_map(64, 64);
  Image b = a;
  rotate_texel(b, 10, 20, 4.0);
  diff::DiffOptions o;
  o.mask.assign(64 * 64, 1);
  o.mask[0] = 0;  // texel (0, 0) not compared
  diff::AngleField field;
  const diff::DiffStats s = diff::compare_normal_maps(a, b, o, &field);
  ASSERT_EQ(field.degrees.size(), 64u * 64u);
  EXPECT_EQ(field.degrees[0], -1.0f);
  EXPECT_NEAR(field.degrees[20 * 64 + 10], 4.0, 1e-3);

  const double scale = diff::auto_heatmap_scale(s, o.tolerances);
  EXPECT_DOUBLE_EQ(scale, 2.0);  // max(--max-deg 2, p99 0)
  const Image h = diff::render_heatmap(field, 4.0);
  EXPECT_EQ(h.width, 64);
  EXPECT_GT(h.height, 64 + 4);
  EXPECT_EQ(h.channels, 3);
  auto luma = [](const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; };
  const float* grey = h.at(0, 0);
  EXPECT_EQ(grey[0], grey[1]);
  EXPECT_EQ(grey[1], grey[2]);
  const float* zero = h.at(1, 0);
  const float* hot = h.at(10, 20);
  EXPECT_GT(luma(hot), luma(zero) + 0.5);
  // The legend bar (the first row below the gap that is not black) rises left to right.
  int bar_row = 64;
  while (bar_row < h.height && h.at(0, bar_row)[0] + h.at(0, bar_row)[1] + h.at(0, bar_row)[2] == 0.0f) ++bar_row;
  ASSERT_LT(bar_row, h.height);
  for (int x = 1; x < 64; ++x) EXPECT_GE(luma(h.at(x, bar_row)), luma(h.at(x - 1, bar_row)) - 1e-6) << x;
  EXPECT_NEAR(luma(h.at(63, bar_row)), luma(hot), 1e-6);  // 4 deg = the scale = the bar's right end
}

// Conventions stated differently by the two maps are a difference by default, the maps compared
// as they are (B decoded in A's green); --same-convention decodes each in its own green.
TEST(NmdiffConventions, DifferentGreensAreADifference) {
  const diff::MapConventions up{"up", "tangent", ""}, down{"down", "tangent", ""};
  const diff::ConventionVerdict v = diff::compare_conventions(up, down, false, false);
  EXPECT_EQ(v.differences, std::vector<std::string>{"green"});
  EXPECT_EQ(v.described, "green up against down");
  EXPECT_TRUE(v.green_from_metadata);
  EXPECT_EQ(v.green_a, diff::GreenAxis::up);
  EXPECT_EQ(v.green_b, diff::GreenAxis::up);  // as they are
  EXPECT_FALSE(v.spaces_clash);

  const diff::ConventionVerdict same = diff::compare_conventions(up, down, false, true);
  EXPECT_TRUE(same.differences.empty());
  EXPECT_EQ(same.described, "");
  EXPECT_EQ(same.green_a, diff::GreenAxis::up);
  EXPECT_EQ(same.green_b, diff::GreenAxis::down);  // B's green flipped to compare
}

TEST(NmdiffConventions, AgreeingOrUnstatedConventionsAreNoDifference) {
  const diff::MapConventions down{"down", "tangent", "pixel"}, none{};
  diff::ConventionVerdict v = diff::compare_conventions(down, down, false, false);
  EXPECT_TRUE(v.differences.empty());
  EXPECT_TRUE(v.green_from_metadata);
  EXPECT_EQ(v.green_a, diff::GreenAxis::down);
  EXPECT_EQ(v.green_b, diff::GreenAxis::down);
  v = diff::compare_conventions(down, none, false, false);  // only one map says
  EXPECT_TRUE(v.differences.empty());
  EXPECT_FALSE(v.green_from_metadata);
  v = diff::compare_conventions({"sideways", "", ""}, {"up", "", ""}, false, false);  // not a green
  EXPECT_TRUE(v.differences.empty());
  EXPECT_FALSE(v.green_from_metadata);
}

// Greens given on the command line override the metadata's: no green difference, the other
// conventions still compared.
TEST(NmdiffConventions, GreensGivenOverrideTheMetadata) {
  const diff::ConventionVerdict v =
      diff::compare_conventions({"up", "tangent", "pixel"}, {"down", "tangent", "vertex"}, true, false);
  EXPECT_FALSE(v.green_from_metadata);
  EXPECT_EQ(v.differences, std::vector<std::string>{"bitangent"});
  EXPECT_EQ(v.described, "bitangent pixel against vertex");
}

TEST(NmdiffConventions, SpacesAndBitangents) {
  const diff::MapConventions tangent{"up", "tangent", "pixel"}, object{"down", "object", "vertex"};
  const diff::ConventionVerdict v = diff::compare_conventions(tangent, object, false, false);
  EXPECT_EQ(v.differences, (std::vector<std::string>{"green", "space", "bitangent"}));
  EXPECT_EQ(v.described, "green up against down, space tangent against object, bitangent pixel against vertex");
  EXPECT_FALSE(v.spaces_clash);
  const diff::ConventionVerdict same = diff::compare_conventions(tangent, object, false, true);
  EXPECT_TRUE(same.differences.empty());
  EXPECT_TRUE(same.spaces_clash);  // normals in different frames: refused
}
