// The solvers behind LinearSolver: both solve the clamped beam as a dense Cholesky does, the
// direct solver reuses its factor while CG on it is fast and follows FactorReuse when not, the
// multigrid solver keeps its hierarchy until the iterations grow, and the near-null space is
// the stiffness's kernel.
#include "fem/linear_solver.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include "fem/clamped_beam.h"
#include "fem/solver_policy.h"

namespace topopt::fem {
namespace {

/// A clamped beam whose stiffness can be rebuilt for new element factors in place (the pattern
/// stays), as Elasticity does between SIMP iterations.
struct Beam {
  TetMesh mesh;
  System system;
  explicit Beam(std::array<int, 3> cells) : mesh(beam(cells)), system(clamped_beam_system(mesh, ones())) {}
  VecXd ones() const { return VecXd::Ones(mesh.T.rows()); }
  FreeSystem view() const { return {&system.A, &system.free_dofs, &mesh.V, 2}; }
  /// New values for element factors `scale` (#T), same pattern (A's values rewritten in place,
  /// as Elasticity's assembly does).
  void rescale(const VecXd& scale) {
    System s = clamped_beam_system(mesh, scale);
    ASSERT_EQ(s.A.col, system.A.col);
    system.A.val = s.A.val;
    system.lower = std::move(s.lower);
  }
  /// A load along -z on every free dof (nf by 1).
  Eigen::MatrixXd load() const {
    Eigen::MatrixXd B = Eigen::MatrixXd::Zero(system.A.rows, 1);
    for (size_t k = 0; k < system.free_dofs.size(); ++k)
      if (system.free_dofs[k] % 3 == 2) B(k, 0) = -1;
    return B;
  }
  /// K⁻¹ B by Eigen's own sparse Cholesky factorisation.
  Eigen::MatrixXd exact(const Eigen::MatrixXd& B) const {
    Eigen::SimplicialLLT<SparseLower, Eigen::Lower> llt(system.lower);
    return llt.solve(B);
  }
  /// One SIMP-like step: new element factors `scale` (#T), `solver` told of the new values,
  /// then B solved into X (X's old value is the warm start). Returns the solver's statistics.
  SolverStats step(LinearSolver& solver, const VecXd& scale, const Eigen::MatrixXd& B, Eigen::MatrixXd& X) {
    rescale(scale);
    solver.update({});
    solver.solve(B, X, {});
    return solver.stats();
  }
};

/// Factors with a soft half: `soft` on the tets whose centroid has z < 4.
VecXd half_soft(const TetMesh& m, double soft) {
  VecXd s = VecXd::Ones(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) {
    double z = 0;
    for (int a = 0; a < 4; ++a) z += m.V(m.T(t, a), 2) / 4;
    if (z < 4) s[t] = soft;
  }
  return s;
}

double relative_error(const Eigen::MatrixXd& x, const Eigen::MatrixXd& ref) { return (x - ref).norm() / ref.norm(); }

TEST(LinearSolver, AutoTakesTheDirectSolverUpToTheLimit) {
  EXPECT_EQ(choose_solver(SolverKind::Auto, kDirectDofLimit), SolverKind::Direct);
  EXPECT_EQ(choose_solver(SolverKind::Auto, kDirectDofLimit + 1), SolverKind::Iterative);
  EXPECT_EQ(choose_solver(SolverKind::Iterative, 10), SolverKind::Iterative);
  EXPECT_EQ(choose_solver(SolverKind::Direct, 10 * kDirectDofLimit), SolverKind::Direct);
}

TEST(LinearSolver, BothSolversSolveTheBeam) {
  Beam b({20, 4, 4});
  const Eigen::MatrixXd B = b.load(), ref = b.exact(B);
  for (SolverKind kind : {SolverKind::Direct, SolverKind::Iterative}) {
    SolverParams p;
    p.kind = kind;
    p.tolerance = 1e-10;
    p.multigrid.coarse_dofs = 200;  // three levels or more on this small beam
    auto solver = make_linear_solver(b.view(), p);
    solver->update({});
    Eigen::MatrixXd X;
    solver->solve(B, X, {});
    EXPECT_LT(relative_error(X, ref), 1e-8) << (kind == SolverKind::Direct ? "direct" : "multigrid");
    EXPECT_EQ(solver->stats().preparations, 1);
    if (kind == SolverKind::Iterative) {
      EXPECT_GT(solver->stats().iterations, 3);
    }
  }
}

TEST(LinearSolver, DirectSolverRecyclesItsFactorWhileCgIsFast) {
  Beam b({20, 4, 4});
  SolverParams p;
  p.kind = SolverKind::Direct;
  auto solver = make_direct_solver(b.view(), p);
  const Eigen::MatrixXd B = b.load();
  Eigen::MatrixXd X;
  auto step = [&](const VecXd& scale) { return b.step(*solver, scale, B, X); };
  SolverStats s = step(b.ones());
  EXPECT_EQ(s.preparations, 1);
  // a small change: CG on the old factor, to the recycle tolerance
  s = step(VecXd::Constant(b.mesh.T.rows(), 1.0) + 0.05 * half_soft(b.mesh, 0.0));
  EXPECT_EQ(s.preparations, 1);
  EXPECT_EQ(s.reuses, 1);
  EXPECT_GT(s.iterations, 0);
  EXPECT_LE(s.iterations, p.recycle_iterations);
  EXPECT_LT(relative_error(X, b.exact(B)), 1e-7);
  // a large change: CG would be slow, so it gives up and factorises ...
  s = step(half_soft(b.mesh, 1e-4));
  EXPECT_EQ(s.preparations, 2);
  EXPECT_EQ(s.reuses, 1);
  EXPECT_LT(relative_error(X, b.exact(B)), 1e-10);  // a factorisation's accuracy, not CG's 1e-9
  // ... and the next kSkipAfterFailure matrices are factorised without trying CG
  const VecXd near = half_soft(b.mesh, 1.1e-4);
  for (int k = 1; k <= FactorReuse::kSkipAfterFailure; ++k) {
    s = step(near);
    EXPECT_EQ(s.preparations, 2 + k);
    EXPECT_EQ(s.reuses, 1);
  }
  s = step(half_soft(b.mesh, 1.2e-4));  // then recycling again
  EXPECT_EQ(s.preparations, 2 + FactorReuse::kSkipAfterFailure);
  EXPECT_EQ(s.reuses, 2);
}

TEST(LinearSolver, WithoutRecyclingEveryMatrixIsFactorised) {
  Beam b({10, 2, 2});
  SolverParams p;
  p.kind = SolverKind::Direct;
  p.recycle_factor = false;
  auto solver = make_direct_solver(b.view(), p);
  Eigen::MatrixXd X;
  for (int k = 1; k <= 3; ++k) {
    const SolverStats s = b.step(*solver, VecXd::Constant(b.mesh.T.rows(), 1.0 + 0.01 * k), b.load(), X);
    EXPECT_EQ(s.preparations, k);
    EXPECT_EQ(s.reuses, 0);
  }
}

/// CG with our multigrid to a relative residual of 1e-8 on the beam, coarse below 200 unknowns
/// (so that the hierarchy has levels to keep or refresh).
std::unique_ptr<LinearSolver> beam_multigrid(Beam& b) {
  SolverParams p;
  p.kind = SolverKind::Iterative;
  p.tolerance = 1e-8;
  p.multigrid.coarse_dofs = 200;
  return make_multigrid_solver(b.view(), p);
}

TEST(LinearSolver, MultigridKeepsItsHierarchyUntilTheIterationsGrow) {
  Beam b({24, 6, 6});
  auto solver = beam_multigrid(b);
  const Eigen::MatrixXd B = b.load();
  Eigen::MatrixXd X;
  auto step = [&](const VecXd& scale) {
    const SolverStats s = b.step(*solver, scale, B, X);
    EXPECT_LT(relative_error(X, b.exact(B)), 1e-5);
    return s;
  };
  SolverStats s = step(b.ones());
  ASSERT_EQ(s.preparations, 1);
  const int baseline = s.iterations;
  s = step(VecXd::Constant(b.mesh.T.rows(), 1.02));  // kept: the same operator up to a factor
  EXPECT_EQ(s.preparations, 1);
  EXPECT_EQ(s.reuses, 1);
  // SIMP's void contrast: the kept hierarchy would need far more iterations, so the solve is
  // cut at a refresh's cost past the reference (HierarchyReuse::patience) and finished after its coarse
  // matrices are recomputed from the new matrix (no full setup); the next solve on the
  // refreshed hierarchy, from zero, needs fewer iterations than the cut one did in all
  s = step(half_soft(b.mesh, 1e-6));
  const int kept_iterations = s.iterations, setups = s.preparations;
  EXPECT_GT(kept_iterations, 1.5 * baseline + 4);
  EXPECT_EQ(setups, 1);
  X.resize(0, 0);  // from zero, as the kept hierarchy nearly was
  s = step(half_soft(b.mesh, 1e-6));
  EXPECT_EQ(s.preparations, setups);
  EXPECT_LT(s.iterations, kept_iterations);
}

TEST(LinearSolver, MultigridStaleCoarseMatricesKeepTheAccuracyAndAreRefreshedWhenTheyCost) {
  // SIMP-like: a void region (1e-4) spreads along the beam a slice a step, so the kept coarse
  // matrices grow staler. Every solve on them meets the tolerance, as a solver set up for that
  // very matrix does; the coarse matrices are recomputed (refresh_galerkin) some steps but not
  // all, as the iterations they cost say (HierarchyReuse), and no new setup is needed.
  Beam b({24, 6, 6});
  auto solver = beam_multigrid(b);
  const Eigen::MatrixXd B = b.load();
  Eigen::MatrixXd X;
  const int steps = 16;
  int kept_refreshes = 0;
  SolverStats s = b.step(*solver, b.ones(), B, X);
  for (int k = 1; k <= steps; ++k) {
    VecXd scale = b.ones();
    for (long t = 0; t < b.mesh.T.rows(); ++t) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (int a = 0; a < 4; ++a) c += b.mesh.V.row(b.mesh.T(t, a)).transpose() / 4;
      if (c.x() < 1.5 * k && c.z() < 3) scale[t] = 1e-4;
    }
    const int before = s.refreshes;
    s = b.step(*solver, scale, B, X);
    kept_refreshes += s.refreshes > before;
    auto fresh = beam_multigrid(b);  // a hierarchy of this matrix
    Eigen::MatrixXd Y;
    fresh->update({});
    fresh->solve(B, Y, {});
    const Eigen::MatrixXd exact = b.exact(B);
    EXPECT_LT(relative_error(X, exact), 1e-5) << k;
    EXPECT_LT(relative_error(Y, exact), 1e-5) << k;
    EXPECT_LT(relative_error(X, Y), 1e-5) << k;
  }
  EXPECT_EQ(s.preparations, 1);
  EXPECT_GE(kept_refreshes, 1);     // the stale coarse matrices were refreshed ...
  EXPECT_LT(kept_refreshes, steps);  // ... but not for every matrix
}

TEST(LinearSolver, MultigridMeetsEachToleranceItIsGiven) {
  // SIMP loosens the tolerance before the final β and tightens it after (solver_tolerance in
  // simp/continuation.h): each solve meets the tolerance set, a looser one in fewer iterations,
  // and the tight solve on the kept hierarchy after the loose ones is as accurate as a fresh one
  Beam b({24, 6, 6});
  auto solver = beam_multigrid(b);
  const Eigen::MatrixXd B = b.load();
  auto residual = [&](const Eigen::MatrixXd& X) {
    Eigen::VectorXd KX(X.rows());
    b.system.A.multiply(X.data(), KX.data(), 1);
    return (B.col(0) - KX).norm() / B.col(0).norm();
  };
  Eigen::MatrixXd X;
  solver->set_tolerance(1e-3);
  SolverStats s = b.step(*solver, b.ones(), B, X);
  EXPECT_LE(residual(X), 1e-3);
  const int loose = s.iterations;
  X.resize(0, 0);
  solver->set_tolerance(1e-8);
  s = b.step(*solver, VecXd::Constant(b.mesh.T.rows(), 1.02), B, X);  // kept hierarchy, from zero
  EXPECT_EQ(s.preparations, 1);
  EXPECT_LE(residual(X), 1e-8);
  EXPECT_GT(s.iterations, loose);
  EXPECT_LT(relative_error(X, b.exact(B)), 1e-6);
  // a new matrix at the tight tolerance: kept, not rebuilt (the loose solves set no baseline the
  // tight ones would be judged against)
  s = b.step(*solver, VecXd::Constant(b.mesh.T.rows(), 1.04), B, X);
  EXPECT_EQ(s.preparations, 1);
  EXPECT_LE(residual(X), 1e-8);
}

TEST(LinearSolver, NearNullSpaceIsTheKernelOfAFreeBody) {
  TetMesh m = beam({6, 2, 2});
  const int nv = static_cast<int>(m.V.rows());
  // the unconstrained stiffness (all dofs free): a shift of the clamped fixture's x moves no
  // node onto x = 0, so every dof stays free
  m.V.col(0).array() += 1.0;
  System s = clamped_beam_system(m, VecXd::Ones(m.T.rows()));
  ASSERT_EQ(static_cast<int>(s.free_dofs.size()), 3 * nv);
  const Eigen::MatrixXd K = Eigen::MatrixXd(s.lower).selfadjointView<Eigen::Lower>();
  const std::vector<double> modes = near_null_space(m.V, s.free_dofs);
  for (int j = 0; j < 6; ++j) {
    Eigen::VectorXd r(3 * nv);
    for (int k = 0; k < 3 * nv; ++k) r[k] = modes[6 * k + j];
    EXPECT_GT(r.norm(), 0.1);
    EXPECT_LT((K * r).norm(), 1e-10 * K.norm() * r.norm()) << "mode " << j;
  }
  EXPECT_EQ(node_blocks({0, 1, 2, 4, 5, 9}), std::vector<int>({0, 3, 5, 6}));
  EXPECT_EQ(node_blocks({}), std::vector<int>({0}));
}

}  // namespace
}  // namespace topopt::fem
