// CPU time readers: the budgets and the reports count CPU seconds, not wall seconds, so that a
// machine shared with other work slows a stage's clock without stopping or misreporting it.
#pragma once
#include <sys/resource.h>
#include <time.h>

namespace topopt {

/// CPU seconds (user + system) the calling thread has used: for a stage that runs on one
/// thread (the volume fill, OCCT's splitter with SetRunParallel(false)).
inline double thread_cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// CPU seconds (user + system) this process has used, all its threads.
inline double process_cpu_seconds() {
  timespec t{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// CPU seconds (user + system) of this process's ended children that it has waited for (a
/// child of run_isolated once it returned).
inline double children_cpu_seconds() {
  rusage u{};
  ::getrusage(RUSAGE_CHILDREN, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

}  // namespace topopt
