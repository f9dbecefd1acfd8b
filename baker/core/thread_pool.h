// The process's worker threads, kept from one parallel loop to the next (run_on_threads in
// parallel.h runs on them).
//
// A bake runs some 80 parallel loops. Each made its threads and joined them: on the calling thread,
// one after another, a thread start (clone, a stack, its first pages) and an end per extra thread
// per loop, about 50 us per loop at 2 threads and 130 us at 4 on this VM (and ~15 starts in a row
// per loop at 16 threads, serial work that grows with the thread count). Kept threads are woken
// instead, and their stacks stay mapped and touched.
#pragma once

namespace nmbake {

// A task for run_pooled: called once per id; must not throw (run_on_threads catches for it).
using PooledTask = void (*)(void* context, int id) noexcept;

// task(context, id) for every id in [0, count): 0 on the caller's thread, every other id at once on
// a thread of its own from the pool (idle ones first; new ones, kept after, when too few are idle,
// so a task may itself call run_pooled). Returns when all have ended. Ids whose thread could not
// be started (EAGAIN under a ulimit) run on the caller's thread after its own. After fork, the
// child starts an empty pool of its own.
void run_pooled(int count, PooledTask task, void* context);

// How many threads the pool has started in this process (for tests).
int pooled_threads_started();

}  // namespace nmbake
