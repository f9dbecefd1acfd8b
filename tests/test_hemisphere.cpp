// The secondary rays' sampler (core/hemisphere.h): cosine-weighted directions against their known
// moments, the orthonormal basis at every normal (the poles, the plane z = 0, zero and NaN), and
// the counter-based stream against uniformity statistics, the scrambled Sobol points (the
// directions of a texel's chains) against the net property and uniformity over seeds. Statistical checks use fixed keys and
// bounds of 4 standard errors (each about 6e-5 two-sided), chi-square bounds at about 1e-6 a tail.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/hemisphere.h"

using namespace nmbake;

namespace {

// Normals that break simpler constructions: both poles (Frisvad's 2012 basis divides by 1 + n.z),
// next to them, on the plane z = 0 (where the basis switches) with either sign of zero, the axes,
// and some in general position.
std::vector<glm::dvec3> hard_normals() {
  std::vector<glm::dvec3> n = {{0, 0, 1},          {0, 0, -1},          {1, 1, -0.0},       {1, 0, 0},
                               {1, 0, -0.0},       {0, -1, 0},          {-1, 0, 0},         {1e-9, 0, -1},
                               {0, 1e-9, -1},      {1e-20, -1e-20, -1}, {3e-8, 2e-8, 1},    {1, 1e-12, 1e-17},
                               {1, 1e-12, -1e-17}, {0.3, -0.4, 0.866},  {-0.6, 0.1, -0.79}, {0.5, 0.5, -0.5}};
  for (glm::dvec3& v : n) v = glm::normalize(v);
  SampleStream s(12111);
  for (int i = 0; i < 16; ++i) {  // uniform on the sphere
    const double z = 2.0 * s.next() - 1.0, phi = 6.283185307179586 * s.next(), r = std::sqrt(1.0 - z * z);
    n.push_back({r * std::cos(phi), r * std::sin(phi), z});
  }
  return n;
}

}  // namespace

TEST(Hemisphere, BasisIsOrthonormalAndRightHandedEverywhere) {
  for (const glm::dvec3& n0 : hard_normals()) {
    glm::dvec3 t, b, n;
    orthonormal_basis(n0, t, b, n);
    SCOPED_TRACE(testing::Message() << "n = " << n0.x << " " << n0.y << " " << n0.z);
    EXPECT_NEAR(glm::length(t), 1.0, 1e-15);
    EXPECT_NEAR(glm::length(b), 1.0, 1e-15);
    EXPECT_NEAR(glm::dot(t, b), 0.0, 1e-15);
    EXPECT_NEAR(glm::dot(t, n), 0.0, 1e-15);
    EXPECT_NEAR(glm::dot(b, n), 0.0, 1e-15);
    EXPECT_NEAR(glm::length(glm::cross(t, b) - n), 0.0, 1e-15);  // right-handed: t x b = n
    EXPECT_NEAR(glm::length(n - n0), 0.0, 1e-15);
  }
  // Not a direction (zero, NaN, infinite): the basis of +z, no NaN.
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (const glm::dvec3& bad : {glm::dvec3(0.0), glm::dvec3(nan, 0, 1), glm::dvec3(inf, 0, 0)}) {
    glm::dvec3 t, b, n;
    orthonormal_basis(bad, t, b, n);
    EXPECT_EQ(n, glm::dvec3(0, 0, 1));
    EXPECT_EQ(t, glm::dvec3(1, 0, 0));
    EXPECT_EQ(b, glm::dvec3(0, 1, 0));
  }
  // A normal not of unit length is normalised first.
  glm::dvec3 t, b, n;
  orthonormal_basis(glm::dvec3(0, 0, -7), t, b, n);
  EXPECT_EQ(n, glm::dvec3(0, 0, -1));
}

TEST(Hemisphere, BasisIsContinuousWithinEachHalfSpace) {
  // Close normals on one side of z = 0 (near both poles and near the plane): the basis moves by at
  // most a few times as much as the normal (its derivatives are bounded there; Frisvad's would
  // blow up next to (0, 0, -1)).
  SampleStream s(7);
  int pairs = 0;
  for (const glm::dvec3& n0 : hard_normals()) {
    for (int k = 0; k < 64; ++k) {
      const glm::dvec3 jitter(s.next() - 0.5, s.next() - 0.5, s.next() - 0.5);
      const glm::dvec3 n1 = glm::normalize(n0 + 1e-6 * jitter);
      if (std::signbit(n1.z) != std::signbit(n0.z)) continue;
      glm::dvec3 t0, b0, m0, t1, b1, m1;
      orthonormal_basis(n0, t0, b0, m0);
      orthonormal_basis(n1, t1, b1, m1);
      const double dn = glm::length(m1 - m0);
      EXPECT_LE(glm::length(t1 - t0), 4.0 * dn + 1e-15) << n0.x << " " << n0.y << " " << n0.z;
      EXPECT_LE(glm::length(b1 - b0), 4.0 * dn + 1e-15) << n0.x << " " << n0.y << " " << n0.z;
      ++pairs;
    }
  }
  EXPECT_GT(pairs, 1000);
}

