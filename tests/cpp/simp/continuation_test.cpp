// The β continuation: β rises only once the design has settled (or after the cap of
// iterations at one β), by the factor, up to beta_max; convergence is declared at beta_max
// only; without projection β stays 1 and the plain convergence test applies.
#include "simp/continuation.h"

#include <gtest/gtest.h>

namespace topopt::simp {
namespace {

ProjectionParams schedule(double beta_max = 8) {
  ProjectionParams p;
  p.beta_start = 1;
  p.beta_max = beta_max;
  p.beta_factor = 2;
  p.max_iterations_per_beta = 30;
  p.settle_tolerance = 1e-2;
  p.settle_iterations = 3;
  return p;
}

TEST(Continuation, BetaRisesOnlyOnceTheComplianceHasSettled) {
  Continuation c(schedule(), 1e-6, 1e-4);
  // compliance falling by 10 % per iteration: not settled, β stays
  double compliance = 100;
  for (int it = 0; it < 10; ++it) {
    compliance *= 0.9;
    ASSERT_EQ(c.next(compliance, 0.1), NextStep::Continue);
  }
  EXPECT_EQ(c.beta(), 1);
  // changes of 0.5 % (below the 1 % tolerance): β rises at the third calm iteration
  EXPECT_EQ(c.next(compliance *= 0.995, 0.1), NextStep::Continue);
  EXPECT_EQ(c.next(compliance *= 0.995, 0.1), NextStep::Continue);
  EXPECT_EQ(c.next(compliance *= 0.995, 0.1), NextStep::RaiseBeta);
  EXPECT_EQ(c.beta(), 2);
  EXPECT_FALSE(c.sharp());
}

TEST(Continuation, ConvergenceIsJudgedAtTheFinalBetaOnly) {
  Continuation c(schedule(4), 1e-3, 1e-4);
  // a design that does not move at all: settled at once at β 1 and 2 (its first iteration
  // at each β has nothing to compare with), converged only at β 4
  EXPECT_EQ(c.next(50, 0), NextStep::Continue);
  EXPECT_EQ(c.next(50, 0), NextStep::RaiseBeta);
  EXPECT_EQ(c.beta(), 2);
  EXPECT_EQ(c.next(50, 0), NextStep::Continue);
  EXPECT_EQ(c.next(50, 0), NextStep::RaiseBeta);
  EXPECT_EQ(c.beta(), 4);
  EXPECT_TRUE(c.sharp());
  EXPECT_EQ(c.next(50, 0), NextStep::Continue);
  EXPECT_EQ(c.next(50, 0), NextStep::Converged);
}

TEST(Continuation, TheCapOfIterationsPerBetaRaisesItAnyway) {
  ProjectionParams p = schedule(5);
  p.max_iterations_per_beta = 4;
  Continuation c(p, 1e-6, 1e-6);
  double compliance = 100;
  std::vector<double> betas;
  for (int it = 0; it < 12; ++it) {
    compliance *= 0.8;  // never settles
    if (c.next(compliance, 0.2) == NextStep::RaiseBeta) betas.push_back(c.beta());
  }
  // 1 → 2 → 4 → 5 (capped at beta_max), each after 4 iterations
  EXPECT_EQ(betas, (std::vector<double>{2, 4, 5}));
  EXPECT_TRUE(c.sharp());
}

TEST(Continuation, WithoutProjectionBetaStaysOneAndFiveCalmIterationsConverge) {
  ProjectionParams p = schedule();
  p.enabled = false;
  Continuation c(p, 1e-3, 1e-3);
  EXPECT_EQ(c.beta(), 1);
  EXPECT_TRUE(c.sharp());
  EXPECT_EQ(c.next(10, 0.1), NextStep::Continue);
  for (int it = 0; it < 4; ++it) ASSERT_EQ(c.next(10, 0.1), NextStep::Continue) << it;
  EXPECT_EQ(c.next(10, 0.1), NextStep::Converged);
  EXPECT_EQ(c.beta(), 1);
}

TEST(Continuation, TheSolverToleranceIsLooseBelowTheFinalBetaOnly) {
  Continuation c(schedule(4), 1e-6, 1e-6);
  EXPECT_EQ(solver_tolerance(c, 1e-5, 1e-3), 1e-3);  // β 1
  EXPECT_EQ(solver_tolerance(c, 1e-5, 1e-7), 1e-5);  // an "early" one tighter than the final: never used
  for (double compliance = 100; !c.sharp(); compliance *= 0.5) {
    ASSERT_EQ(solver_tolerance(c, 1e-5, 1e-3), 1e-3) << "beta " << c.beta();
    c.next(compliance, 0.2);
  }
  EXPECT_EQ(c.beta(), 4);
  EXPECT_EQ(solver_tolerance(c, 1e-5, 1e-3), 1e-5);  // the final β: every compliance compared is tight
  ProjectionParams off = schedule();
  off.enabled = false;
  EXPECT_EQ(solver_tolerance(Continuation(off, 1e-3, 1e-3), 1e-5, 1e-3), 1e-5);  // no continuation: tight
}

}  // namespace
}  // namespace topopt::simp
