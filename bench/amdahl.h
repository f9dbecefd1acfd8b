// Amdahl's law fitted to two timings of one stage, at 1 and 2 threads (issue 38): the stage's
// serial and parallel seconds, and the time it predicts at N threads. Pure arithmetic, header only.
//
// Model: T(n) = s + p / n, s the serial seconds, p the parallel seconds at one thread. From
// T1 = s + p and T2 = s + p / 2: s = 2 T2 - T1, p = 2 (T1 - T2). Timings carry noise, so s is
// clamped to [0, T2] and p is then taken as 2 (T2 - s), which keeps s + p / 2 = T2: the prediction
// always starts from the measured 2-thread time.
//  - T2 >= T1 (no gain, or noise): all serial, s = T2, p = 0;
//  - T2 <= T1 / 2 (as fast as perfect scaling, or better): all parallel, s = 0, p = 2 T2;
//  - otherwise p = T1 - s, as the two equations give.
// Times in seconds; a negative or non-finite input (a stage the report lacks) counts as 0, so no
// result is ever NaN.
#pragma once

#include <algorithm>
#include <cmath>

namespace nmbake::bench {

struct AmdahlFit {
  double t1 = 0.0, t2 = 0.0;  // the timings fitted (after cleaning), seconds
  double serial = 0.0;        // s, seconds
  double parallel = 0.0;      // p, seconds of work that divides over the threads (its 1-thread time)

  // Predicted seconds at `threads` (>= 1) threads: s + p / threads.
  double at(int threads) const { return serial + parallel / double(std::max(1, threads)); }
};

// A timing fit to enter the fit: negative, NaN and infinite values become 0.
inline double amdahl_clean_seconds(double t) { return std::isfinite(t) && t > 0.0 ? t : 0.0; }

inline AmdahlFit fit_amdahl(double t1, double t2) {
  AmdahlFit f;
  f.t1 = amdahl_clean_seconds(t1);
  f.t2 = amdahl_clean_seconds(t2);
  f.serial = std::clamp(2.0 * f.t2 - f.t1, 0.0, f.t2);
  f.parallel = 2.0 * (f.t2 - f.serial);
  return f;
}

// `before` / `after` as a speed-up; 1 when `after` is 0 (nothing left to time), never NaN.
inline double amdahl_speedup(double before, double after) {
  before = amdahl_clean_seconds(before);
  after = amdahl_clean_seconds(after);
  if (after <= 0.0) return 1.0;
  return before / after;
}

}  // namespace nmbake::bench
