#include "pipeline/workers.h"

#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "pipeline/bake.h"

namespace nmbake {

void run_workers(int threads, const std::function<void(int)>& work, std::atomic<bool>& cancel,
                 const std::function<bool(double)>& progress, const std::function<double()>& done) {
  std::mutex done_mutex;
  std::condition_variable done_cv;
  std::exception_ptr error;
  int running = 0;
  auto run = [&](int i) {
    try {
      work(i);
    } catch (...) {
      std::lock_guard<std::mutex> lock(done_mutex);
      if (!error) error = std::current_exception();
      cancel = true;
    }
    std::lock_guard<std::mutex> lock(done_mutex);
    if (--running == 0) done_cv.notify_all();
  };
  std::vector<std::thread> pool;
  try {
    pool.reserve(std::size_t(threads));
    for (int i = 0; i < threads; ++i) {
      {
        std::lock_guard<std::mutex> lock(done_mutex);
        ++running;
      }
      try {
        pool.emplace_back(run, i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(done_mutex);
        --running;
        throw;
      }
    }
  } catch (const std::exception&) {
    if (pool.empty()) {  // not one thread: work here
      ++running;
      run(0);
    }
  }
  if (progress) {
    std::unique_lock<std::mutex> lock(done_mutex);
    while (running > 0 && !cancel.load()) {
      lock.unlock();
      if (!progress(done())) cancel = true;
      lock.lock();
      done_cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return running == 0; });
    }
  }
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  if (cancel) throw Cancelled();
  if (progress) progress(1.0);
}

}  // namespace nmbake
