// run_parallel: worker(id) on `threads` threads, ids 0 .. threads - 1 (0: the caller's), joined
// before return.
// parallel_chunks: a loop over [0, count) in chunks shared out to `threads` threads (the caller's among them):
// fn(begin, end) for each chunk, in no particular order. threads <= 0: all cores.
// fill_on_threads, mark_on_threads: a large array set on every core (its fresh pages first touched
// there too).
// touch_storage, touch_pages: the fresh pages of large arrays (about to be sized, or left unset),
// first touched on every core.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

#include "core/thread_pool.h"

namespace nmbake {

// What "all cores" (a count <= 0) means in this process: the machine's cores, unless an AllCores
// scope says otherwise (nmbake --threads N: then every stage keeps within N, the file readers and
// the helpers that are given no count among them).
inline std::atomic<int>& all_cores_setting() {
  static std::atomic<int> count{0};  // <= 0: the machine's
  return count;
}

// Within its lifetime, "all cores" means `count` threads (count <= 0: the machine's). Not for
// concurrent jobs with different counts: the setting is the process's.
class AllCores {
 public:
  explicit AllCores(int count) : before_(all_cores_setting().exchange(count > 0 ? count : 0)) {}
  ~AllCores() { all_cores_setting().store(before_); }
  AllCores(const AllCores&) = delete;
  AllCores& operator=(const AllCores&) = delete;

 private:
  int before_;
};

// The worker threads for a requested count: itself when positive, else all cores (at least 1).
inline int worker_threads(int requested) {
  if (requested > 0) return requested;
  const int set = all_cores_setting().load(std::memory_order_relaxed);
  return set > 0 ? set : std::max(1, int(std::thread::hardware_concurrency()));
}

// Runs fn(id) for ids [0, count) on the caller's thread and count - 1 others of the process's pool
// (thread_pool.h), each id on a thread of its own, all ended before return. An exception in any of
// them (std::bad_alloc under a memory limit) is rethrown here once all have ended, not
// std::terminate; ids whose thread could not be started (EAGAIN under ulimit) run on the caller's
// thread.
template <typename Fn>
void run_on_threads(int count, Fn&& fn) {
  if (count <= 1) {
    fn(0);
    return;
  }
  std::exception_ptr error;
  std::mutex error_mutex;
  auto guarded = [&](int id) noexcept {
    try {
      fn(id);
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
    }
  };
  using Guarded = decltype(guarded);
  run_pooled(
      count, [](void* context, int id) noexcept { (*static_cast<Guarded*>(context))(id); }, &guarded);
  if (error) std::rethrow_exception(error);
}

template <typename Fn>
void run_parallel(int threads, Fn&& worker) {
  run_on_threads(threads, worker);
}

template <typename Fn>
void parallel_chunks(int threads, std::size_t count, std::size_t chunk, Fn&& fn) {
  threads = worker_threads(threads);
  std::atomic<std::size_t> next{0};
  run_on_threads(threads, [&](int) {
    for (std::size_t i; (i = next.fetch_add(chunk)) < count;) fn(i, std::min(count, i + chunk));
  });
}

// Every element of `v` set to `value`, in chunks on `threads` threads: a vector left unset as it
// grew (DefaultInitAllocator) is zeroed where its pages are first touched, not on one thread.
template <typename T, typename A>
void fill_on_threads(int threads, std::vector<T, A>& v, const T& value) {
  parallel_chunks(threads, v.size(), std::size_t(1) << 16, [&](std::size_t begin, std::size_t end) {
    std::fill(v.begin() + std::ptrdiff_t(begin), v.begin() + std::ptrdiff_t(end), value);
  });
}

// `marks` (bytes) all 0, then 1 at every value of `index`, on `threads` threads: a mark is only ever
// set to 1 (relaxed atomic stores), so the marks do not depend on which thread set them.
template <typename Index, typename A>
void mark_on_threads(int threads, const Index& index, std::vector<std::uint8_t, A>& marks) {
  fill_on_threads(threads, marks, std::uint8_t(0));
  parallel_chunks(threads, index.size(), std::size_t(1) << 16, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) __atomic_store_n(&marks[index[i]], std::uint8_t(1), __ATOMIC_RELAXED);
  });
}

// Byte ranges whose pages are touched on `threads` threads, a byte written in every 4 KiB, in
// chunks of 2 MiB: the system zeroes a fresh page at its first touch, on the touching thread, so
// that work is shared out (touch_storage, touch_pages).
struct PageRange {
  unsigned char* begin;
  std::size_t bytes;
};
inline void touch_ranges(int threads, const std::vector<PageRange>& ranges) {
  constexpr std::size_t kPage = 4096, kStep = std::size_t(1) << 21;  // bytes per chunk
  std::vector<std::size_t> first(ranges.size() + 1, 0);              // chunks before each range
  for (std::size_t i = 0; i < ranges.size(); ++i) first[i + 1] = first[i] + (ranges[i].bytes + kStep - 1) / kStep;
  parallel_chunks(threads, first.back(), 1, [&](std::size_t c, std::size_t) {
    const std::size_t r = std::size_t(std::upper_bound(first.begin(), first.end(), c) - first.begin()) - 1;
    const std::size_t at = (c - first[r]) * kStep, end = std::min(ranges[r].bytes, at + kStep);
    for (std::size_t b = at; b < end; b += kPage) ranges[r].begin[b] = 0;
  });
}

// Each vector given storage for its count of elements (reserve), and those pages touched on
// `threads` threads (touch_ranges), before the caller sizes them. A large std::vector sized on one
// thread (which value-initializes it there) pays all of the zeroing on that thread; after this, the
// sizing only writes to pages already there. For vectors of trivially copyable elements.
template <typename T, typename A>
struct StorageToTouch {
  std::vector<T, A>* v;
  std::size_t n;
};

// `v` to be sized to `n` (an argument of touch_storage).
template <typename T, typename A>
StorageToTouch<T, A> storage_for(std::vector<T, A>& v, std::size_t n) {
  return {&v, n};
}

template <typename... Vs>
void touch_storage(int threads, Vs... vs) {
  std::vector<PageRange> ranges;
  const auto add = [&](auto s) {
    using T = typename std::remove_reference_t<decltype(*s.v)>::value_type;
    static_assert(std::is_trivially_copyable_v<T>);
    if (s.n <= s.v->capacity()) return;
    s.v->reserve(s.n);
    auto* base = reinterpret_cast<unsigned char*>(s.v->data());
    ranges.push_back({base + s.v->size() * sizeof(T), (s.n - s.v->size()) * sizeof(T)});
  };
  (add(vs), ...);
  touch_ranges(threads, ranges);
}

// The pages of a buffer whose values are not set yet (an Image made Unset) touched on `threads`
// threads (touch_ranges).
inline void touch_pages(int threads, void* data, std::size_t bytes) {
  touch_ranges(threads, {{static_cast<unsigned char*>(data), bytes}});
}

}  // namespace nmbake
