// A vector of values drawn uniformly from [lo, hi) with a fixed seed: the random designs and
// fields the gradient tests start from.
#pragma once
#include <random>

#include "common/types.h"

namespace topopt::testing {

inline VecXd uniform_vector(long n, unsigned seed, double lo, double hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  VecXd x(n);
  for (long i = 0; i < n; ++i) x[i] = u(rng);
  return x;
}

}  // namespace topopt::testing
