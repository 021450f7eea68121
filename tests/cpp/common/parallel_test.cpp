// Tests of common/parallel.h: how many threads a run takes, and the parallel loop's coverage.
#include "common/parallel.h"

#include <gtest/gtest.h>
#include <sched.h>
#include <stdlib.h>

#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>

namespace topopt {
namespace {

/// Sets OMP_NUM_THREADS for the scope of a test and puts the old value back.
class ThreadsVariable {
 public:
  explicit ThreadsVariable(const char* value) {
    if (const char* old = std::getenv("OMP_NUM_THREADS")) had_ = true, old_ = old;
    if (value)
      setenv("OMP_NUM_THREADS", value, 1);
    else
      unsetenv("OMP_NUM_THREADS");
  }
  ~ThreadsVariable() {
    if (had_)
      setenv("OMP_NUM_THREADS", old_.c_str(), 1);
    else
      unsetenv("OMP_NUM_THREADS");
  }

 private:
  bool had_ = false;
  std::string old_;
};

TEST(ThreadCount, AnExplicitRequestWins) {
  ThreadsVariable v("1");
  EXPECT_EQ(thread_count(3), 3);
}

TEST(ThreadCount, FollowsOmpNumThreads) {
  ThreadsVariable v("1");
  EXPECT_EQ(thread_count(0), 1);
  ThreadsVariable w("3");
  EXPECT_EQ(thread_count(0), 3);
}

/// Holds the calling thread to one CPU for the scope of a test and puts its old mask back.
class PinnedTo {
 public:
  explicit PinnedTo(int cpu) {
    ok_ = sched_getaffinity(0, sizeof(old_), &old_) == 0;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(cpu, &one);
    ok_ = ok_ && sched_setaffinity(0, sizeof(one), &one) == 0;
  }
  ~PinnedTo() { sched_setaffinity(0, sizeof(old_), &old_); }
  bool ok() const { return ok_; }

 private:
  cpu_set_t old_;
  bool ok_ = false;
};

TEST(ThreadCount, APinnedRunTakesOneThreadPerCpuOfItsMask) {
  ThreadsVariable v(nullptr);
  cpu_set_t mask;
  CPU_ZERO(&mask);
  ASSERT_EQ(sched_getaffinity(0, sizeof(mask), &mask), 0);
  EXPECT_LE(thread_count(0), CPU_COUNT(&mask));
  int first = 0;
  while (!CPU_ISSET(first, &mask)) ++first;
  PinnedTo pin(first);  // as `taskset -c <first>` would: before, still hardware_concurrency threads
  ASSERT_TRUE(pin.ok());
  EXPECT_EQ(thread_count(0), 1);
}

TEST(ThreadCount, AnUnreadableVariableIsIgnored) {
  ThreadsVariable v("many");
  EXPECT_GE(thread_count(0), 1);
  ThreadsVariable w("0");
  EXPECT_GE(thread_count(0), 1);
}

TEST(ParallelFor, CoversEveryIndexOnce) {
  std::vector<int> hits(10000, 0);
  parallel_for(
      static_cast<long>(hits.size()), 3,
      [&](long b, long e) {
        for (long i = b; i < e; ++i) ++hits[i];
      },
      100);
  for (int h : hits) ASSERT_EQ(h, 1);
}

TEST(ParallelFor, RunsOnTheSamePersistentThreadsEveryCall) {
  // 200 loops at 2 threads: before, 200 new threads; now the caller and the pool's workers only
  std::set<std::thread::id> seen;
  std::mutex m;
  for (int k = 0; k < 200; ++k)
    parallel_for(
        4, 2,
        [&](long, long) {
          std::lock_guard<std::mutex> lock(m);
          seen.insert(std::this_thread::get_id());
        },
        1);
  EXPECT_LE(static_cast<int>(seen.size()), shared_pool(2).workers() + 1);
  EXPECT_GE(shared_pool(2).workers(), 1);
  EXPECT_GE(seen.size(), 2u);  // the chunks did run on a second thread
}

TEST(ParallelFor, RethrowsAChunksException) {
  EXPECT_THROW(parallel_for(
                   1000, 2,
                   [](long b, long) {
                     if (b > 0) throw std::runtime_error("second chunk");
                   },
                   10),
               std::runtime_error);
  std::vector<int> hits(1000, 0);  // the pool still works afterwards
  parallel_for(
      1000, 2,
      [&](long b, long e) {
        for (long i = b; i < e; ++i) ++hits[i];
      },
      10);
  for (int h : hits) ASSERT_EQ(h, 1);
}

TEST(ParallelFor, NestedAndConcurrentLoopsCoverEveryIndexOnce) {
  // a loop inside a chunk, and two threads looping at once: the pool takes one job, the rest
  // runs inline on its caller
  std::vector<int> hits(4 * 1000, 0);
  auto outer = [&](int base) {
    parallel_for(
        2, 2,
        [&](long b, long e) {
          for (long o = b; o < e; ++o)
            parallel_for(
                1000, 2,
                [&](long ib, long ie) {
                  for (long i = ib; i < ie; ++i) ++hits[(base + o) * 1000 + i];
                },
                10);
        },
        1);
  };
  std::thread other(outer, 2);
  outer(0);
  other.join();
  for (int h : hits) ASSERT_EQ(h, 1);
}

}  // namespace
}  // namespace topopt
