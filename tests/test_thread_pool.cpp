// run_on_threads on the process's kept threads (core/thread_pool.h): every id on a thread of its
// own, at once; threads kept from one loop to the next; loops within loops; exceptions after all
// ids end; a forked child with a pool of its own.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "core/parallel.h"
#include "core/thread_pool.h"

using namespace nmbake;

namespace {

// Whether all `count` ids of one run_on_threads call were running at the same time: each waits
// (up to 20 s, so that a broken pool fails rather than hangs) until all have arrived.
bool all_ids_at_once(int count) {
  std::mutex m;
  std::condition_variable cv;
  int arrived = 0;
  std::atomic<int> met{0};
  run_on_threads(count, [&](int) {
    std::unique_lock<std::mutex> lock(m);
    if (++arrived == count) cv.notify_all();
    if (cv.wait_for(lock, std::chrono::seconds(20), [&] { return arrived == count; })) ++met;
  });
  return met == count;
}

}  // namespace

TEST(ThreadPool, EveryIdOnceOnAThreadOfItsOwnAllAtOnce) {
  for (int count : {1, 2, 5, 9}) {
    std::mutex m;
    std::vector<int> seen;
    std::set<std::thread::id> threads;
    run_on_threads(count, [&](int id) {
      std::lock_guard<std::mutex> lock(m);
      seen.push_back(id);
      threads.insert(std::this_thread::get_id());
    });
    std::sort(seen.begin(), seen.end());
    std::vector<int> want(static_cast<std::size_t>(count));
    for (int i = 0; i < count; ++i) want[std::size_t(i)] = i;
    EXPECT_EQ(seen, want) << count << " threads";
    EXPECT_EQ(threads.size(), std::size_t(count)) << count << " threads";
    EXPECT_TRUE(all_ids_at_once(count)) << count << " threads";
  }
}

// Id 0 runs on the caller's thread; the others on kept threads, reused by the next loops.
TEST(ThreadPool, LoopsReuseTheKeptThreads) {
  run_on_threads(6, [](int) {});
  const int started = pooled_threads_started();
  std::set<std::thread::id> threads;
  std::mutex m;
  for (int round = 0; round < 50; ++round)
    run_on_threads(round % 6 + 1, [&](int) {
      std::lock_guard<std::mutex> lock(m);
      threads.insert(std::this_thread::get_id());
    });
  EXPECT_EQ(pooled_threads_started(), started);
  EXPECT_LE(threads.size(), std::size_t(started) + 1);
  std::thread::id caller = std::this_thread::get_id(), zero;
  run_on_threads(3, [&](int id) {
    if (id == 0) zero = std::this_thread::get_id();
  });
  EXPECT_EQ(zero, caller);
}

// A loop's ids may run loops of their own (a file's encoder beside another's, the topology check
// beside the write): each inner loop still gets its ids at once.
TEST(ThreadPool, LoopsWithinLoops) {
  std::atomic<int> inner{0}, at_once{0};
  run_on_threads(3, [&](int) {
    if (all_ids_at_once(4)) ++at_once;
    parallel_chunks(4, 1000, 7, [&](std::size_t begin, std::size_t end) { inner += int(end - begin); });
  });
  EXPECT_EQ(inner.load(), 3000);
  EXPECT_EQ(at_once.load(), 3);
}

// An exception in any id comes out of run_on_threads once every id has ended; the pool goes on.
TEST(ThreadPool, AnExceptionComesOutAfterEveryIdEnded) {
  for (int thrower : {0, 3}) {
    std::atomic<int> ended{0};
    EXPECT_THROW(run_on_threads(5,
                                [&](int id) {
                                  if (id == thrower) throw std::runtime_error("id " + std::to_string(id));
                                  std::this_thread::sleep_for(std::chrono::milliseconds(20));
                                  ++ended;
                                }),
                 std::runtime_error);
    EXPECT_EQ(ended.load(), 4) << "thrower " << thrower;
  }
  std::atomic<int> ran{0};
  run_on_threads(5, [&](int) { ++ran; });
  EXPECT_EQ(ran.load(), 5);
}

// The parent's kept threads do not exist in a forked child: the child's loops start its own.
TEST(ThreadPool, AForkedChildRunsLoopsOnThreadsOfItsOwn) {
  run_on_threads(4, [](int) {});
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::atomic<int> ran{0};
    for (int round = 0; round < 10; ++round) run_on_threads(4, [&](int) { ++ran; });
    ::_exit(ran == 40 && all_ids_at_once(4) ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}
