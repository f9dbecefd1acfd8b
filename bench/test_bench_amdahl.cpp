// Amdahl's law fitted to a stage's 1- and 2-thread times (amdahl.h): known answers, the clamps for
// noisy timings, and no NaN for missing or degenerate ones.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "amdahl.h"

namespace nmbake::bench {
namespace {

constexpr double kAmdahlTol = 1e-12;

TEST(BenchAmdahl, KnownTimesGiveKnownSerialAndParallelSeconds) {
  // T1 = s + p = 10, T2 = s + p / 2 = 6: s = 2, p = 8; at 16 threads 2 + 0.5.
  const AmdahlFit f = fit_amdahl(10.0, 6.0);
  EXPECT_NEAR(f.serial, 2.0, kAmdahlTol);
  EXPECT_NEAR(f.parallel, 8.0, kAmdahlTol);
  EXPECT_NEAR(f.at(1), 10.0, kAmdahlTol);
  EXPECT_NEAR(f.at(2), 6.0, kAmdahlTol);
  EXPECT_NEAR(f.at(16), 2.5, kAmdahlTol);
  EXPECT_NEAR(amdahl_speedup(f.at(2), f.at(16)), 2.4, kAmdahlTol);
  // The 1M 2048^2 1-sample bake on the Xeon: 1.64 s and 0.99 s give s = 0.34, p = 1.30.
  const AmdahlFit x = fit_amdahl(1.64, 0.99);
  EXPECT_NEAR(x.serial, 0.34, 1e-9);
  EXPECT_NEAR(x.parallel, 1.30, 1e-9);
  EXPECT_NEAR(x.at(16), 0.34 + 1.30 / 16.0, 1e-9);
}

TEST(BenchAmdahl, PerfectScalingAndNoScaling) {
  const AmdahlFit perfect = fit_amdahl(4.0, 2.0);
  EXPECT_NEAR(perfect.serial, 0.0, kAmdahlTol);
  EXPECT_NEAR(perfect.parallel, 4.0, kAmdahlTol);
  EXPECT_NEAR(perfect.at(16), 0.25, kAmdahlTol);
  const AmdahlFit none = fit_amdahl(3.0, 3.0);
  EXPECT_NEAR(none.serial, 3.0, kAmdahlTol);
  EXPECT_NEAR(none.parallel, 0.0, kAmdahlTol);
  EXPECT_NEAR(none.at(16), 3.0, kAmdahlTol);
}

TEST(BenchAmdahl, SlowerAtTwoThreadsClampsToAllSerial) {
  // Noise: 2 threads took longer than 1. All serial, anchored at the 2-thread time.
  const AmdahlFit f = fit_amdahl(1.0, 1.25);
  EXPECT_NEAR(f.serial, 1.25, kAmdahlTol);
  EXPECT_NEAR(f.parallel, 0.0, kAmdahlTol);
  EXPECT_NEAR(f.at(16), 1.25, kAmdahlTol);
  EXPECT_NEAR(amdahl_speedup(f.at(2), f.at(16)), 1.0, kAmdahlTol);
}

TEST(BenchAmdahl, FasterThanHalfClampsToAllParallel) {
  // Better than perfect scaling (noise, or a cache effect): all parallel, from the 2-thread time.
  const AmdahlFit f = fit_amdahl(1.0, 0.4);
  EXPECT_NEAR(f.serial, 0.0, kAmdahlTol);
  EXPECT_NEAR(f.parallel, 0.8, kAmdahlTol);
  EXPECT_NEAR(f.at(2), 0.4, kAmdahlTol);
  EXPECT_NEAR(f.at(16), 0.05, kAmdahlTol);
  EXPECT_NEAR(amdahl_speedup(f.at(2), f.at(16)), 8.0, kAmdahlTol);
}

TEST(BenchAmdahl, MissingOrDegenerateTimesGiveNoNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  const double cases[][2] = {{0.0, 0.0}, {-1.0, -1.0}, {nan, 0.5}, {0.5, nan}, {inf, 1.0}, {1.0, -inf}, {0.0, 0.3}, {0.3, 0.0}};
  for (const auto& c : cases) {
    const AmdahlFit f = fit_amdahl(c[0], c[1]);
    for (const double v : {f.serial, f.parallel, f.at(1), f.at(2), f.at(16), amdahl_speedup(f.at(2), f.at(16))}) {
      EXPECT_TRUE(std::isfinite(v)) << c[0] << " " << c[1];
      EXPECT_GE(v, 0.0) << c[0] << " " << c[1];
    }
    EXPECT_NEAR(f.at(2), f.t2, kAmdahlTol) << c[0] << " " << c[1];  // always anchored at the 2-thread time
    EXPECT_LE(f.serial, f.t2);
  }
  // A stage the report lacks (-1) and one that took nothing: zero seconds, speed-up 1.
  const AmdahlFit missing = fit_amdahl(-1.0, -1.0);
  EXPECT_EQ(missing.at(16), 0.0);
  EXPECT_EQ(amdahl_speedup(missing.at(2), missing.at(16)), 1.0);
  EXPECT_EQ(amdahl_speedup(nan, 1.0), 0.0);
}

TEST(BenchAmdahl, WholeBakeSpeedUpSumsTheStages) {
  // A parallel stage (2 -> 1 s) and a serial one (0.5 s at both): T2 = 1.5, T16 = 0.125 + 0.5.
  const AmdahlFit a = fit_amdahl(2.0, 1.0), b = fit_amdahl(0.5, 0.5);
  EXPECT_NEAR(amdahl_speedup(a.at(2) + b.at(2), a.at(16) + b.at(16)), 1.5 / 0.625, kAmdahlTol);
}

}  // namespace
}  // namespace nmbake::bench
