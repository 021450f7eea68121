// A minimal parallel loop over index ranges on std::threads (no OpenMP, no global pool).
#pragma once
#include <algorithm>
#include <thread>
#include <vector>

namespace topopt {

/// Number of worker threads to use: `requested` if > 0, else the hardware concurrency.
inline int thread_count(int requested) {
  if (requested > 0) return requested;
  unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

/// Calls fn(begin, end) on `threads` contiguous chunks of [0, n) in parallel; runs inline
/// when n is small or threads == 1. fn must only write to data owned by its range.
template <class Fn>
void parallel_for(long n, int threads, Fn&& fn, long min_chunk = 2048) {
  threads = static_cast<int>(std::max<long>(1, std::min<long>(threads, (n + min_chunk - 1) / min_chunk)));
  if (threads <= 1) {
    if (n > 0) fn(0L, n);
    return;
  }
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  long chunk = (n + threads - 1) / threads;
  for (int t = 1; t < threads; ++t) {
    long b = t * chunk, e = std::min(n, b + chunk);
    if (b < e) pool.emplace_back([&fn, b, e] { fn(b, e); });
  }
  fn(0L, std::min(n, chunk));
  for (auto& th : pool) th.join();
}

}  // namespace topopt
