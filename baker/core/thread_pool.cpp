#include "core/thread_pool.h"

#include <pthread.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <new>
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

  // Until the last id's finish_one has let go of this object (not merely counted down: it may
  // still be about to take the lock).
  void wait() {
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

  void give_back(Worker* w) noexcept {
    const std::lock_guard<std::mutex> lock(mutex_);
    idle_.push_back(w);  // within the room start() made
  }

  // A new worker running `job` first; false when no thread could be started (or no memory was
  // left for one). The idle list's room for it is made first, so that a worker going back to the
  // list never allocates.
  bool start(const Job& job) noexcept {
    Worker* w = nullptr;
    bool counted = false;
    try {
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        idle_.reserve(std::size_t(started_) + 1);
        ++started_;
        counted = true;
      }
      w = new Worker;
      w->job = job;
      std::thread(&Pool::serve, this, w).detach();
    } catch (...) {
      delete w;
      if (counted) {
        const std::lock_guard<std::mutex> lock(mutex_);
        --started_;
      }
      return false;
    }
    return true;
  }

  int started() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return started_;
  }

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
  std::vector<Worker*> idle_;  // workers (never freed: they live as long as the process); room for all
  int started_ = 0;            // threads started, or being started
};

std::atomic<Pool*>& pool_slot() {
  static std::atomic<Pool*> slot{nullptr};
  return slot;
}

// The process's pool (null when there was no memory for one). A forked child has only the forking
// thread: its pool starts empty (the parent's, whose lists and locks may be mid-use, is left alone).
Pool* pool() noexcept {
  static const bool registered = [] {
    ::pthread_atfork(nullptr, nullptr, [] { pool_slot().store(new (std::nothrow) Pool); });
    pool_slot().store(new (std::nothrow) Pool);
    return true;
  }();
  (void)registered;
  return pool_slot().load();
}

}  // namespace

void run_pooled(int count, PooledTask task, void* context) {
  Pool* p = count > 1 ? pool() : nullptr;
  std::vector<Worker*> workers;
  std::vector<int> here;  // ids no thread could be started for
  try {
    // Made before any id is handed out: nothing below allocates or throws.
    if (p) workers.reserve(std::size_t(count - 1)), here.reserve(std::size_t(count - 1));
  } catch (...) {
    p = nullptr;
  }
  if (!p) {  // one id, or no memory: every id here
    for (int id = 0; id < count || id == 0; ++id) task(context, id);
    return;
  }
  Batch batch(count - 1);
  p->take(workers, count - 1);
  int id = 1;
  for (Worker* w : workers) {
    {
      const std::lock_guard<std::mutex> lock(w->mutex);
      w->job = {task, context, id++, &batch};
    }
    w->wake.notify_one();
  }
  for (; id < count; ++id)
    if (!p->start({task, context, id, &batch})) here.push_back(id);
  task(context, 0);
  for (int i : here) {
    task(context, i);
    batch.finish_one();
  }
  batch.wait();
}

int pooled_threads_started() {
  Pool* p = pool();
  return p ? p->started() : 0;
}

}  // namespace nmbake
