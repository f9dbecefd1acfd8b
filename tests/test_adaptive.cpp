// --samples auto (BakeOptions::adaptive): every texel holds either its 4 Gauss-Legendre samples'
// mean or exactly what a fixed bake with BakeOptions::samples gives it; texels refine where their
// samples disagree, and never on a surface baked onto itself; the map does not depend on the
// thread count; the error estimate works with it.
#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "pipeline/bake.h"
#include "pipeline/error_estimate.h"
#include "procedural.h"
#include "test_support.h"

using namespace nmbake;

namespace {

BakeOptions adaptive(int size, double max_error) {
  BakeOptions o;
  o.width = o.height = size;
  o.samples = 16;
  o.adaptive = true;
  o.max_error_deg = max_error;
  o.padding = 0;
  return o;
}

bool same_texel(const Image& a, const Image& b, std::size_t i) {
  return std::memcmp(&a.pixels[3 * i], &b.pixels[3 * i], 12) == 0;
}

// A bumpy high-poly over a flat low-poly: the bumps tilt the normal by up to ~20 degrees, some of
// them sharply (within a texel at 64^2).
struct Bumps {
  Mesh low = test::make_grid(1, 1);
  Mesh high = test::make_height_field(
      256, 256, [](double x, double y) { return 0.02 * std::sin(9.0 * x) * std::sin(7.0 * y) + 0.01 * std::sin(40.0 * x * y); },
      [](double x, double y) {
        const double dx = 0.18 * std::cos(9.0 * x) * std::sin(7.0 * y) + 0.4 * y * std::cos(40.0 * x * y);
        const double dy = 0.14 * std::sin(9.0 * x) * std::cos(7.0 * y) + 0.4 * x * std::cos(40.0 * x * y);
        return glm::normalize(glm::dvec3(-dx, -dy, 1.0));
      });
};

}  // namespace

TEST(Adaptive, EveryTexelIsItsBaseMeanOrTheFixedBakes) {
  const Bumps s;
  BakeOptions fixed = adaptive(64, 1.0);
  fixed.adaptive = false;
  fixed.front = fixed.rear = 0.1f;
  BakeOptions tight = adaptive(64, 0.05), loose = adaptive(64, 90.0);
  tight.front = tight.rear = loose.front = loose.rear = 0.1f;
  const BakeResult f = bake_normal_map(s.low, s.high, nullptr, fixed);
  fixed.samples = 64;
  const BakeResult f64 = bake_normal_map(s.low, s.high, nullptr, fixed);
  const BakeResult t = bake_normal_map(s.low, s.high, nullptr, tight);
  const BakeResult l = bake_normal_map(s.low, s.high, nullptr, loose);
  // The quad covers every texel fully and every ray hits: nothing refines at 90 degrees.
  EXPECT_EQ(l.stats.trace.texels_refined, 0u);
  EXPECT_EQ(l.stats.trace.texels_base, 64u * 64u);
  EXPECT_EQ(l.stats.trace.rays, 4u * 64u * 64u);
  // At 0.05 degrees nearly every texel of the curved field refines, most of them to 64 samples, and
  // then holds the fixed bake's value with as many.
  EXPECT_GT(t.stats.trace.texels_refined + t.stats.trace.texels_deep, 64u * 64u * 9 / 10);
  EXPECT_GT(t.stats.trace.texels_deep, 64u * 64u / 2);
  EXPECT_EQ(t.stats.trace.texels_base + t.stats.trace.texels_refined + t.stats.trace.texels_deep, 64u * 64u);
  EXPECT_EQ(t.stats.trace.rays,
            4u * 64u * 64u + 16u * (t.stats.trace.texels_refined + t.stats.trace.texels_deep) + 64u * t.stats.trace.texels_deep);
  std::size_t as_fixed = 0, as_fixed64 = 0, as_base = 0;
  for (std::size_t i = 0; i < 64u * 64u; ++i) {
    const bool is_fixed = same_texel(t.map, f.map, i), is_fixed64 = same_texel(t.map, f64.map, i),
               is_base = same_texel(t.map, l.map, i);
    EXPECT_TRUE(is_fixed || is_fixed64 || is_base) << "texel " << i;
    as_fixed += is_fixed && !is_base;
    as_fixed64 += is_fixed64 && !is_base && !is_fixed;
    as_base += is_base && !is_fixed && !is_fixed64;
  }
  EXPECT_GE(as_fixed + as_fixed64, 64u * 64u * 8 / 10);
  EXPECT_GE(as_fixed64, t.stats.trace.texels_deep * 9 / 10);
  EXPECT_LE(as_base, 64u * 64u - t.stats.trace.texels_refined - t.stats.trace.texels_deep);
  // The base pass alone (2x2 Gauss-Legendre) is not the fixed bake: the test can tell them apart.
  std::size_t base_differs = 0;
  for (std::size_t i = 0; i < 64u * 64u; ++i) base_differs += !same_texel(l.map, f.map, i);
  EXPECT_GT(base_differs, 64u * 64u / 2);
}

