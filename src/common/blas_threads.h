// Limits the threads of the BLAS that CHOLMOD calls (OpenBLAS on Debian) for a scope.
//
// OpenBLAS's worker threads spin (sched_yield) for a while after every call. Where BLAS is
// used for small, frequent work (the multigrid's coarse solve between sparse products on our
// own threads) they take the cores our threads need; one BLAS thread is then faster. Found at
// run time with dlsym, so any BLAS works (a BLAS without these functions is left alone).
#pragma once
#include <dlfcn.h>

namespace topopt {

class BlasThreadLimit {
 public:
  explicit BlasThreadLimit(int threads) {
    set_ = reinterpret_cast<void (*)(int)>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"));
    auto get = reinterpret_cast<int (*)()>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
    if (set_ && get) {
      previous_ = get();
      if (previous_ != threads) set_(threads);
    } else {
      set_ = nullptr;
    }
    threads_ = threads;
  }
  ~BlasThreadLimit() {
    if (set_ && previous_ != threads_) set_(previous_);
  }
  BlasThreadLimit(const BlasThreadLimit&) = delete;
  BlasThreadLimit& operator=(const BlasThreadLimit&) = delete;

 private:
  void (*set_)(int) = nullptr;
  int previous_ = 0, threads_ = 0;
};

}  // namespace topopt
