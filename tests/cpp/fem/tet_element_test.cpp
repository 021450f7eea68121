// The element kernels of fem/tet_element.h: the upper-triangle stiffness that assembly uses
// against the full 12 by 12 one.
#include "fem/tet_element.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace topopt::fem {
namespace {

TEST(TetElement, UpperTriangleIsTheFullStiffnessToTheBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 50; ++trial) {
    double g[12];
    for (double& v : g) v = u(rng);
    const double vol = 0.1 + std::abs(u(rng)), lambda = 1e5 * (1 + std::abs(u(rng))), mu = 8e4;
    double full[144], upper[78];
    element_stiffness(g, vol, lambda, mu, full);
    element_stiffness_upper(g, vol, lambda, mu, upper);
    int k = 0;
    for (int i = 0; i < 12; ++i)
      for (int j = i; j < 12; ++j, ++k) ASSERT_EQ(upper[k], full[12 * i + j]) << "entry " << i << ", " << j;
    ASSERT_EQ(k, 78);
  }
}

}  // namespace
}  // namespace topopt::fem