TEST(Hemisphere, CosineDirectionsAreUnitAndInTheHemisphere) {
  // The corners of the unit square (u = 0 and u just under 1) and random points, every hard normal.
  const double below_one = 1.0 - 0x1.0p-53;
  std::vector<glm::dvec2> u = {{0, 0}, {0, below_one}, {below_one, 0}, {below_one, below_one}, {0.5, 0.5}, {0.5, 0}, {0, 0.5}};
  SampleStream s(99);
  for (int i = 0; i < 256; ++i) u.push_back(s.next2());
  for (const glm::dvec3& n : hard_normals())
    for (const glm::dvec2& uv : u) {
      const glm::dvec3 d = cosine_direction(n, uv.x, uv.y);
      ASSERT_TRUE(std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z));
      EXPECT_NEAR(glm::length(d), 1.0, 1e-15);
      EXPECT_GE(glm::dot(d, n), -1e-15) << "u = " << uv.x << " " << uv.y;
      // The float version: the same direction rounded.
      const glm::vec3 f = cosine_direction(glm::vec3(n), uv.x, uv.y);
      EXPECT_NEAR(glm::length(f), 1.0f, 1e-6f);
      EXPECT_GE(glm::dot(f, glm::vec3(n)), -1e-6f);
    }
  // The centre of the square is the normal itself; the rim of the disk is grazing.
  EXPECT_NEAR(glm::length(cosine_direction(glm::dvec3(0, 0, -1), 0.5, 0.5) - glm::dvec3(0, 0, -1)), 0.0, 1e-15);
  EXPECT_NEAR(glm::dot(cosine_direction(glm::dvec3(0, 0, -1), 0.0, 0.5), glm::dvec3(0, 0, -1)), 0.0, 1e-15);
  // A normal that is not one: +z's hemisphere, no NaN.
  const glm::dvec3 z = cosine_direction(glm::dvec3(0.0), 0.25, 0.75);
  EXPECT_GE(z.z, 0.0);
  EXPECT_NEAR(glm::length(z), 1.0, 1e-15);
}

TEST(Hemisphere, CosineDirectionsHaveTheKnownMoments) {
  // For density cos(theta) / pi: E[cos] = 2/3, Var[cos] = 1/2 - 4/9 = 1/18, so E[d] = (2/3) n;
  // along each tangent E = 0, Var = E[sin^2] / 2 = 1/4. Each checked within 4 standard errors.
  const int count = 20000;
  for (const glm::dvec3& n : hard_normals()) {
    SCOPED_TRACE(testing::Message() << "n = " << n.x << " " << n.y << " " << n.z);
    SampleStream s(sample_key(std::uint64_t(n.x * 1e6 + 3e6), std::uint64_t(n.z * 1e6 + 3e6), 1));
    glm::dvec3 sum(0.0), sum2(0.0);
    double cos_sum = 0.0, cos2_sum = 0.0;
    glm::dvec3 t, b, nn;
    orthonormal_basis(n, t, b, nn);
    double tan_sum = 0.0, tan2_sum = 0.0;
    for (int i = 0; i < count; ++i) {
      const glm::dvec2 u = s.next2();
      const glm::dvec3 d = cosine_direction(n, u.x, u.y);
      const double c = glm::dot(d, n);
      cos_sum += c;
      cos2_sum += c * c;
      sum += d;
      sum2 += d * d;
      const double x = glm::dot(d, t);
      tan_sum += x;
      tan2_sum += x * x;
    }
    const double mean_cos = cos_sum / count;
    EXPECT_NEAR(mean_cos, 2.0 / 3.0, 4.0 * std::sqrt(1.0 / 18.0 / count));
    EXPECT_NEAR(cos2_sum / count, 0.5, 4.0 * std::sqrt((1.0 / 3.0 - 0.25) / count));  // E[cos^4] = 1/3
    EXPECT_NEAR(tan_sum / count, 0.0, 4.0 * std::sqrt(0.25 / count));
    EXPECT_NEAR(tan2_sum / count, 0.25, 4.0 * std::sqrt((0.125 - 0.0625) / count));  // E[x^4] = 1/8
    // E[direction] = (2/3) n, per world axis, against the sample's own standard error.
    const glm::dvec3 mean = sum / double(count);
    for (int a = 0; a < 3; ++a) {
      const double var = sum2[a] / count - mean[a] * mean[a];
      EXPECT_NEAR(mean[a], 2.0 / 3.0 * n[a], 4.0 * std::sqrt(var / count) + 1e-12) << "axis " << a;
    }
  }
}

