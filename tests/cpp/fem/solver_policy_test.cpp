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

TEST(HierarchyReuse, KeptUntilTheIterationsGrowByHalf) {
  HierarchyReuse r(true);
  EXPECT_FALSE(r.keep(false));  // nothing built yet
  r.set_up();
  r.record(10);  // the baseline
  EXPECT_TRUE(r.keep(true));
  r.record(19);  // 1.5 * 10 + 4 = 19: not yet
  EXPECT_TRUE(r.keep(true));
  r.record(20);
  EXPECT_FALSE(r.keep(true));
  r.set_up();  // a new hierarchy, a new baseline
  EXPECT_TRUE(r.keep(true));
  r.record(30);
  r.record(49);
  EXPECT_TRUE(r.keep(true));
  r.record(50);
  EXPECT_FALSE(r.keep(true));
}

TEST(HierarchyReuse, PatienceIsTheGrowthThatWouldRebuild) {
  HierarchyReuse r(true);
  r.set_up();
  EXPECT_EQ(r.patience(5000), 5000);  // no baseline yet: the solver's own cap
  r.record(12);
  EXPECT_EQ(r.patience(5000), 22);  // 1.5 * 12 + 4
  EXPECT_EQ(r.patience(15), 15);    // never above the solver's cap
  r.record(22);                     // a solve that used all its patience does not count as grown
  EXPECT_TRUE(r.keep(true));
  r.set_up();
  EXPECT_EQ(r.patience(5000), 5000);
}

TEST(HierarchyReuse, CoarseLevelsRecomputedUpFrontForTwoMatricesAfterACut) {
  HierarchyReuse r(true);
  r.set_up();
  r.record(12);
  EXPECT_FALSE(r.refresh_coarse_on_update());  // no cut yet: the finest level only
  r.cut();
  for (int k = 0; k < HierarchyReuse::kRefreshAfterCut; ++k) EXPECT_TRUE(r.refresh_coarse_on_update()) << k;
  EXPECT_FALSE(r.refresh_coarse_on_update());  // then the finest only again, until the next cut
  r.cut();
  r.set_up();  // a new hierarchy fits its matrix: nothing to recompute
  EXPECT_FALSE(r.refresh_coarse_on_update());
}

TEST(HierarchyReuse, NeverKeptWhenReuseIsOff) {
  HierarchyReuse r(false);
  r.set_up();
  r.record(10);
  EXPECT_FALSE(r.keep(true));
}

}  // namespace
}  // namespace topopt::fem
