// Seconds of wall time for the stats and reports, on the steady clock (never jumps with the system
// time).
#pragma once

#include <chrono>

namespace nmbake {

// Seconds since `t0`, a std::chrono::steady_clock::now() taken earlier.
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace nmbake