TEST(Hemisphere, ConcentricDiskIsUniformInArea) {
  // Equal-area rings and sectors of the disk each get 1/64 of uniform (u1, u2): chi-square with 63
  // degrees of freedom below 132 (upper tail about 1e-6) and above 23 (lower tail about 1e-6).
  const int count = 1 << 18;
  std::vector<int> bins(64, 0);
  SampleStream s(2024);
  for (int i = 0; i < count; ++i) {
    const glm::dvec2 u = s.next2();
    const glm::dvec2 p = concentric_disk(u.x, u.y);
    const double r2 = glm::dot(p, p);
    ASSERT_LE(r2, 1.0 + 1e-15);
    const int ring = std::min(7, int(r2 * 8.0));  // equal areas: r^2 in [k/8, (k+1)/8)
    const double a = std::atan2(p.y, p.x) + 3.141592653589793;
    const int sector = std::min(7, int(a / (2.0 * 3.141592653589793) * 8.0));
    ++bins[std::size_t(ring * 8 + sector)];
  }
  double chi2 = 0.0;
  const double expected = count / 64.0;
  for (int c : bins) chi2 += (c - expected) * (c - expected) / expected;
  EXPECT_LT(chi2, 132.0);
  EXPECT_GT(chi2, 23.0);
}

// sin_cos_quarter against the library within a unit in the last place over the quarter-turn it
// serves, and the concentric map it feeds against the map written with the library's sin and cos
// (Shirley and Chiu's form) within rounding.
TEST(Hemisphere, SinCosQuarterIsWithinAnUlpAndTheDiskMatchesTheLibrarys) {
  SampleStream r(4711);
  constexpr double quarter_pi = 0.78539816339744830962;
  const auto ulps = [](double got, double want) {
    const double ulp = std::nextafter(std::fabs(want), 2.0) - std::fabs(want);
    return std::fabs(got - want) / ulp;
  };
  double worst = 0.0;
  for (int i = 0; i < 200000; ++i) {
    const double t = quarter_pi * (2.0 * r.next() - 1.0);
    double s, c;
    sin_cos_quarter(t, s, c);
    worst = std::max({worst, ulps(s, std::sin(t)), ulps(c, std::cos(t))});
  }
  for (double t : {0.0, -0.0, quarter_pi, -quarter_pi, 1e-300}) {
    double s, c;
    sin_cos_quarter(t, s, c);
    EXPECT_EQ(s, std::sin(t)) << t;
    EXPECT_EQ(c, std::cos(t)) << t;
  }
  EXPECT_LE(worst, 1.0);
  for (int i = 0; i < 100000; ++i) {
    const double u1 = r.next(), u2 = r.next(), a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    const double rad = std::fabs(a) > std::fabs(b) ? a : b;
    const double phi = std::fabs(a) > std::fabs(b) ? quarter_pi * (b / a) : 2.0 * quarter_pi - quarter_pi * (a / b);
    const glm::dvec2 d = concentric_disk(u1, u2);
    EXPECT_NEAR(d.x, rad * std::cos(phi), 1e-15) << u1 << " " << u2;
    EXPECT_NEAR(d.y, rad * std::sin(phi), 1e-15) << u1 << " " << u2;
  }
  EXPECT_EQ(concentric_disk(0.5, 0.5), glm::dvec2(0.0));
}