TEST(Adaptive, ASurfaceBakedOntoItselfRefinesOnlyIslandEdges) {
  const Mesh m = test::make_torus(48, 24);
  BakeOptions o = adaptive(128, 0.5);
  o.front = o.rear = 0.05f;
  const BakeResult r = bake_normal_map(m, m, nullptr, o);
  EXPECT_EQ(r.stats.trace.misses, 0u);
  // Interior texels' samples all hit the surface they start on: flat, no disagreement. The texels
  // an island's edge crosses have fewer than 4 base samples and refine.
  std::size_t interior = 0;
  for (std::size_t i = 0; i < r.coverage.size(); ++i) {
    if (!r.coverage[i]) continue;
    const float* c = &r.map.pixels[3 * i];
    EXPECT_NEAR(c[0], 0.5f, 2e-3f);
    EXPECT_NEAR(c[1], 0.5f, 2e-3f);
    ++interior;
  }
  EXPECT_GT(interior, 0u);
  EXPECT_LT(r.stats.trace.texels_refined, r.stats.trace.texels_base / 10);
}

TEST(Adaptive, TheMapDoesNotDependOnTheThreadCount) {
  const Bumps s;
  BakeOptions o = adaptive(96, 1.0);
  o.front = o.rear = 0.1f;
  o.padding = 4;
  o.threads = 1;
  const BakeResult one = bake_normal_map(s.low, s.high, nullptr, o);
  o.threads = 2;
  const BakeResult two = bake_normal_map(s.low, s.high, nullptr, o);
  o.threads = 3;
  const BakeResult three = bake_normal_map(s.low, s.high, nullptr, o);
  EXPECT_TRUE(one.map.pixels == two.map.pixels);
  EXPECT_TRUE(one.map.pixels == three.map.pixels);
  EXPECT_EQ(one.stats.trace.texels_refined, two.stats.trace.texels_refined);
  EXPECT_GT(one.stats.trace.texels_refined, 0u);
  EXPECT_GT(one.stats.trace.texels_base, 0u);
}

TEST(Adaptive, OptionsAreChecked) {
  const Bumps s;
  BakeOptions o = adaptive(16, 1.0);
  o.samples = 8;  // not a square
  EXPECT_THROW(bake_normal_map(s.low, s.high, nullptr, o), UsageError);
  o.samples = 64;
  EXPECT_NO_THROW(bake_normal_map(s.low, s.high, nullptr, o));
  for (double bad : {0.0, -1.0, 91.0, std::nan("")}) {
    o.max_error_deg = bad;
    EXPECT_THROW(bake_normal_map(s.low, s.high, nullptr, o), UsageError) << bad;
  }
}

