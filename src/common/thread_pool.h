// A persistent set of worker threads for parallel_for (common/parallel.h): the workers are
// started once and sleep between jobs, so that a parallel loop costs a wake-up, not a thread
// start and join (issue 21: a multigrid solve runs thousands of short parallel sparse products
// per SIMP iteration; starting threads for each doubled the system time at 2 threads).
#pragma once
#include <sys/types.h>

#include <atomic>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace topopt {

/// Worker threads that run the parts of one job at a time. A job is `parts` calls
/// part(context, i), i in [0, parts): part 0 on the calling thread, part i on worker i - 1.
/// The workers spin a few microseconds after a job (a parallel loop is usually followed by
/// another soon), then sleep on a condition variable until the next job or the pool's end.
class ThreadPool {
 public:
  /// The function type of a job's part: part(context, i) runs part i of the job.
  using Part = void (*)(void* context, int i);

  /// Starts `workers` threads (>= 0), sleeping until a job arrives.
  explicit ThreadPool(int workers);

  /// Shuts the pool down: wakes the workers with the stop flag set and joins them. No job can be
  /// running (run_parts returns only when its job is done).
  ~ThreadPool();

  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  /// Number of worker threads (the calling thread of a job comes on top).
  int workers() const { return static_cast<int>(threads_.size()); }

  /// Runs part(context, i) for every i in [0, parts) (parts <= workers() + 1) and returns when
  /// all are done; the first exception a part throws is rethrown here once all have finished.
  /// Returns false, having run nothing, when the pool cannot take the job: another thread's job
  /// is running, the caller is one of the pool's own workers (a nested loop), or the process is
  /// a fork of the one that started the workers (a fork copies only the calling thread). The
  /// caller then runs the job itself.
  bool run_parts(int parts, Part part, void* context);

 private:
  /// A worker's loop: wait for a job with a part for `index`, run it, report it done.
  void work(int index);
  /// Runs part `i` of the current job, keeping the first exception.
  void run_one(int i);

  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_;  // workers: a new job or stop
  std::condition_variable done_;  // caller: the last worker finished
  std::atomic<long> generation_{0};
  std::atomic<int> pending_{0};  // parts on workers not yet finished
  std::atomic<bool> busy_{false};
  bool stop_ = false;
  Part part_ = nullptr;
  void* context_ = nullptr;
  int parts_ = 0;
  std::exception_ptr failure_;
  pid_t owner_;
};

/// The process's pool for parallel loops, started at the first loop that asks for more than
/// one thread, with max(thread_count(0), threads) - 1 workers; later loops use at most that
/// many. It lives until the process exits (a function-local static: its destructor stops and
/// joins the workers at exit; a forked child leaving with _exit never touches it).
ThreadPool& shared_pool(int threads);

}  // namespace topopt
