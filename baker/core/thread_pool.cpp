#include "core/thread_pool.h"

#include <pthread.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace nmbake {

namespace {

// One run_pooled call's ids on pooled threads: how many have not ended.
class Batch {
 public:
  explicit Batch(int count) : left_(count) {}

  void finish_one() {
    if (left_.fetch_sub(1, std::memory_order_acq_rel) != 1) return;
    // Notified under the lock: the caller cannot return (and end this object) before it is released.
    const std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
    done_cv_.notify_one();
  }

  void wait() {
    if (left_.load(std::memory_order_acquire) == 0) return;
    std::unique_lock<std::mutex> lock(mutex_);
    done_cv_.wait(lock, [this] { return done_; });
  }

 private:
  std::atomic<int> left_;
  std::mutex mutex_;
  std::condition_variable done_cv_;
  bool done_ = false;
};

struct Job {
  PooledTask task = nullptr;  // null: none waiting
  void* context = nullptr;
  int id = 0;
  Batch* batch = nullptr;
};

// A kept thread and the job it is given.
struct Worker {
  std::mutex mutex;
  std::condition_variable wake;
  Job job;
};

class Pool {
 public:
  // Up to n idle workers, most recently used first (their stacks and caches warmest).
  void take(std::vector<Worker*>& out, int n) {
    const std::lock_guard<std::mutex> lock(mutex_);
    while (n-- > 0 && !idle_.empty()) {
      out.push_back(idle_.back());
      idle_.pop_back();
    }
  }

  void give_back(Worker* w) {
    const std::lock_guard<std::mutex> lock(mutex_);
    idle_.push_back(w);
  }

  // A new worker running `job` first; false when no thread could be started.
  bool start(const Job& job) {
    auto* w = new Worker;
    w->job = job;
    try {
      std::thread(&Pool::serve, this, w).detach();
    } catch (...) {
      delete w;
      return false;
    }
    started_.fetch_add(1, std::memory_order_relaxed);
    return true;
  }

  int started() const { return started_.load(std::memory_order_relaxed); }

 private:
  // A worker's life: its job, then back to the idle list, then the job's batch told; then the
  // next job. Back in the list before the batch hears: the caller's next loop finds it idle.
  void serve(Worker* w) {
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(w->mutex);
        w->wake.wait(lock, [w] { return w->job.task != nullptr; });
        job = w->job;
        w->job.task = nullptr;
      }
      job.task(job.context, job.id);
      give_back(w);
      job.batch->finish_one();
    }
  }

  std::mutex mutex_;
  std::vector<Worker*> idle_;  // workers (never freed: they live as long as the process)
  std::atomic<int> started_{0};
};

std::atomic<Pool*>& pool_slot() {
  static std::atomic<Pool*> slot{nullptr};
  return slot;
}

// The process's pool. A forked child has only the forking thread: its pool starts empty (the
// parent's, whose lists and locks may be mid-use, is left alone).
Pool& pool() {
  static const bool registered = [] {
    ::pthread_atfork(nullptr, nullptr, [] { pool_slot().store(new Pool); });
    pool_slot().store(new Pool);
    return true;
  }();
  (void)registered;
  return *pool_slot().load();
}

}  // namespace

void run_pooled(int count, PooledTask task, void* context) {
  if (count <= 1) {
    task(context, 0);
    return;
  }
  Pool& p = pool();
  Batch batch(count - 1);
  std::vector<Worker*> workers;
  workers.reserve(std::size_t(count - 1));
  p.take(workers, count - 1);
  int id = 1;
  for (Worker* w : workers) {
    {
      const std::lock_guard<std::mutex> lock(w->mutex);
      w->job = {task, context, id++, &batch};
    }
    w->wake.notify_one();
  }
  std::vector<int> here;  // ids no thread could be started for
  for (; id < count; ++id)
    if (!p.start({task, context, id, &batch})) here.push_back(id);
  task(context, 0);
  for (int i : here) {
    task(context, i);
    batch.finish_one();
  }
  batch.wait();
}

int pooled_threads_started() { return pool().started(); }

}  // namespace nmbake
