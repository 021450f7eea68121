// Smoothed-aggregation multigrid: the preconditioner is symmetric positive definite, the
// iteration count does not grow with the mesh (multigrid's defining property), a Galerkin
// refresh equals a fresh hierarchy, and the multigrid-CG solve equals the Cholesky solve, also
// with SIMP's 1e-9 void contrast.
#include "fem/amg.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fem/boundary_conditions.h"
#include "fem/clamped_beam.h"
#include "fem/elasticity.h"
#include "fem/node_block_matrix.h"

namespace topopt::fem {
namespace {

TEST(Amg, PreconditionerIsSymmetricPositiveDefinite) {
  TetMesh m = beam({24, 6, 6});
  System s = clamped_beam_system(m, VecXd::Ones(m.T.rows()));
  SmoothedAggregationAmg amg;
  AmgParams p;
  p.coarse_dofs = 200;  // force three or more levels on this small problem
  amg.setup(s.A, s.node_ptr, s.modes, p);
  ASSERT_GE(amg.levels(), 3);
  EXPECT_LT(amg.complexity(), 2.0);
  std::mt19937 rng(3);
  std::normal_distribution<double> N;
  const int n = s.A.rows;
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::VectorXd x(n), y(n), Mx(n), My(n);
    for (int i = 0; i < n; ++i) x[i] = N(rng), y[i] = N(rng);
    amg.apply(x.data(), Mx.data());
    amg.apply(y.data(), My.data());
    EXPECT_NEAR(y.dot(Mx), x.dot(My), 1e-10 * std::abs(y.dot(Mx)) + 1e-14 * Mx.norm() * y.norm());
    EXPECT_GT(x.dot(Mx), 0);
  }
}

TEST(Amg, IterationsDoNotGrowWithTheMesh) {
  // Halving h multiplies the unknowns by 8; a one-level preconditioner's CG iterations would
  // double, multigrid's stay about the same.
  std::vector<int> iterations;
  for (int k : {1, 2}) {
    TetMesh m = beam({20 * k, 4 * k, 4 * k});
    System s = clamped_beam_system(m, VecXd::Ones(m.T.rows()));
    SmoothedAggregationAmg amg;
    AmgParams p;
    p.coarse_dofs = 300;
    amg.setup(s.A, s.node_ptr, s.modes, p);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(s.A.rows), x = Eigen::VectorXd::Zero(s.A.rows);
    for (int i = 2; i < s.A.rows; i += 3) b[i] = -1.0;  // a body force along -z
    PcgParams pp;
    pp.tolerance = 1e-8;
    pp.max_iterations = 500;
    PcgResult r = pcg(CsrOperator(s.A, 2), amg, b, x, pp);
    ASSERT_TRUE(r.converged);
    // the residual it reports is the true one
    Eigen::VectorXd Ax(s.A.rows);
    s.A.multiply(x.data(), Ax.data(), 1);
    EXPECT_LT((b - Ax).norm(), 1.01e-8 * b.norm());
    iterations.push_back(r.iterations);
  }
  EXPECT_LT(iterations[0], 60);
  EXPECT_LE(iterations[1], iterations[0] * 1.4 + 2) << iterations[0] << " then " << iterations[1];
}

TEST(Amg, GalerkinRefreshEqualsAFreshHierarchyToTheBit) {
  // K doubled: the strength graph, the aggregates, D⁻¹K and so the prolongators are those of K
  // (a power of two scales every product exactly), and every coarse matrix doubles. A hierarchy
  // of K refreshed for 2K (R A P refilled on its kept pattern, the coarse factor's values copied
  // into its kept pattern) must then equal a hierarchy set up on 2K and refreshed alike (the
  // same power-iteration steps): the same V-cycle to the bit. One refreshed on the finest level
  // only keeps K's coarse levels and must not.
  TetMesh m = beam({24, 6, 6});
  System s = clamped_beam_system(m, VecXd::Ones(m.T.rows()));
  AmgParams p;
  p.coarse_dofs = 200;  // three levels or more: a refill of a middle level and of the coarsest
  CsrMatrix kept = s.A, stale = s.A, doubled = s.A;
  for (double& v : doubled.val) v *= 2;
  SmoothedAggregationAmg refreshed, finest_only, fresh;
  refreshed.setup(kept, s.node_ptr, s.modes, p);
  finest_only.setup(stale, s.node_ptr, s.modes, p);
  fresh.setup(doubled, s.node_ptr, s.modes, p);
  ASSERT_GE(fresh.levels(), 3);
  ASSERT_EQ(refreshed.level_sizes(), fresh.level_sizes());
  kept.val = doubled.val;
  stale.val = doubled.val;
  for (int twice = 0; twice < 2; ++twice) {  // the second refill takes the kept patterns only
    refreshed.refresh_galerkin();
    fresh.refresh_galerkin();
  }
  finest_only.refresh_finest();
  finest_only.refresh_finest();
  const int n = s.A.rows;
  std::mt19937 rng(5);
  std::normal_distribution<double> N;
  Eigen::VectorXd r(n), z_fresh(n), z_refreshed(n), z_stale(n);
  for (int i = 0; i < n; ++i) r[i] = N(rng);
  fresh.apply(r.data(), z_fresh.data());
  refreshed.apply(r.data(), z_refreshed.data());
  finest_only.apply(r.data(), z_stale.data());
  EXPECT_EQ(z_refreshed, z_fresh);
  EXPECT_GT((z_stale - z_fresh).norm(), 1e-3 * z_fresh.norm());  // the coarse levels matter
}

TEST(Amg, NodeBlockProductsGiveTheRowWalksVCycleAndProductToTheBit) {
  // K with its node blocks: the finest level's products read 3×3 blocks (fem/node_block_matrix.h);
  // the same K without them: the row walk of sparse_product. The two hierarchies are the same
  // (aggregation goes by node_ptr), so the V-cycles and the finest products must be the same to
  // the bit, after the setup and after new values (a finest and a Galerkin refresh).
  TetMesh m = beam({24, 6, 6});
  System s = clamped_beam_system(m, VecXd::Ones(m.T.rows()));
  AmgParams p;
  p.coarse_dofs = 200;
  CsrMatrix blocked = s.A, plain = s.A;
  plain.blocks.clear();
  ASSERT_TRUE(NodeBlockPattern().build(blocked));  // the blocks' products are the ones compared
  ASSERT_FALSE(NodeBlockPattern().build(plain));
  SmoothedAggregationAmg by_blocks, by_rows;
  by_blocks.setup(blocked, s.node_ptr, s.modes, p);
  by_rows.setup(plain, s.node_ptr, s.modes, p);
  ASSERT_GE(by_blocks.levels(), 3);
  const int n = s.A.rows;
  std::mt19937 rng(7);
  std::normal_distribution<double> N;
  Eigen::VectorXd r(n);
  for (int i = 0; i < n; ++i) r[i] = N(rng);
  auto expect_same = [&](const char* when) {
    Eigen::VectorXd z_blocks(n), z_rows(n), y_blocks(n), y_rows(n);
    by_blocks.apply(r.data(), z_blocks.data());
    by_rows.apply(r.data(), z_rows.data());
    EXPECT_EQ(z_blocks, z_rows) << when;
    by_blocks.multiply_finest(r.data(), y_blocks.data());
    by_rows.multiply_finest(r.data(), y_rows.data());
    EXPECT_EQ(y_blocks, y_rows) << when;
    Eigen::VectorXd y(n);
    blocked.multiply(r.data(), y.data(), 1);
    EXPECT_EQ(y_blocks, y) << when;  // the matrix's current values, not the setup's
  };
  expect_same("after the setup");
  std::vector<double> f(n);  // K scaled by f f ᵀ entrywise (symmetric positive definite still)
  for (int i = 0; i < n; ++i) f[i] = 1 + 0.3 * std::sin(0.7 * i);
  for (int i = 0; i < n; ++i)
    for (int k = blocked.ptr[i]; k < blocked.ptr[i + 1]; ++k) blocked.val[k] = plain.val[k] *= f[i] * f[blocked.col[k]];
  by_blocks.refresh_finest();
  by_rows.refresh_finest();
  expect_same("after a finest refresh");
  for (double* v : {blocked.val.data(), plain.val.data()})
    for (size_t k = 0; k < blocked.val.size(); ++k) v[k] *= 1.5;
  by_blocks.refresh_galerkin();
  by_rows.refresh_galerkin();
  expect_same("after a Galerkin refresh");
}

TEST(Amg, MultigridSolveEqualsCholeskyWithVoidContrast) {
  // SIMP's worst case: most of the beam at the 1e-9 void stiffness around a solid path.
  TetMesh m = beam({24, 6, 6});
  VecXd scale(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) {
    Eigen::RowVector3d c = 0.25 * (m.V.row(m.T(t, 0)) + m.V.row(m.T(t, 1)) + m.V.row(m.T(t, 2)) + m.V.row(m.T(t, 3)));
    const bool solid = c[2] > 5.5 || c[2] < 2.5 || std::abs(c[2] - (4 + 3 * std::sin(c[0] / 6))) < 1.2;
    scale[t] = solid ? 1.0 : 1e-9;
  }
  Supports sup = make_supports(m, {support_on(SupportSpec::Kind::Fixed, {1})});
  LoadSpec load{LoadSpec::Kind::Force, {2}, {0, 0, -100}, 0, {}};
  Eigen::MatrixXd F = make_loads(m, Material{}, {LoadCase{"c", {load}, 1}});
  Eigen::MatrixXd U[2];
  for (int k = 0; k < 2; ++k) {
    SolverParams sp;
    sp.kind = k == 0 ? SolverKind::Direct : SolverKind::Iterative;
    sp.tolerance = 1e-10;
    Elasticity fe(m, Material{}, sup, sp);
    fe.set_scale(scale);
    U[k] = fe.solve(F);
  }
  EXPECT_LT((U[1] - U[0]).norm(), 1e-6 * U[0].norm());
  EXPECT_NEAR(F.col(0).dot(U[1].col(0)), F.col(0).dot(U[0].col(0)), 1e-8 * F.col(0).dot(U[0].col(0)));
}

}  // namespace
}  // namespace topopt::fem
