// Optimality criteria on a separable problem whose optimum is known in closed form:
// min Σ a_i / x_i  s.t.  Σ v_i x_i = V*  has x_i ∝ sqrt(a_i / v_i) (OC's fixed point is exact
// for it, so OC must converge there), and the volume is met at every step.
#include "simp/update.h"

#include <gtest/gtest.h>

#include <cmath>

namespace topopt::simp {
namespace {

TEST(OcUpdate, ConvergesToTheAnalyticOptimumOfASeparableProblem) {
  const int n = 300;
  VecXd v(n), a(n);
  for (int i = 0; i < n; ++i) {
    v[i] = 1.0 + 0.5 * std::cos(0.37 * i);
    a[i] = v[i] * (1.0 + 0.8 * std::sin(0.7 * i));
  }
  const double target = 0.4 * v.sum();
  auto excess = [&](const VecXd& x) { return v.dot(x) - target; };
  VecXd x = VecXd::Constant(n, 0.4);
  for (int it = 0; it < 200; ++it) {
    VecXd dc = -a.array() / x.array().square();
    x = oc_update(x, dc, v, 0.2, excess);
    ASSERT_LE(std::abs(excess(x)), 1e-6 * target) << "iteration " << it;
    ASSERT_GE(x.minCoeff(), 0.0);
    ASSERT_LE(x.maxCoeff(), 1.0);
  }
  VecXd best = (a.array() / v.array()).sqrt();
  best *= target / v.dot(best);
  ASSERT_LE(best.maxCoeff(), 1.0);  // inside the bounds, so the unconstrained formula holds
  EXPECT_LT((x - best).cwiseAbs().maxCoeff(), 1e-4);
}

}  // namespace
}  // namespace topopt::simp