// The four-at-a-time directions have the one-at-a-time bits: random points, the disk's centre, the
// diagonals where the quarters meet (|a| = |b|), the square's edges, and a count that leaves a tail.
TEST(Hemisphere, CosineDirectionsManyAtOnceHaveTheBitsOfOneAtATime) {
  SampleStream r(99);
  std::vector<double> u1, u2;
  for (int i = 0; i < 4000; ++i) u1.push_back(r.next()), u2.push_back(r.next());
  for (const double e : {0.0, 0.25, 0.5, 0.75, 0.999999}) {
    for (const double f : {0.0, 0.25, 0.5, 0.75, 0.999999}) u1.push_back(e), u2.push_back(f);
  }
  u1.push_back(0.5), u2.push_back(0.5);
  for (const glm::dvec3 axis : {glm::dvec3(0, 0, 1), glm::dvec3(0.3, -0.4, 0.8), glm::dvec3(0, 0, -1), glm::dvec3(-1, 2, 0.01)}) {
    glm::dvec3 t, b, n;
    orthonormal_basis(axis, t, b, n);
    const std::size_t count = u1.size();
    std::vector<float> x(count), y(count), z(count);
    cosine_directions(t, b, n, u1.data(), u2.data(), count, x.data(), y.data(), z.data());
    for (std::size_t i = 0; i < count; ++i) {
      const glm::vec3 d(cosine_direction(t, b, n, u1[i], u2[i]));
      ASSERT_EQ(glm::vec3(x[i], y[i], z[i]), d) << i << " (" << u1[i] << ", " << u2[i] << ")";
    }
  }
}

TEST(SampleStream, EqualKeysGiveEqualStreams) {
  SampleStream a(sample_key(1234, 5, 2)), b(sample_key(1234, 5, 2)), c(sample_key(1234, 6, 2));
  int equal_to_other = 0;
  for (int i = 0; i < 1000; ++i) {
    const double x = a.next();
    ASSERT_EQ(x, b.next()) << "value " << i;  // bit for bit
    equal_to_other += x == c.next();
  }
  EXPECT_EQ(equal_to_other, 0);
  // A copy goes on from where its original was.
  SampleStream d = a;
  EXPECT_EQ(d.next(), a.next());
}

TEST(SampleStream, KeysOfTheBakeAreDistinct) {
  // Every (texel, sample, map) of a 64 x 64 tile, 64 samples, 3 maps: a key of its own.
  std::vector<std::uint64_t> keys;
  for (std::uint64_t map = 0; map < 3; ++map)
    for (std::uint64_t texel = 0; texel < 4096; ++texel)
      for (std::uint64_t sample = 0; sample < 64; ++sample) keys.push_back(sample_key(texel, sample, map));
  std::sort(keys.begin(), keys.end());
  EXPECT_EQ(std::adjacent_find(keys.begin(), keys.end()), keys.end());
}

TEST(SampleStream, ValuesAreUniformInTheHalfOpenUnitInterval) {
  // The largest value the stream can give is below 1.
  EXPECT_LT(double(~std::uint64_t(0) >> 11) * 0x1.0p-53, 1.0);
  // One long stream, and the first values of streams of consecutive keys (as the bake keys them by
  // texel): mean 1/2, variance 1/12 (whose estimate has variance 1/180 per value), chi-square
  // over 64 bins within its 1e-6 tails (23, 132), lag-1 correlation within 4 standard errors.
  const int count = 1 << 20;
  for (int mode = 0; mode < 2; ++mode) {
    SCOPED_TRACE(mode == 0 ? "one stream" : "first values of consecutive keys");
    SampleStream one(42);
    std::vector<int> bins(64, 0);
    double sum = 0.0, sum_sq = 0.0, lag = 0.0, prev = 0.5, lo = 1.0, hi = 0.0;
    for (int i = 0; i < count; ++i) {
      const double x = mode == 0 ? one.next() : SampleStream(std::uint64_t(i)).next();
      lo = std::min(lo, x);
      hi = std::max(hi, x);
      sum += x;
      sum_sq += (x - 0.5) * (x - 0.5);
      lag += (x - 0.5) * (prev - 0.5);
      prev = x;
      ++bins[std::size_t(x * 64.0)];
    }
    EXPECT_GE(lo, 0.0);
    EXPECT_LT(hi, 1.0);
    EXPECT_NEAR(sum / count, 0.5, 4.0 * std::sqrt(1.0 / 12.0 / count));
    EXPECT_NEAR(sum_sq / count, 1.0 / 12.0, 4.0 * std::sqrt(1.0 / 180.0 / count));
    EXPECT_NEAR(lag / count, 0.0, 4.0 * (1.0 / 12.0) / std::sqrt(double(count)));
    double chi2 = 0.0;
    const double expected = count / 64.0;
    for (int c : bins) chi2 += (c - expected) * (c - expected) / expected;
    EXPECT_LT(chi2, 132.0);
    EXPECT_GT(chi2, 23.0);
  }
  // Pairs (as cosine_direction takes them) over 8 x 8 cells: the same chi-square bounds.
  SampleStream s(77);
  std::vector<int> cells(64, 0);
  for (int i = 0; i < count / 2; ++i) {
    const glm::dvec2 u = s.next2();
    ++cells[std::size_t(int(u.x * 8.0) * 8 + int(u.y * 8.0))];
  }
  double chi2 = 0.0;
  const double expected = count / 2 / 64.0;
  for (int c : cells) chi2 += (c - expected) * (c - expected) / expected;
  EXPECT_LT(chi2, 132.0);
  EXPECT_GT(chi2, 23.0);
}

