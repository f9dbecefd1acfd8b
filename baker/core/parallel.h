// worker(id) on `threads` threads, ids 0 .. threads - 1 (0: the caller's), joined before return.
// A loop over [0, count) in chunks shared out to `threads` threads (the caller's among them):
// fn(begin, end) for each chunk, in no particular order. threads <= 0: all cores.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace nmbake {

// The worker threads for a requested count: itself when positive, else all cores (at least 1).
inline int worker_threads(int requested) {
  return requested > 0 ? requested : std::max(1, int(std::thread::hardware_concurrency()));
}

template <typename Fn>
void run_parallel(int threads, Fn&& worker) {
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(worker, i);
  worker(0);
  for (auto& t : pool) t.join();
}

template <typename Fn>
void parallel_chunks(int threads, std::size_t count, std::size_t chunk, Fn&& fn) {
  threads = worker_threads(threads);
  std::atomic<std::size_t> next{0};
  auto work = [&] {
    for (std::size_t i; (i = next.fetch_add(chunk)) < count;) fn(i, std::min(count, i + chunk));
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < threads; ++i) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
}

}  // namespace nmbake