TEST(Adaptive, TheErrorEstimateMeasuresIt) {
  const Bumps s;
  BakeOptions o = adaptive(64, 1.0);
  o.front = o.rear = 0.1f;
  o.keep_trace = true;
  const BakeResult r = bake_normal_map(s.low, s.high, nullptr, o);
  ErrorEstimateOptions eo;
  eo.bits = 32;
  const ErrorEstimate e = estimate_bake_error(s.low, o, r, eo);
  EXPECT_EQ(e.samples, 256);  // 4x the deepest level's 64
  EXPECT_GT(e.texels, 0u);
  EXPECT_TRUE(std::isfinite(e.mean_deg));
  EXPECT_LT(e.mean_deg, 1.0);
}

TEST(Adaptive, TheCommandTakesSamplesAutoAndReportsTheHistogram) {
  const std::string pair = test::sample_low() + " " + test::sample_high();
  const test::CliRun run =
      test::run_nmbake(pair + " -o m.png --size 64 --samples auto --max-error 2 --estimate-error --report r.json");
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_TRUE(test::contains(run.out, "samples auto (16 at ")) << run.out;
  EXPECT_TRUE(test::contains(run.out, ", 64 at ")) << run.out;
  const nlohmann::json& r = run.report;
  EXPECT_EQ(r["options"]["samples"], "auto");
  EXPECT_EQ(r["options"]["max_error_deg"], 2.0);
  ASSERT_EQ(r["samples_histogram"].size(), 3u);
  EXPECT_EQ(r["samples_histogram"][0]["samples"], 4);
  EXPECT_EQ(r["samples_histogram"][1]["samples"], 16);
  EXPECT_EQ(r["samples_histogram"][2]["samples"], 64);
  const std::uint64_t base = r["samples_histogram"][0]["texels"], refined = r["samples_histogram"][1]["texels"],
                      deep = r["samples_histogram"][2]["texels"];
  EXPECT_EQ(base + refined + deep, r["texels"]["covered"].get<std::uint64_t>());
  // Refined texels cast their first 4 rays too, and the deepest their 16.
  EXPECT_EQ(r["rays"].get<std::uint64_t>(), 4 * base + 20 * refined + 84 * deep);
  EXPECT_TRUE(r.contains("error_estimate"));
  // Below 2048^2 the report says that auto does not pay, and why; from 2048 (either side) that it does.
  EXPECT_EQ(r["samples_auto"]["pays_at_this_size"], false);
  EXPECT_TRUE(test::contains(r["samples_auto"]["why"].get<std::string>(), "below 2048^2"));
  const test::CliRun wide = test::run_nmbake(pair + " -o w.png --size 2048x8 --samples auto --report r.json");
  ASSERT_EQ(wide.code, 0) << wide.err;
  EXPECT_EQ(wide.report["samples_auto"]["pays_at_this_size"], true);
  // A fixed count: one row, every covered texel.
  const test::CliRun fixed = test::run_nmbake(pair + " -o m.png --size 64 --samples 4 --report r.json");
  ASSERT_EQ(fixed.code, 0) << fixed.err;
  ASSERT_EQ(fixed.report["samples_histogram"].size(), 1u);
  EXPECT_EQ(fixed.report["samples_histogram"][0]["texels"], fixed.report["texels"]["covered"]);
  EXPECT_EQ(fixed.report["options"]["samples"], 4);
  EXPECT_FALSE(fixed.report.contains("samples_auto"));
}

TEST(Adaptive, TheCommandRefusesBadSamplingOptions) {
  const std::string pair = test::sample_low() + " " + test::sample_high() + " -o m.png --size 16 ";
  for (const char* bad : {"--samples 4x", "--samples automatic", "--samples ''", "--max-error 2", "--samples 4 --max-error 2",
                          "--samples auto --max-error 0", "--samples auto --max-error 95", "--samples auto --max-error nan"}) {
    const test::CliRun run = test::run_nmbake(pair + bad);
    EXPECT_EQ(run.code, 1) << bad << ": " << run.err;
    EXPECT_TRUE(test::contains(run.err, "--samples") || test::contains(run.err, "--max-error")) << bad << ": " << run.err;
    EXPECT_FALSE(test::exists(run.dir + "/m.png")) << bad;
  }
}