TEST(SampleStream, MixFlipsEachOutputBitWithProbabilityOneHalf) {
  // Avalanche: flipping any one input bit flips each output bit in 1/2 of 4000 random inputs, within
  // 0.05 (6 standard errors; the worst of the 4096 pairs lies near 4).
  const int trials = 4000;
  std::vector<int> flips(64 * 64, 0);
  SampleStream s(5);
  for (int i = 0; i < trials; ++i) {
    const std::uint64_t x = std::uint64_t(s.next() * 0x1.0p53) << 11 ^ std::uint64_t(s.next() * 0x1.0p53);
    const std::uint64_t h = mix64(x);
    for (int in = 0; in < 64; ++in) {
      const std::uint64_t d = h ^ mix64(x ^ (std::uint64_t(1) << in));
      for (int out = 0; out < 64; ++out) flips[std::size_t(in * 64 + out)] += int(d >> out & 1u);
    }
  }
  double worst = 0.0;
  for (int f : flips) worst = std::max(worst, std::fabs(double(f) / trials - 0.5));
  EXPECT_LT(worst, 0.05);
}

// The first 2^m points of a scrambled Sobol set, for every seed: one point in each of the 2^m
// elementary rectangles of every shape 2^-k x 2^-(m-k) (a (0, m, 2)-net), in [0, 1)^2.
TEST(ScrambledSobol, EveryPowerOfTwoPrefixIsANet) {
  for (std::uint64_t seed : {1ull, 77ull, 0x123456789abcdefull})
    for (int m = 0; m <= 10; ++m) {
      const std::uint32_t n = 1u << m;
      std::vector<glm::dvec2> p(n);
      for (std::uint32_t i = 0; i < n; ++i) {
        p[i] = scrambled_sobol2(i, seed);
        ASSERT_TRUE(p[i].x >= 0.0 && p[i].x < 1.0 && p[i].y >= 0.0 && p[i].y < 1.0) << i;
      }
      for (int k = 0; k <= m; ++k) {
        std::vector<int> cells(n, 0);
        for (const glm::dvec2& q : p) ++cells[std::size_t(int(q.x * (1 << k)) * (1 << (m - k)) + int(q.y * (1 << (m - k))))];
        EXPECT_EQ(*std::min_element(cells.begin(), cells.end()), 1) << "seed " << seed << " m " << m << " k " << k;
        EXPECT_EQ(*std::max_element(cells.begin(), cells.end()), 1) << "seed " << seed << " m " << m << " k " << k;
      }
    }
}

// One point over many seeds is uniform: each axis's mean 1/2 and mean square 1/3 (4 standard
// errors of 16384 seeds), x and y uncorrelated, and equal (index, seed) give the same point bit for bit.
TEST(ScrambledSobol, EachPointIsUniformOverSeeds) {
  for (std::uint32_t index : {0u, 1u, 5u, 100u}) {
    const int count = 16384;
    double sx = 0.0, sy = 0.0, sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (int s = 0; s < count; ++s) {
      const glm::dvec2 p = scrambled_sobol2(index, mix64(std::uint64_t(s) + 99));
      ASSERT_EQ(p, scrambled_sobol2(index, mix64(std::uint64_t(s) + 99)));
      sx += p.x, sy += p.y, sxx += p.x * p.x, syy += p.y * p.y, sxy += (p.x - 0.5) * (p.y - 0.5);
    }
    // Standard errors of the mean of x (variance 1/12) and of x^2 (variance 1/5 - 1/9 = 4/45).
    const double se_mean = std::sqrt(1.0 / 12.0 / count), se_sq = std::sqrt(4.0 / 45.0 / count);
    EXPECT_NEAR(sx / count, 0.5, 4 * se_mean) << index;
    EXPECT_NEAR(sy / count, 0.5, 4 * se_mean) << index;
    EXPECT_NEAR(sxx / count, 1.0 / 3.0, 4 * se_sq) << index;
    EXPECT_NEAR(syy / count, 1.0 / 3.0, 4 * se_sq) << index;
    EXPECT_NEAR(sxy / count, 0.0, 4.0 / 12.0 / std::sqrt(double(count))) << index;
  }
}

