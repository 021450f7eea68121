// ThreadPool (see thread_pool.h): one job at a time, workers woken by a generation counter.
#include "common/thread_pool.h"

#include <unistd.h>

#include <algorithm>

#include "common/parallel.h"

namespace topopt {

namespace {

/// Busy-wait rounds (each a CPU pause) before a waiting thread sleeps: about 20-50 us, the
/// gap between two sparse products of a V-cycle on the finest levels.
constexpr int kSpinRounds = 2000;

/// The calling thread is one of some pool's workers (a parallel loop inside a part runs inline).
thread_local bool t_in_pool = false;

inline void cpu_pause() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

/// Spins until pred() holds or the spin budget is spent; returns pred().
template <class Pred>
bool spin_until(Pred pred) {
  for (int k = 0; k < kSpinRounds; ++k) {
    if (pred()) return true;
    cpu_pause();
  }
  return pred();
}

}  // namespace

ThreadPool::ThreadPool(int workers) : owner_(::getpid()) {
  threads_.reserve(std::max(0, workers));
  for (int w = 0; w < workers; ++w) threads_.emplace_back([this, w] { work(w + 1); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
    generation_.fetch_add(1);
  }
  wake_.notify_all();
  for (std::thread& t : threads_) t.join();
}

bool ThreadPool::run_parts(int parts, Part part, void* context) {
  if (t_in_pool || ::getpid() != owner_ || parts - 1 > workers()) return false;
  bool expected = false;
  if (!busy_.compare_exchange_strong(expected, true)) return false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    part_ = part;
    context_ = context;
    parts_ = parts;
    failure_ = nullptr;
    pending_.store(parts - 1);
    generation_.fetch_add(1);
  }
  wake_.notify_all();
  run_one(0);
  if (!spin_until([this] { return pending_.load() == 0; })) {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_.load() == 0; });
  }
  std::exception_ptr failure = failure_;
  busy_.store(false);
  if (failure) std::rethrow_exception(failure);
  return true;
}

void ThreadPool::run_one(int i) {
  try {
    part_(context_, i);
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!failure_) failure_ = std::current_exception();
  }
}

void ThreadPool::work(int index) {
  t_in_pool = true;
  long seen = 0;
  for (;;) {
    if (!spin_until([&] { return generation_.load() != seen; })) {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [&] { return generation_.load() != seen; });
    }
    bool mine = false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      seen = generation_.load();
      if (stop_) return;
      mine = index < parts_;
    }
    if (!mine) continue;
    run_one(index);
    if (pending_.fetch_sub(1) == 1) {
      std::lock_guard<std::mutex> lock(mutex_);  // the caller may be between its check and its wait
      done_.notify_one();
    }
  }
}

ThreadPool& shared_pool(int threads) {
  static ThreadPool pool(std::max(thread_count(0), threads) - 1);
  return pool;
}

}  // namespace topopt
