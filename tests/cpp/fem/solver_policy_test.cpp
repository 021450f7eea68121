// The SIMP-time reuse rules, decision by decision.
#include "fem/solver_policy.h"

#include <gtest/gtest.h>

namespace topopt::fem {
namespace {

TEST(FactorReuse, FactorisesWithoutAFactorOrWhenReuseIsOff) {
  const FactorReuse on(true), off(false);
  EXPECT_TRUE(on.factorise_on_update(false));
  EXPECT_FALSE(on.factorise_on_update(true));
  EXPECT_TRUE(off.factorise_on_update(false));
  EXPECT_TRUE(off.factorise_on_update(true));
}

TEST(FactorReuse, TwoSolvesFactoriseDirectlyAfterAFailedRecycling) {
  FactorReuse r(true);
  EXPECT_FALSE(r.factorise_before_solve());
  r.recycling_failed();
  EXPECT_TRUE(r.factorise_before_solve());
  EXPECT_TRUE(r.factorise_before_solve());
  EXPECT_FALSE(r.factorise_before_solve());
  EXPECT_FALSE(r.factorise_before_solve());
}

TEST(HierarchyReuse, NewHierarchyWhenRefreshedCoarseMatricesOutgrowTheSetup) {
  HierarchyReuse r(true);
  EXPECT_FALSE(r.keep(false));  // nothing built yet
  r.set_up();
  r.record(10);  // the baseline
  EXPECT_TRUE(r.keep(true));
  r.cut();  // a kept solve cut short: the next matrix's coarse matrices are refreshed
  ASSERT_TRUE(r.refresh_coarse_on_update());
  r.record(19);  // on refreshed coarse matrices, 1.5 * 10 + 4 = 19: not yet
  EXPECT_TRUE(r.keep(true));
  r.cut();
  ASSERT_TRUE(r.refresh_coarse_on_update());
  r.record(20);  // the aggregates no longer fit: a new setup
  EXPECT_FALSE(r.keep(true));
  r.set_up();  // a new hierarchy, a new baseline
  EXPECT_TRUE(r.keep(true));
  r.record(30);
  EXPECT_FALSE(r.refresh_coarse_on_update());
  r.record(60);  // a kept solve, however slow, says nothing of the aggregates
  EXPECT_TRUE(r.keep(true));
}

TEST(HierarchyReuse, CoarseMatricesRefreshedWhenTheExcessWouldReachARefreshsCost) {
  const int cost = HierarchyReuse::kRefreshCost;
  HierarchyReuse r(true);
  r.set_up();
  r.record(12);  // baseline and reference
  // kept solves 2, 3, then 4 beyond the reference: refreshed once the excess so far plus one more
  // solve like the last reaches the cost, not before
  int excess = 0, last = 0, kept = 0;
  for (int extra = 2;; ++extra) {
    const bool refresh = r.refresh_coarse_on_update();
    EXPECT_EQ(refresh, excess + last >= cost) << extra;
    if (refresh) break;
    r.record(12 + extra);
    excess += extra;
    last = extra;
    ++kept;
  }
  EXPECT_GE(kept, 3);  // at 14: 2 + 3 + 4 + 5 kept, then 14 + 5 ahead: the refresh
  // the refreshed solve is the new reference: a kept solve of its count adds nothing
  r.record(15);
  EXPECT_FALSE(r.refresh_coarse_on_update());
  r.record(15);
  EXPECT_FALSE(r.refresh_coarse_on_update());
  r.record(14);  // fewer than the reference: no negative excess
  EXPECT_FALSE(r.refresh_coarse_on_update());
  // one kept solve half a refresh's cost past it: the next one like it would reach the cost
  r.record(15 + (cost + 1) / 2);
  EXPECT_TRUE(r.refresh_coarse_on_update());
  EXPECT_TRUE(r.keep(true));  // refreshed, not rebuilt
}

TEST(HierarchyReuse, PatienceIsTheReferencePlusARefreshsCost) {
  HierarchyReuse r(true);
  r.set_up();
  EXPECT_EQ(r.patience(5000), 5000);  // coarse matrices that fit: the solver's own cap
  r.record(12);
  EXPECT_FALSE(r.refresh_coarse_on_update());
  EXPECT_EQ(r.patience(5000), 12 + HierarchyReuse::kRefreshCost);
  EXPECT_EQ(r.patience(15), 15);  // never above the solver's cap
  r.cut();
  EXPECT_TRUE(r.refresh_coarse_on_update());
  EXPECT_EQ(r.patience(5000), 5000);  // refreshed for this matrix
  r.record(9);
  EXPECT_FALSE(r.refresh_coarse_on_update());
  EXPECT_EQ(r.patience(5000), 9 + HierarchyReuse::kRefreshCost);
}

TEST(HierarchyReuse, WhileOneMatrixsStalenessCostsARefreshEveryMatrixIsRefreshed) {
  const int cost = HierarchyReuse::kRefreshCost;
  HierarchyReuse r(true);
  r.set_up();
  r.record(12);
  EXPECT_FALSE(r.refresh_coarse_on_update());
  r.cut(12 + 3 * cost);  // one matrix on the kept coarse matrices cost three refreshes
  int refreshed = 0;
  while (r.refresh_coarse_on_update()) {
    r.record(12);  // each refreshed solve as fast as the reference
    ++refreshed;
    ASSERT_LT(refreshed, 10);
  }
  // refreshed for the matrices after the cut, not for ever: the remembered staleness fades and a
  // kept solve is tried again
  EXPECT_GE(refreshed, 3);
  EXPECT_EQ(r.patience(5000), 12 + cost);
  r.cut();  // and it is as slow: refreshed again
  EXPECT_TRUE(r.refresh_coarse_on_update());
}

TEST(HierarchyReuse, ATolerancesChangeTakesANewBaselineOnTheHierarchyAsItIs) {
  HierarchyReuse r(true);
  r.set_up();
  r.record(10);
  EXPECT_FALSE(r.refresh_coarse_on_update());
  r.record(20);  // kept, 10 beyond the reference
  r.rebaseline(1e-3, 1e-5);  // counts at the old tolerance are not those at the new one
  EXPECT_FALSE(r.refresh_coarse_on_update());  // their excess is forgotten, nothing forced
  EXPECT_EQ(r.patience(5000), 5000);           // no reference at this tolerance yet
  r.record(25);  // the new baseline and reference: more iterations at a tighter tolerance are not growth
  EXPECT_TRUE(r.keep(true));
  EXPECT_FALSE(r.refresh_coarse_on_update());
  EXPECT_EQ(r.patience(5000), 25 + HierarchyReuse::kRefreshCost);
  r.cut();
  EXPECT_TRUE(r.refresh_coarse_on_update());
  r.record(static_cast<int>(1.5 * 25) + 4 + 1);  // refreshed, against the new baseline: grown
  EXPECT_FALSE(r.keep(true));
}

TEST(HierarchyReuse, AFirstSolveAtANewToleranceFarPastTheScaledBaselineSetsUpAnew) {
  // the setup's first solve took 9 iterations at 1e-2: at 1e-5, log(1e-5) / log(1e-2) = 2.5 times
  // as many are expected (22.5), and clearly more is 1.5 * 22.5 + 4 = 37
  const auto first_at_new_tolerance = [](int iterations) {
    HierarchyReuse r(true);
    r.set_up();
    r.record(9);
    EXPECT_FALSE(r.refresh_coarse_on_update());
    r.record(12);  // a kept solve at the old tolerance
    r.rebaseline(1e-2, 1e-5);
    EXPECT_FALSE(r.refresh_coarse_on_update());  // nothing forced: the hierarchy as it is
    EXPECT_EQ(r.patience(5000), 5000);           // no reference at this tolerance yet
    r.record(iterations);
    return r.keep(true);
  };
  EXPECT_TRUE(first_at_new_tolerance(22));  // as the tolerance alone explains
  EXPECT_TRUE(first_at_new_tolerance(37));  // not clearly more
  EXPECT_FALSE(first_at_new_tolerance(38));
  EXPECT_FALSE(first_at_new_tolerance(53));  // the rocker's β = 32 on the uniform start's aggregates

  // only the first solve at the new tolerance is judged so: a later kept solve is no growth
  HierarchyReuse r(true);
  r.set_up();
  r.record(9);
  r.rebaseline(1e-2, 1e-5);
  EXPECT_FALSE(r.refresh_coarse_on_update());
  r.record(30);  // the new baseline, within 37
  EXPECT_FALSE(r.refresh_coarse_on_update());
  r.record(40);  // kept, stale coarse matrices: an excess, not growth
  EXPECT_TRUE(r.keep(true));

  // a looser tolerance lowers the expectation (40 at 1e-5: 16 at 1e-2, clearly more is 28)
  HierarchyReuse loose(true);
  loose.set_up();
  loose.record(40);
  loose.rebaseline(1e-5, 1e-2);
  EXPECT_FALSE(loose.refresh_coarse_on_update());
  loose.record(29);
  EXPECT_FALSE(loose.keep(true));

  // a new setup forgets the expectation: its first solve is the baseline whatever its count
  HierarchyReuse fresh(true);
  fresh.set_up();
  fresh.record(9);
  fresh.rebaseline(1e-2, 1e-5);
  fresh.set_up();
  fresh.record(60);
  EXPECT_TRUE(fresh.keep(true));
}

TEST(HierarchyReuse, NeverKeptWhenReuseIsOff) {
  HierarchyReuse r(false);
  r.set_up();
  r.record(10);
  EXPECT_FALSE(r.keep(true));
}

}  // namespace
}  // namespace topopt::fem
