// The --estimate-error machinery: the bake's own tracer, over the trace inputs the bake kept, gives
// the bake's texels again bit for bit, and the estimate is ~0 where there is nothing to estimate
// and close to the true error where there is.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/bake.h"
#include "pipeline/error_estimate.h"
#include "test_support.h"

using namespace nmbake;
using test::angle_deg;
using test::decode_rgb;

namespace {

using nmbake::test::kPi;

BakeOptions estimate_options(int size, int samples) {
  BakeOptions o;
  o.width = o.height = size;
  o.samples = samples;
  o.padding = 0;
  o.keep_trace = true;
  return o;
}

// z = 0.005 sin(42 pi x) sin(42 pi y) over [-1,1]^2: 42 waves across, 3 texels per wave at 128^2,
// slopes up to 33 deg. A 1-sample bake aliases it badly.
Mesh aliasing_height_field() {
  const double a = 0.005, w = 42 * kPi;
  return test::make_height_field(
      504, 504, [&](double x, double y) { return a * std::sin(w * x) * std::sin(w * y); },
      [&](double x, double y) {
        return glm::normalize(
            glm::dvec3(-a * w * std::cos(w * x) * std::sin(w * y), -a * w * std::sin(w * x) * std::cos(w * y), 1.0));
      });
}

}  // namespace

// What the estimate's re-bake gives a texel at the bake's own samples is the bake's texel, bit for
// bit: one tracer, one BVH. With a fixed distance, two rays per sample, --green down, the automatic
// cage, object space.
TEST(ErrorEstimate, TheBakesTracerGivesItsTexelsAgain) {
  const Mesh low = test::make_torus(24, 12);
  const Mesh high = test::make_torus(96, 48, 1.0f, 0.37f);
  for (int variant = 0; variant < 5; ++variant) {
    BakeOptions o = estimate_options(96, variant == 1 || variant == 3 ? 1 : 4);
    if (variant != 3) o.front = o.rear = 0.1f;
    if (variant == 1) o.policy = RayPolicy::closest;
    if (variant == 2) o.green_down = true;
    if (variant == 4) o.space = NormalSpace::object;
    const BakeResult r = bake_normal_map(low, high, nullptr, o);
    ASSERT_TRUE(r.trace_inputs);
    EXPECT_EQ(r.stats.distances.cage == BakeStats::CageSource::automatic, variant == 3);
    std::size_t covered = 0;
    EXPECT_EQ(test::texels_traced_otherwise(low, *r.trace_inputs, o, r, &covered), 0u) << "variant " << variant;
    EXPECT_GT(covered, 4000u);
  }
}

// The kept inputs read the high-poly (its triangles' objects, and with no triangle culled its
// index buffer): one moved to the low-poly's origin for the bake is kept with them.
TEST(ErrorEstimate, AHighPolyMovedForTheBakeIsKeptWithItsTrace) {
  const Mesh low = test::make_torus(24, 12);
  Mesh high = with_origin(test::make_torus(96, 48, 1.0f, 0.37f), glm::dvec3(0.5, 0.25, 0.0));
  high.objects = {{"inner", ""}, {"outer", ""}};
  for (std::size_t t = 0; t < high.triangle_count(); ++t) high.triangle_object.push_back(std::uint32_t(t % 2));
  BakeOptions o = estimate_options(64, 1);
  o.front = o.rear = 0.1f;
  o.cull_far = false;
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  // The memory the bake freed taken again and overwritten.
  std::vector<std::vector<std::uint32_t>> clobber;
  for (std::size_t n : {high.triangle_count(), 3 * high.triangle_count()})
    for (int k = 0; k < 32; ++k) clobber.emplace_back(n, 0xffffffffu);
  std::size_t covered = 0;
  EXPECT_EQ(test::texels_traced_otherwise(low, *r.trace_inputs, o, r, &covered), 0u);
  EXPECT_GT(covered, 2000u);
  EXPECT_EQ(r.stats.trace.misses, 0u);
  EXPECT_EQ(clobber.back().back(), 0xffffffffu);
}

TEST(ErrorEstimate, OnlyABakeThatKeptItsTraceIsEstimated) {
  const Mesh m = test::make_torus(32, 16);
  BakeOptions o = estimate_options(32, 1);
  o.keep_trace = false;
  const BakeResult r = bake_normal_map(m, m, nullptr, o);
  EXPECT_FALSE(r.trace_inputs);
  EXPECT_THROW(estimate_bake_error(m, o, r), std::invalid_argument);
}

TEST(ErrorEstimate, SelfBakeEstimatesZero) {
  const Mesh m = test::make_torus(64, 32);
  BakeOptions o = estimate_options(128, 1);
  o.front = o.rear = 0.05f;
  const BakeResult r = bake_normal_map(m, m, nullptr, o);
  ErrorEstimateOptions eo;
  eo.bits = 8;
  const ErrorEstimate e = estimate_bake_error(m, o, r, eo);
  EXPECT_EQ(e.texels, 4096u);
  EXPECT_EQ(e.samples, 64);
  EXPECT_LT(e.max_deg, 1e-3);
  // Flat rounds to (128,128,255), and 128/255 decodes to 0.0039, not 0: 8-bit output is 0.32 deg
  // off even for a flat map (atan(sqrt(2) * 1/255)).
  EXPECT_NEAR(e.quantization_max_deg, std::atan(std::sqrt(2.0) / 255.0) * 180.0 / kPi, 1e-3);
  EXPECT_NEAR(e.quantization_mean_deg, e.quantization_max_deg, 1e-9);
}

TEST(ErrorEstimate, AliasedBakeEstimateIsCloseToTheTrueError) {
  const Mesh high = aliasing_height_field();
  const Mesh low = test::make_grid(1, 1);
  BakeOptions o = estimate_options(128, 1);
  o.front = o.rear = 0.01f;
  const BakeResult r = bake_normal_map(low, high, nullptr, o);
  // True error: every texel against a full 64-sample bake.
  BakeOptions ref_o = o;
  ref_o.samples = 64;
  ref_o.keep_trace = false;
  const BakeResult ref = bake_normal_map(low, high, nullptr, ref_o);
  std::vector<double> err;
  for (std::size_t i = 0; i < r.coverage.size(); ++i)
    err.push_back(angle_deg(decode_rgb(&r.map.pixels[3 * i]), decode_rgb(&ref.map.pixels[3 * i])));
  double mean = 0.0;
  for (double e : err) mean += e / double(err.size());
  std::sort(err.begin(), err.end());
  const double p95 = err[std::size_t(0.95 * double(err.size() - 1) + 0.5)];

  const ErrorEstimate e = estimate_bake_error(low, o, r);
  std::printf(
      "aliased 128^2, 1 sample: true mean %.3f p95 %.3f max %.3f deg; estimate mean %.3f p95 %.3f max %.3f deg on %zu texels, "
      "%.3f s\n",
      mean, p95, err.back(), e.mean_deg, e.p95_deg, e.max_deg, e.texels, e.seconds);
  EXPECT_EQ(e.texels, 4096u);  // a quarter of the map
  EXPECT_GT(mean, 1.0);
  EXPECT_NEAR(e.mean_deg, mean, 0.05 * mean);
  EXPECT_NEAR(e.p95_deg, p95, 0.1 * p95);
  EXPECT_LE(e.max_deg, err.back() + 1e-6);
}
