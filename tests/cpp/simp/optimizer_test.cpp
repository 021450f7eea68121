// SIMP: gradients against finite differences, the volume constraint, non-design elements,
// MMA against OC, cancellation, and the filter's basic properties.
#include "simp/optimizer.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <vector>

#include "common/error.h"
#include "fem/boundary_conditions.h"
#include "fem/elasticity.h"
#include "mesh/core/structured_box.h"
#include "simp/density_filter.h"
#include "simp/update.h"
#include "testing/self_weight.h"
#include "testing/uniform_vector.h"

namespace topopt::simp {
namespace {

struct Case {
  TetMesh mesh;
  fem::Material mat;
  fem::Supports supports;
  Eigen::MatrixXd loads;
};

Case cantilever(std::array<int, 3> cells = {12, 4, 2}) {
  Case c;
  mesh::StructuredBoxParams p;
  p.size = {30, 10, 5};
  p.cells = cells;
  p.nondesign = {{27.5, 0, 0, 30, 10, 5}};  // a load pad
  c.mesh = mesh::structured_box_mesh(p);
  c.supports = fem::make_supports(c.mesh, {fem::support_on(fem::SupportSpec::Kind::Fixed, {1})});
  fem::LoadSpec pull{fem::LoadSpec::Kind::Force, {2}, {0, -100, 0}, 0, {}};
  fem::LoadSpec push{fem::LoadSpec::Kind::Force, {2}, {0, 0, -60}, 0, {}};
  c.loads = fem::make_loads(c.mesh, c.mat, {fem::LoadCase{"a", {pull}, 1}, fem::LoadCase{"b", {push}, 1}});
  return c;
}

void check_gradient(SimpParams params, unsigned seed, const Eigen::Matrix3Xd& gravity = {}) {
  Case c = cantilever({6, 2, 2});
  params.solver.recycle_factor = false;  // every solve to machine precision
  // with self-weight the loads hold each case's full weight (as fem::make_loads gives it)
  const Eigen::MatrixXd loads = testing::with_self_weight(c.mesh, c.mat, c.loads, gravity);
  ComplianceProblem prob(c.mesh, c.mat, c.supports, loads, {1.0, 0.5}, params, {}, gravity);
  const int nd = static_cast<int>(prob.design().size());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.2, 0.8);
  VecXd x(nd);
  for (int i = 0; i < nd; ++i) x[i] = u(rng);
  VecXd dc, dv;
  double c0 = prob.compliance(x, &dc);
  prob.volume_fraction(x, &dv);
  // central differences; h balances truncation (h²) against the solver's round-off (1e-12/h)
  const double h = 1e-4;
  for (int i : {0, nd / 3, nd / 2, nd - 1}) {
    VecXd xp = x, xm = x;
    xp[i] += h, xm[i] -= h;
    double fd = (prob.compliance(xp) - prob.compliance(xm)) / (2 * h);
    EXPECT_NEAR(dc[i], fd, 1e-5 * std::abs(fd) + 1e-9 * std::abs(c0)) << "variable " << i;
    double fdv = (prob.volume_fraction(xp) - prob.volume_fraction(xm)) / (2 * h);
    EXPECT_NEAR(dv[i], fdv, 1e-6 * std::abs(fdv) + 1e-12);
  }
}

TEST(Simp, ComplianceGradientMatchesFiniteDifferencesThroughTheFilter) {
  SimpParams p;
  p.filter.radius = 6;
  check_gradient(p, 1);
  p.filter.kind = FilterKind::Cone;
  check_gradient(p, 2);
  p.filter.kind = FilterKind::Helmholtz;
  check_gradient(p, 3);
}

TEST(Simp, GradientWithSelfWeight) {
  // the weight of a design tet follows its density: both load cases get a gravity of 1e9
  // mm/s² (about 12 N on the whole steel block, against forces of 100 and 60 N), the second
  // sideways, so the load's derivative counts as much as the stiffness's
  SimpParams p;
  p.filter.radius = 6;
  Eigen::Matrix3Xd g(3, 2);
  g << 0, 3e8, -1e9, 0, 0, 5e8;
  p.projection.enabled = false;
  check_gradient(p, 4, g);
  p.projection.enabled = true;
  check_gradient(p, 5, g);
}

TEST(Simp, SelfWeightFollowsTheDensity) {
  // A block of design tets only, fixed at one end, under its own weight. At a uniform density
  // ρ the load is ρ F₁ and the stiffness E(ρ) K₁, so c(ρ) = ρ² / E(ρ) c(1): 2 c(1) at ρ = 0.5
  // (E = 1/8), and 5 c(1) at ρ = 0.05, where the law is linear (E = 0.05 × 0.1²) so that
  // near-void tets do not sag under a weight their stiffness cannot carry.
  mesh::StructuredBoxParams bp;
  bp.size = {30, 10, 5};
  bp.cells = {6, 2, 2};
  const TetMesh mesh = mesh::structured_box_mesh(bp);
  const fem::Material mat;
  const fem::Supports supports = fem::make_supports(mesh, {fem::support_on(fem::SupportSpec::Kind::Fixed, {1})});
  const fem::LoadSpec weight{fem::LoadSpec::Kind::Gravity, {}, {0, 0, -9810}, 0, {}};
  const std::vector<fem::LoadCase> cases{fem::LoadCase{"g", {weight}, 1}};
  const Eigen::MatrixXd F = fem::make_loads(mesh, mat, cases);  // the full weight
  SimpParams p;
  p.solver.recycle_factor = false;
  p.law.e_min = 0;               // the closed form without the void floor
  p.projection.enabled = false;  // ... and with ρ̄ = ρ
  ComplianceProblem prob(mesh, mat, supports, F, {}, p, {}, fem::gravity_of(cases));
  const int nd = static_cast<int>(prob.design().size());
  const double c1 = prob.compliance(VecXd::Ones(nd));
  EXPECT_GT(c1, 0);
  EXPECT_NEAR(prob.compliance(VecXd::Constant(nd, 0.5)), 2 * c1, 1e-8 * c1);
  EXPECT_NEAR(prob.compliance(VecXd::Constant(nd, 0.05)), 5 * c1, 1e-8 * c1);
  // at full density it is the plain analysis with the weight in the loads
  fem::Elasticity fe(mesh, mat, supports, p.solver);
  EXPECT_NEAR(F.col(0).dot(fe.solve(F).col(0)), c1, 1e-8 * c1);
}

TEST(Simp, OcUnderSelfWeightAloneMeetsTheVolumeAndLowersTheCompliance) {
  // a cantilever loaded by nothing but its own weight: removing material also removes load,
  // so some sensitivities are positive (OC takes those elements to their lower move limit)
  Case c = cantilever();
  const fem::LoadSpec weight{fem::LoadSpec::Kind::Gravity, {}, {0, -9810, 0}, 0, {}};
  const std::vector<fem::LoadCase> cases{fem::LoadCase{"g", {weight}, 1}};
  SimpParams p;
  p.volume_fraction = 0.4;
  p.max_iterations = 40;
  const SimpResult r =
      optimize(c.mesh, c.mat, c.supports, fem::make_loads(c.mesh, c.mat, cases), {}, p, {}, {}, fem::gravity_of(cases));
  ASSERT_GE(r.history.size(), 5u);
  EXPECT_NEAR(r.history.back().volume_fraction, 0.4, 0.005);
  EXPECT_LT(r.history.back().compliance, 0.8 * r.history.front().compliance);
  for (long t = 0; t < c.mesh.T.rows(); ++t)
    if (c.mesh.domain[t] != 0) {
      EXPECT_EQ(r.density[t], 1.0);
    }
}

TEST(Simp, GradientThroughHeavisideProjection) {
  SimpParams p;
  p.filter.radius = 6;
  p.projection.enabled = true;
  check_gradient(p, 3);  // β = 1
}

TEST(Simp, OcMeetsTheVolumeAndKeepsNonDesignSolid) {
  Case c = cantilever();
  SimpParams p;
  p.volume_fraction = 0.4;
  p.filter.radius = 5;
  p.max_iterations = 40;
  std::vector<IterationRecord> seen;
  SimpResult r =
      optimize(c.mesh, c.mat, c.supports, c.loads, {}, p, {}, [&](const IterationRecord& rec) { seen.push_back(rec); });
  ASSERT_FALSE(r.history.empty());
  EXPECT_EQ(seen.size(), r.history.size());
  // volume of the design domain at the end, from the returned densities
  VecXd vol = tet_volumes(c.mesh);
  double kept = 0, total = 0;
  for (long t = 0; t < c.mesh.T.rows(); ++t) {
    if (c.mesh.domain[t] != 0) {
      EXPECT_EQ(r.density[t], 1.0);
      continue;
    }
    kept += vol[t] * r.density[t], total += vol[t];
    EXPECT_GE(r.density[t], 0.0);
    EXPECT_LE(r.density[t], 1.0);
  }
  EXPECT_NEAR(kept / total, 0.4, 0.005 * 0.4);
  // the optimiser lowers compliance well below the uniform start
  EXPECT_LT(r.history.back().compliance, 0.7 * r.history.front().compliance);
}

/// The design domain's volume fraction of the physical densities of x, summed here from the tet
/// volumes (not through ComplianceProblem::volume_fraction, the function the update linearises).
double summed_volume(const Case& c, const ComplianceProblem& prob, const VecXd& x) {
  const VecXd rho = prob.physical(x), vol = tet_volumes(c.mesh);
  double kept = 0, total = 0;
  for (size_t i = 0; i < prob.design().size(); ++i) {
    kept += vol[prob.design()[i]] * rho[static_cast<long>(i)];
    total += vol[prob.design()[i]];
  }
  return kept / total;
}

/// The two volume tests' settings: volume fraction 0.4, filter radius 5, the Heaviside projection.
SimpParams projected_params() {
  SimpParams p;
  p.volume_fraction = 0.4;
  p.filter.radius = 5;
  p.projection.enabled = true;
  return p;
}

/// n design variables drawn uniformly from [0.3, 0.7] with `seed`.
VecXd random_design(long n, unsigned seed) { return testing::uniform_vector(n, seed, 0.3, 0.7); }

TEST(Simp, OcOnTheLinearisedVolumeMeetsTheRealVolumeAsTightlyAsTheExactBisection) {
  // One OC step, as the loop takes it (density filter, Heaviside projection), from a random
  // design 0.1 off the target: the multiplier bisected on the real volume (a filter application
  // and projection per step) and on the volume linearised at x, corrected on the real one. The
  // step's real volume must meet the target as tightly either way, with a few filter
  // applications instead of ~44. The linearisation alone (its first candidate) misses it by its
  // error, measured here 1.2e-3 (β 1), 0.045 (β 8) and 0.11 (β 32); the exact bisection meets it
  // to 2.7e-7, 1.2e-7, 3.8e-7 (43-44 evaluations), the corrected one to 0.9e-7, 4.6e-7, 5.5e-7
  // (3, 5, 10: from this start, far from a settled design, β 32 takes the most rounds).
  Case c = cantilever();
  const SimpParams p = projected_params();
  ComplianceProblem prob(c.mesh, c.mat, c.supports, c.loads, {}, p);
  const VecXd x = random_design(prob.num_variables(), 7);
  for (double beta : {1.0, 8.0, 32.0}) {
    SCOPED_TRACE("beta " + std::to_string(beta));
    prob.set_beta(beta);
    VecXd dc, dv;
    prob.compliance(x, &dc);
    const double vol = prob.volume_fraction(x, &dv);
    ASSERT_NEAR(vol, summed_volume(c, prob, x), 1e-12);
    ASSERT_GT(std::abs(vol - p.volume_fraction), 0.05) << "the start must miss the target for the test to mean anything";
    std::vector<double> seen;  // the real volume fraction of every candidate evaluated
    auto excess = [&](const VecXd& xn) {
      seen.push_back(prob.volume_fraction(xn));
      return seen.back() - p.volume_fraction;
    };
    const VecXd move = VecXd::Constant(x.size(), p.move);
    const VecXd exact = oc_update(x, dc, dv.cwiseMax(1e-30), move, excess);
    const size_t exact_evaluations = seen.size();
    seen.clear();
    const OcLinearisation linear{vol - p.volume_fraction, {}};
    const VecXd linearised = oc_update(x, dc, dv.cwiseMax(1e-30), move, excess, nullptr, &linear);
    const double exact_error = std::abs(summed_volume(c, prob, exact) - p.volume_fraction);
    const double error = std::abs(summed_volume(c, prob, linearised) - p.volume_fraction);
    std::printf("beta %g: linearisation alone %.2e, exact bisection %.2e (%zu evaluations), corrected %.2e (%zu)\n",
                beta, std::abs(seen.front() - p.volume_fraction), exact_error, exact_evaluations, error, seen.size());
    EXPECT_LE(exact_error, 2e-6 * p.volume_fraction);
    EXPECT_LE(error, 2e-6 * p.volume_fraction);
    EXPECT_LT(3 * seen.size(), exact_evaluations);
    EXPECT_LT((linearised - exact).cwiseAbs().maxCoeff(), 1e-3);
  }
}

TEST(Simp, TheVolumeAtTheAnalysedDesignIsTheVolumeOfAFreshProblemToTheBit) {
  // The loop asks for the volume and its gradient at the x compliance() just analysed: the
  // problem takes that x's filtered densities from the analysis instead of filtering again. The
  // figures must be a fresh problem's to the bit, at that x and at any other (no stale reuse).
  Case c = cantilever();
  const SimpParams p = projected_params();
  ComplianceProblem analysed(c.mesh, c.mat, c.supports, c.loads, {}, p);
  ComplianceProblem fresh(c.mesh, c.mat, c.supports, c.loads, {}, p);
  VecXd x = random_design(analysed.num_variables(), 8);
  VecXd y = x;
  y[3] += 0.1;
  for (double beta : {1.0, 16.0}) {
    analysed.set_beta(beta);
    fresh.set_beta(beta);
    analysed.compliance(x);
    for (const VecXd* at : {&x, &y, &x}) {
      VecXd dv, dv_fresh;
      EXPECT_EQ(analysed.volume_fraction(*at, &dv), fresh.volume_fraction(*at, &dv_fresh)) << beta;
      EXPECT_EQ(dv, dv_fresh) << beta;
    }
  }
}

TEST(Simp, MmaReachesAboutTheSameDesignAsOc) {
  Case c = cantilever();
  SimpParams p;
  p.volume_fraction = 0.4;
  p.filter.radius = 5;
  p.max_iterations = 60;
  SimpResult oc = optimize(c.mesh, c.mat, c.supports, c.loads, {}, p);
  p.update = UpdateKind::MMA;
  SimpResult mma = optimize(c.mesh, c.mat, c.supports, c.loads, {}, p);
  double a = oc.history.back().compliance, b = mma.history.back().compliance;
  EXPECT_NEAR(a, b, 0.05 * a);
  EXPECT_NEAR(mma.history.back().volume_fraction, 0.4, 0.01);
}

TEST(Simp, ALooseSolverToleranceBeforeTheFinalBetaEndsAtTheSameDesign) {
  // multigrid CG (forced on this small case: two levels and more) with the Heaviside
  // continuation; the early tolerance (1e-3 before β reaches 8) against none (1e-6 throughout)
  Case c = cantilever({24, 8, 4});
  SimpParams p;
  p.volume_fraction = 0.4;
  p.filter.radius = 3;
  p.max_iterations = 150;
  p.tol_objective = 1e-3;
  p.projection.beta_max = 8;
  p.solver.kind = fem::SolverKind::Iterative;
  p.solver.multigrid.coarse_dofs = 300;
  p.solver.tolerance = 1e-6;
  p.early_solver_tolerance = 1e-6;
  const SimpResult tight = optimize(c.mesh, c.mat, c.supports, c.loads, {}, p);
  p.early_solver_tolerance = 1e-3;
  const SimpResult loose = optimize(c.mesh, c.mat, c.supports, c.loads, {}, p);
  ASSERT_TRUE(tight.converged);
  ASSERT_TRUE(loose.converged);
  const IterationRecord &a = tight.history.back(), &b = loose.history.back();
  EXPECT_EQ(a.beta, 8);
  EXPECT_EQ(b.beta, 8);
  EXPECT_NEAR(b.compliance, a.compliance, 1e-3 * a.compliance);
  EXPECT_NEAR(b.volume_fraction, a.volume_fraction, 1e-4);
  EXPECT_LE(std::abs(static_cast<int>(tight.history.size()) - static_cast<int>(loose.history.size())), 2);
  // the early iterations do differ (their solves stopped sooner), and stay within the loose
  // residual's reach: the compliance of a CG iterate is off by ~ the residual's square
  const double first = std::abs(loose.history[1].compliance - tight.history[1].compliance);
  EXPECT_GT(first, 0);
  EXPECT_LT(first, 1e-3 * tight.history[1].compliance);
  std::printf("iterations %zu / %zu, compliance %.8g / %.8g, iteration 2 off by %.3g relative\n", tight.history.size(),
              loose.history.size(), a.compliance, b.compliance, first / tight.history[1].compliance);
  // the densities returned: the same design up to a few boundary tets
  EXPECT_LT((loose.density - tight.density).cwiseAbs().mean(), 5e-3);
}

TEST(Simp, MmaSolvesAConvexProblemWithTwoConstraints) {
  // min Σ (x_i − 0.9)²  s.t.  Σ x_i / n <= 0.5,  x_0 − x_1 <= -0.2  (optimum: all 0.5 but
  // x_1 = x_0 + 0.2; with n = 4 the volume then forces the others down)
  const int n = 4;
  Mma mma(n, 2, 0.3);
  VecXd x = VecXd::Constant(n, 0.3);
  for (int it = 0; it < 80; ++it) {
    VecXd df0 = 2 * (x.array() - 0.9);
    VecXd f(2);
    f << x.mean() - 0.5, x[0] - x[1] + 0.2;
    Eigen::MatrixXd df = Eigen::MatrixXd::Zero(2, n);
    df.row(0).setConstant(1.0 / n);
    df(1, 0) = 1, df(1, 1) = -1;
    x = mma.update(x, (x.array() - 0.9).square().sum(), df0, f, df);
  }
  EXPECT_NEAR(x.mean(), 0.5, 2e-3);
  EXPECT_NEAR(x[1] - x[0], 0.2, 2e-3);
  // KKT by symmetry: x_2 = x_3, and x_0 + x_1 = 2 x_2 (the pair shares one multiplier)
  EXPECT_NEAR(x[2], x[3], 1e-3);
  EXPECT_NEAR(x[0] + x[1], 2 * x[2], 5e-3);
}

TEST(Simp, CancelAndBadInput) {
  Case c = cantilever({6, 2, 2});
  SimpParams p;
  Progress cancel;
  int calls = 0;
  cancel.cancelled = [&] { return ++calls > 3; };
  try {
    optimize(c.mesh, c.mat, c.supports, c.loads, {}, p, cancel);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Cancelled);
  }
  p.volume_fraction = 1.2;
  try {
    optimize(c.mesh, c.mat, c.supports, c.loads, {}, p);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidParameter);
  }
}

TEST(DensityFilter, PreservesConstantsAndVolume) {
  Case c = cantilever({8, 3, 2});
  std::vector<int> design;
  for (long t = 0; t < c.mesh.T.rows(); ++t)
    if (c.mesh.domain[t] == 0) design.push_back(static_cast<int>(t));
  VecXd vol = tet_volumes(c.mesh);
  for (FilterKind k : {FilterKind::Gaussian, FilterKind::Cone}) {
    DensityFilter f(c.mesh, design, vol, {k, 4.0, 0});
    VecXd ones = VecXd::Ones(design.size());
    EXPECT_LT((f.apply(ones) - ones).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_GT(f.mean_neighbours(), 5);
    // adjoint identity: <H x, y> = <x, Hᵀ y>
    VecXd x = VecXd::Random(design.size()), y = VecXd::Random(design.size());
    EXPECT_NEAR(f.apply(x).dot(y), x.dot(f.apply_transpose(y)), 1e-10);
  }
}

}  // namespace
}  // namespace topopt::simp
