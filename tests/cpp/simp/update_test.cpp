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
    x = oc_update(x, dc, v, VecXd::Constant(n, 0.2), excess);
    ASSERT_LE(std::abs(excess(x)), 1e-6 * target) << "iteration " << it;
    ASSERT_GE(x.minCoeff(), 0.0);
    ASSERT_LE(x.maxCoeff(), 1.0);
  }
  VecXd best = (a.array() / v.array()).sqrt();
  best *= target / v.dot(best);
  ASSERT_LE(best.maxCoeff(), 1.0);  // inside the bounds, so the unconstrained formula holds
  EXPECT_LT((x - best).cwiseAbs().maxCoeff(), 1e-4);
}

TEST(OcUpdate, StartingFromTheLastMultiplierMeetsTheSameVolumeInFewerEvaluations) {
  const int n = 200;
  VecXd v(n), a(n);
  for (int i = 0; i < n; ++i) {
    v[i] = 1.0 + 0.5 * std::cos(0.37 * i);
    a[i] = 1e4 * v[i] * (1.0 + 0.8 * std::sin(0.7 * i));  // a multiplier far from 1e9
  }
  const double target = 0.3 * v.sum();
  int evaluations = 0;
  auto excess = [&](const VecXd& x) {
    ++evaluations;
    return v.dot(x) - target;
  };
  VecXd blind = VecXd::Constant(n, 0.3), warm = blind;
  double multiplier = 0;  // none yet: the first call brackets blind as well
  int blind_evaluations = 0, warm_evaluations = 0;
  for (int it = 0; it < 30; ++it) {
    evaluations = 0;
    blind = oc_update(blind, -a.array() / blind.array().square(), v, VecXd::Constant(n, 0.2), excess);
    blind_evaluations += evaluations;
    evaluations = 0;
    warm = oc_update(warm, -a.array() / warm.array().square(), v, VecXd::Constant(n, 0.2), excess, &multiplier);
    warm_evaluations += evaluations;
    ASSERT_LE(std::abs(excess(warm)), 1e-6 * target) << "iteration " << it;
    ASSERT_GT(multiplier, 0);
  }
  EXPECT_LT((warm - blind).cwiseAbs().maxCoeff(), 1e-5);
  EXPECT_LT(warm_evaluations, 0.75 * blind_evaluations) << warm_evaluations << " vs " << blind_evaluations;
}

TEST(MoveLimits, ShrinkWhereTheDesignOscillatesAndGrowBackWhereItMovesOneWay) {
  // variable 0 zig-zags, variable 1 climbs steadily, variable 2 stands still
  MoveLimits moves(3, 0.2, 0.01, 0.5, 2.0);
  VecXd x(3);
  x << 0.5, 0.1, 0.3;
  EXPECT_EQ(moves.at(x), VecXd::Constant(3, 0.2));  // no history yet
  for (int it = 1; it <= 10; ++it) {
    x[0] = it % 2 ? 0.6 : 0.5;
    x[1] += 0.05;
    const VecXd limit = moves.at(x);
    if (it >= 2) {
      EXPECT_DOUBLE_EQ(limit[0], std::max(0.01, 0.2 * std::pow(0.5, it - 1))) << "iteration " << it;
      EXPECT_DOUBLE_EQ(limit[1], 0.2) << "capped at the largest limit";
      EXPECT_DOUBLE_EQ(limit[2], 0.2) << "a still variable keeps its limit";
    }
  }
  // after a restart the old steps no longer count, but the limits stay where they were
  moves.restart();
  x[0] = 0.9;
  EXPECT_DOUBLE_EQ(moves.at(x)[0], 0.01);
  x[0] = 0.95;
  EXPECT_DOUBLE_EQ(moves.at(x)[0], 0.01);
  x[0] = 1.0;  // two steps the same way: grows again
  EXPECT_DOUBLE_EQ(moves.at(x)[0], 0.02);
}

}  // namespace
}  // namespace topopt::simp
