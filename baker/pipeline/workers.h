// The trace's workers: `threads` threads running one function each while the calling thread
// reports progress. Internal to the pipeline (trace.cpp).
#pragma once

#include <atomic>
#include <functional>

namespace nmbake {

// Runs work(0) ... work(threads - 1) on their own threads. With `progress`, the calling thread
// calls it every 100 ms with done() (a fraction in [0,1]) until the workers end; false sets
// `cancel`. The last worker to finish wakes the wait at once, so the stage does not end up to
// 100 ms after its work. The first exception of a worker (std::bad_alloc under ulimit -v) sets
// `cancel` (the workers are to stop when it is set) and is rethrown here; a thread the system
// refuses (EAGAIN) leaves the work to those started, or, when none is, to work(0) on this thread.
// Throws Cancelled when `cancel` ends up set; else reports 1.0 to `progress`.
void run_workers(int threads, const std::function<void(int)>& work, std::atomic<bool>& cancel,
                 const std::function<bool(double)>& progress, const std::function<double()>& done);

}  // namespace nmbake