// Past the depth scrambled exactly (4096 points a chain) points stay distinct.
TEST(ScrambledSobol, LongSetsHaveNoRepeatedPoints) {
  std::vector<std::pair<double, double>> p;
  for (std::uint32_t i = 0; i < (1u << 14); ++i) {
    const glm::dvec2 q = scrambled_sobol2(i, 4242);
    p.emplace_back(q.x, q.y);
  }
  std::sort(p.begin(), p.end());
  EXPECT_EQ(std::adjacent_find(p.begin(), p.end()), p.end());
}

// The points are part of what makes a bake reproducible from one version to the next: these were
// made by the first implementation (three hashes a value); later ones (OwenSeed's depth-0 hash made
// once) must give the same bits, here and through the cached seeds.
TEST(ScrambledSobol, SameBitsAsTheFirstImplementation) {
  struct Known {
    std::uint32_t index;
    double x, y;
  };
  const Known known[] = {{0u, 0x1.a937f64a1afdcp-1, 0x1.0a07b995f1753p-1},
                         {1u, 0x1.e31e6cb4874p-6, 0x1.3290a3d388cf8p-1},
                         {5u, 0x1.aa758ee8b504p-5, 0x1.484cff06804ap-5},
                         {63u, 0x1.6c496d506f9d8p-3, 0x1.bab5de919d8c7p-1},
                         {1000u, 0x1.417cb6222760dp-1, 0x1.e84cf83028873p-1}};
  for (const Known& k : known) {
    const std::uint64_t seed = 0x1234567890abcdefull ^ std::uint64_t(k.index) * 7;
    EXPECT_EQ(scrambled_sobol2(k.index, seed), glm::dvec2(k.x, k.y)) << k.index;
    std::uint64_t sx, sy;
    scramble_seeds(seed, sx, sy);
    EXPECT_EQ(scrambled_sobol2(k.index, owen_seed(sx), owen_seed(sy)), glm::dvec2(k.x, k.y)) << k.index;
  }
}

// scrambled_sobol2_many, four points of several sets at once, gives each point the bits of
// scrambled_sobol2: indices small and large (every bit of the second dimension's loop, lanes that
// end it at different lengths), 0 and 2^32 - 1, chains in any order, counts that leave a tail.
TEST(ScrambledSobol, ManyAtOnceHaveTheBitsOfOneAtATime) {
  SampleStream r(7);
  std::vector<OwenSeed> seeds;
  for (int c = 0; c < 16; ++c) seeds.push_back(owen_seed(std::uint64_t(r.next() * 0x1.0p53) * 2654435761ull));
  std::vector<std::uint32_t> index;
  std::vector<std::uint8_t> chain;
  for (std::uint32_t i = 0; i < 3000; ++i) {
    index.push_back(i % 5 == 0 ? std::uint32_t(r.next() * 4294967296.0) : i % 3 == 0 ? i * 977u : i / 4);
    chain.push_back(std::uint8_t(i % 7 == 0 ? (i / 7) % 8 : i % 8));
  }
  for (std::uint32_t edge : {0u, 1u, 0x80000000u, 0xffffffffu, 4095u, 4096u}) index.push_back(edge), chain.push_back(3);
  for (std::size_t count : {index.size(), std::size_t(3), std::size_t(1), std::size_t(0)}) {
    std::vector<double> u1(count), u2(count);
    scrambled_sobol2_many(index.data(), chain.data(), seeds.data(), count, u1.data(), u2.data());
    for (std::size_t i = 0; i < count; ++i) {
      const glm::dvec2 want = scrambled_sobol2(index[i], seeds[2 * chain[i]], seeds[2 * chain[i] + 1]);
      ASSERT_EQ(glm::dvec2(u1[i], u2[i]), want) << "point " << i << " index " << index[i] << " chain " << int(chain[i]);
    }
  }
}
