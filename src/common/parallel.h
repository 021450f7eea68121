// A minimal parallel loop over index ranges on the process's persistent worker threads
// (common/thread_pool.h; no OpenMP), and a work queue on std::threads for uneven tasks.
#pragma once
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "common/progress.h"
#include "common/thread_pool.h"

namespace topopt {

/// Number of worker threads to use: `requested` if > 0; else OMP_NUM_THREADS when it holds a
/// positive number (the usual way to hold a run to n threads: the bench scripts' single-core
/// runs set it to 1); else the CPUs this process may run on (its affinity mask, so `taskset -c 0`
/// gives 1), at most the hardware concurrency. Before, a pinned run still started two threads
/// per parallel loop on its one core (issue 21: thread starts and switches in the profile).
inline int thread_count(int requested) {
  if (requested > 0) return requested;
  if (const char* env = std::getenv("OMP_NUM_THREADS")) {
    const int n = std::atoi(env);
    if (n > 0) return n;
  }
  unsigned hw = std::thread::hardware_concurrency();
  cpu_set_t mask;
  CPU_ZERO(&mask);
  if (sched_getaffinity(0, sizeof(mask), &mask) == 0 && CPU_COUNT(&mask) > 0)
    hw = hw == 0 ? CPU_COUNT(&mask) : std::min<unsigned>(hw, CPU_COUNT(&mask));
  return hw == 0 ? 1 : static_cast<int>(hw);
}

/// Calls fn(begin, end) on `threads` contiguous chunks of [0, n) in parallel, on the calling
/// thread and the workers of shared_pool (at most its workers + 1 chunks); runs fn(0, n) inline
/// when n is small (fewer than 2 * min_chunk), threads == 1, or the pool is taken (another
/// thread's loop, or a loop nested in a chunk). fn must only write to data owned by its range.
/// The first exception a chunk throws is rethrown here.
template <class Fn>
void parallel_for(long n, int threads, Fn&& fn, long min_chunk = 2048) {
  threads = static_cast<int>(std::max<long>(1, std::min<long>(threads, (n + min_chunk - 1) / min_chunk)));
  if (threads <= 1) {
    if (n > 0) fn(0L, n);
    return;
  }
  ThreadPool& pool = shared_pool(threads);
  struct Job {
    Fn& fn;
    long n, chunk;
  } job{fn, n, 0};
  const int parts = std::min(threads, pool.workers() + 1);
  job.chunk = (n + parts - 1) / parts;
  auto part = [](void* context, int i) {
    Job& j = *static_cast<Job*>(context);
    const long b = i * j.chunk, e = std::min(j.n, b + j.chunk);
    if (b < e) j.fn(b, e);
  };
  if (parts <= 1 || !pool.run_parts(parts, part, &job)) fn(0L, n);
}

/// Work queue: calls task(i, progress) for every i of `order` on `threads` threads, each taking
/// the next item when it is done (uneven tasks, e.g. faces or solids largest first). The calling
/// thread works too and gets `progress` itself (its cancellation checked before each item,
/// with `what` in the message); the others get a quiet Progress whose only callback says
/// whether to stop. The first exception stops the queue and is rethrown here.
template <class Task>
void parallel_tasks(const std::vector<int>& order, int threads, const Progress& progress, const char* what,
                    Task&& task) {
  const int n = static_cast<int>(order.size());
  std::atomic<int> next{0};
  std::atomic<bool> stop{false};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  Progress quiet;  // worker threads: no caller callbacks (they may not be thread-safe)
  quiet.cancelled = [&stop] { return stop.load(); };
  auto worker = [&](bool main_thread) {
    try {
      for (int k; !stop.load() && (k = next.fetch_add(1)) < n;) {
        if (main_thread) progress.check_cancel(what);
        task(order[k], main_thread ? progress : quiet);
      }
    } catch (...) {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      stop = true;
    }
  };
  const int count = std::max(1, std::min(threads, n));
  std::vector<std::thread> pool;
  for (int t = 1; t < count; ++t) pool.emplace_back(worker, false);
  worker(true);
  for (auto& th : pool) th.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace topopt
