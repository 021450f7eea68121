// The Helmholtz (PDE) filter: constants pass, its transpose is its adjoint, it matches the
// continuum solution of −ℓ²∇²ρ̃ + ρ̃ = x for a cosine field, it attenuates like the explicit
// cone filter of the matching radius, non-design elements are left out, memory is linear, and
// padded, it sees void beyond the part's free faces (the 1D solution of the Robin condition).
#include "simp/helmholtz_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "mesh/core/structured_box.h"
#include "simp/density_filter.h"

namespace topopt::simp {
namespace {

struct Box {
  TetMesh mesh;
  std::vector<int> design;
  VecXd volume;
  MatX3d centre;
};

/// A box of `length` mm along z (and 4 × 4 mm across) in cells of about h mm, all design
/// unless `pad` (the top 2 mm of z kept solid).
Box box(double length, double h, bool pad = false) {
  mesh::StructuredBoxParams p;
  p.size = {4, 4, length};
  p.cells = {static_cast<int>(std::lround(4 / h)), static_cast<int>(std::lround(4 / h)),
             static_cast<int>(std::lround(length / h))};
  if (pad) p.nondesign = {{0, 0, length - 2, 4, 4, length}};
  Box b;
  b.mesh = mesh::structured_box_mesh(p);
  for (long t = 0; t < b.mesh.T.rows(); ++t)
    if (b.mesh.domain[t] == 0) b.design.push_back(static_cast<int>(t));
  b.volume = tet_volumes(b.mesh);
  const MatX3d all = tet_centroids(b.mesh);
  b.centre.resize(static_cast<long>(b.design.size()), 3);
  for (size_t i = 0; i < b.design.size(); ++i) b.centre.row(static_cast<long>(i)) = all.row(b.design[i]);
  return b;
}

/// The amplitude A of a filtered field ≈ A cos(k z) over the elements at least `margin` from
/// both ends (least squares).
double amplitude(const VecXd& field, const Box& b, double k, double length, double margin) {
  double num = 0, den = 0;
  for (long i = 0; i < field.size(); ++i) {
    const double z = b.centre(i, 2);
    if (z < margin || z > length - margin) continue;
    num += field[i] * std::cos(k * z), den += std::cos(k * z) * std::cos(k * z);
  }
  return num / den;
}

TEST(HelmholtzFilter, PassesConstantsAndItsTransposeIsItsAdjoint) {
  const Box b = box(12, 1, true);
  HelmholtzFilter f(b.mesh, b.design, b.volume, {FilterKind::Helmholtz, 3.0, 0});
  const VecXd ones = VecXd::Ones(static_cast<long>(b.design.size()));
  EXPECT_LT((f.apply(ones) - ones).cwiseAbs().maxCoeff(), 1e-8);
  const VecXd x = VecXd::Random(ones.size()), y = VecXd::Random(ones.size());
  const VecXd fx = f.apply(x);
  EXPECT_GT(f.last_iterations(), 0);
  EXPECT_NEAR(fx.dot(y), x.dot(f.apply_transpose(y)), 1e-10 * std::abs(fx.dot(y)) + 1e-12);
  EXPECT_NEAR(f.length(), 3.0 / (2 * std::sqrt(3.0)), 1e-12);
}

/// A field that is not finite is the optimiser's fault, not the mesh's: the error says so (it
/// used to blame degenerate tets, which sent a user to remesh a sound part).
TEST(HelmholtzFilter, ANonFiniteFieldIsNamedAsAnInternalFaultNotTheMesh) {
  const Box b = box(6, 1, true);
  HelmholtzFilter f(b.mesh, b.design, b.volume, {FilterKind::Helmholtz, 3.0, 0});
  VecXd x = VecXd::Constant(static_cast<long>(b.design.size()), 0.5);
  x[3] = std::nan("");
  try {
    f.apply(x);
    FAIL() << "a NaN went through the filter";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Internal);
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("degenerate"), std::string::npos) << e.what();
  }
  x[3] = 0.5;
  EXPECT_TRUE(f.apply(x).allFinite());  // the failed call left no NaN in its warm start
}

TEST(HelmholtzFilter, MatchesTheContinuumSolutionForACosine) {
  // cos(k z) with k = mπ/L meets the zero-flux condition at z = 0 and z = L, so the filtered
  // field of the continuum is cos(k z) / (1 + ℓ²k²) exactly; linear tets are O(h²) from it
  const double length = 20, h = 0.5;
  const Box b = box(length, h);
  const double k = 2 * M_PI / length;
  VecXd x(static_cast<long>(b.design.size()));
  for (long i = 0; i < x.size(); ++i) x[i] = std::cos(k * b.centre(i, 2));
  for (double r : {2.0, 5.0, 10.0}) {
    HelmholtzFilter f(b.mesh, b.design, b.volume, {FilterKind::Helmholtz, r, 0});
    const double exact = 1 / (1 + f.length() * f.length() * k * k);
    const VecXd y = f.apply(x);
    EXPECT_NEAR(amplitude(y, b, k, length, 0), exact, 0.01 * exact) << "radius " << r;
    for (long i = 0; i < y.size(); ++i) ASSERT_NEAR(y[i], exact * std::cos(k * b.centre(i, 2)), 0.02) << i;
  }
}

TEST(HelmholtzFilter, AttenuatesLikeTheConeFilterOfTheSameRadius) {
  // Lazarov & Sigmund's match ℓ = r/(2√3): the amplitude left of a cosine of wavelength
  // 4r ... 10r by the two filters, away from the ends (where the explicit filter is cut)
  const double length = 24, h = 1;
  const Box b = box(length, h);
  for (double r : {2.0, 3.0}) {
    DensityFilter cone(b.mesh, b.design, b.volume, {FilterKind::Cone, r, 0});
    HelmholtzFilter pde(b.mesh, b.design, b.volume, {FilterKind::Helmholtz, r, 0});
    for (int m : {2, 4}) {
      const double k = m * M_PI / length;
      VecXd x(static_cast<long>(b.design.size()));
      for (long i = 0; i < x.size(); ++i) x[i] = std::cos(k * b.centre(i, 2));
      const double a_cone = amplitude(cone.apply(x), b, k, length, r), a_pde = amplitude(pde.apply(x), b, k, length, r);
      EXPECT_LT(a_pde, 1.0);
      EXPECT_NEAR(a_pde, a_cone, 0.03) << "radius " << r << ", k " << k;
    }
  }
}

TEST(HelmholtzFilter, NonDesignElementsNeitherGiveNorTake) {
  // a void design beside a solid pad stays void: the pad is not part of the equation
  const Box b = box(12, 1, true);
  HelmholtzFilter f(b.mesh, b.design, b.volume, {FilterKind::Helmholtz, 4.0, 0});
  const VecXd zero = VecXd::Zero(static_cast<long>(b.design.size()));
  EXPECT_EQ(f.apply(zero).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LT(f.unknowns(), b.mesh.V.rows());  // the pad's own nodes are not unknowns
}

TEST(HelmholtzFilter, PaddedFreeFacesSeeVoidBeyondThem) {
  // a 4 × 4 × 12 mm box of 0.5 mm cells, ℓ = 1 mm; the side faces held (every node on x or y = 0
  // or 4: not padded, ∂ρ̃/∂n = 0), so along z the problem is the 1D one: with void beyond the
  // padded ends z = 0 and 12, a full design filters to 1 − ½ e^(−z/ℓ) − ½ e^(−(12−z)/ℓ) (the
  // Robin condition's exact solution: ½ at a face, as the explicit filter's ghost layers give);
  // with the weight κ (ℓ ∂ρ̃/∂n + κ ρ̃ = 0), 1 − κ/(1 + κ) (e^(−z/ℓ) + e^(−(12−z)/ℓ))
  const Box b = box(12, 0.5);
  std::vector<char> held(static_cast<size_t>(b.mesh.V.rows()), 0);
  for (long v = 0; v < b.mesh.V.rows(); ++v)
    for (int a = 0; a < 2; ++a) held[v] |= b.mesh.V(v, a) < 1e-9 || b.mesh.V(v, a) > 4 - 1e-9;
  FilterParams fp{FilterKind::Helmholtz, 2 * std::sqrt(3.0), 0};  // ℓ = r/(2√3) = 1 mm
  fp.pad_free_faces = true;
  const VecXd ones = VecXd::Ones(static_cast<long>(b.design.size()));
  for (double kappa : {1.0, 1.0 / 3}) {
    fp.pad_weight = kappa;
    const HelmholtzFilter weighed(b.mesh, b.design, b.volume, fp, {}, held);
    const VecXd full = weighed.apply(ones);
    // over the middle of the section (the end faces' corner triangles have held nodes only, so are
    // not padded: a Neumann corner whose effect decays over ℓ)
    double worst = 0;
    const double a = kappa / (1 + kappa);
    for (long i = 0; i < full.size(); ++i) {
      const double z = b.centre(i, 2);
      if (std::max(std::abs(b.centre(i, 0) - 2), std::abs(b.centre(i, 1) - 2)) > 1) continue;
      worst = std::max(worst, std::abs(full[i] - (1 - a * std::exp(-z) - a * std::exp(-(12 - z)))));
    }
    std::cout << "padded Helmholtz filter (weight " << kappa << ") of a full design: worst deviation from the 1D "
              << "solution " << worst << "\n";
    EXPECT_LT(worst, 0.02) << "against the 1D solution with void beyond the ends, weight " << kappa;
    EXPECT_NE(weighed.describe().find("padded"), std::string::npos);
  }
  fp.pad_weight = 1;
  const HelmholtzFilter padded(b.mesh, b.design, b.volume, fp, {}, held);
  EXPECT_NEAR(padded.length(), 1.0, 1e-12);
  // the padding keeps the filter symmetric: its transpose is still its adjoint
  const VecXd x = VecXd::Random(ones.size()), y = VecXd::Random(ones.size());
  EXPECT_NEAR(y.dot(padded.apply(x)), x.dot(padded.apply_transpose(y)), 1e-9 * std::abs(y.dot(padded.apply(x))));
  // every face held: nothing padded, constants pass
  const HelmholtzFilter all_held(b.mesh, b.design, b.volume, fp, {},
                                 std::vector<char>(static_cast<size_t>(b.mesh.V.rows()), 1));
  EXPECT_LT((all_held.apply(ones) - ones).cwiseAbs().maxCoeff(), 1e-8);
}

TEST(HelmholtzFilter, ItsMatrixDoesNotGrowWithTheRadius) {
  const Box b = box(12, 1);
  HelmholtzFilter small(b.mesh, b.design, b.volume, {FilterKind::Helmholtz, 1.0, 0});
  HelmholtzFilter large(b.mesh, b.design, b.volume, {FilterKind::Helmholtz, 6.0, 0});
  EXPECT_EQ(small.describe().substr(small.describe().find("edges), ")),
            large.describe().substr(large.describe().find("edges), ")));
  DensityFilter explicit_large(b.mesh, b.design, b.volume, {FilterKind::Cone, 4.0, 0});
  EXPECT_GT(explicit_large.mean_neighbours(), 300);  // what the PDE filter does not hold
}

TEST(HelmholtzFilter, MultigridAndJacobiGiveTheSameFilter) {
  // a radius of many mesh sizes: (ℓ/h)² well above the switch, so "auto" takes multigrid
  const Box b = box(20, 0.5, true);
  FilterParams p{FilterKind::Helmholtz, 8.0, 0};
  HelmholtzFilter automatic(b.mesh, b.design, b.volume, p);
  EXPECT_TRUE(automatic.multigrid());
  EXPECT_NE(automatic.describe().find("preconditioned by multigrid"), std::string::npos) << automatic.describe();
  p.helmholtz_solver = HelmholtzSolver::Jacobi;
  HelmholtzFilter jacobi(b.mesh, b.design, b.volume, p);
  EXPECT_FALSE(jacobi.multigrid());
  const VecXd x = VecXd::Random(static_cast<long>(b.design.size())).cwiseAbs();
  const VecXd a = automatic.apply(x), j = jacobi.apply(x);
  EXPECT_LT((a - j).cwiseAbs().maxCoeff(), 1e-9 * j.cwiseAbs().maxCoeff());
  EXPECT_LT(automatic.last_iterations(), jacobi.last_iterations());
  const VecXd y = VecXd::Random(x.size());
  EXPECT_NEAR(a.dot(y), x.dot(automatic.apply_transpose(y)), 1e-10 * std::abs(a.dot(y)));
  // the rule: the Laplacian's weight (ℓ/h)² against helmholtz_multigrid_above()
  const double above = helmholtz_multigrid_above();
  EXPECT_FALSE(helmholtz_uses_multigrid(HelmholtzSolver::Auto, 0.9 * std::sqrt(above), 1.0));
  EXPECT_TRUE(helmholtz_uses_multigrid(HelmholtzSolver::Auto, 1.1 * std::sqrt(above), 1.0));
  EXPECT_TRUE(helmholtz_uses_multigrid(HelmholtzSolver::Multigrid, 0.1, 1.0));
  EXPECT_FALSE(helmholtz_uses_multigrid(HelmholtzSolver::Jacobi, 10, 1.0));
}

TEST(FilterChoice, AutoTakesTheHelmholtzFilterWhenTheExplicitOneIsDenseOrTooLarge) {
  EXPECT_EQ(choose_filter_kind(FilterKind::Cone, false, 1e12, 1e3, 1e6), FilterKind::Cone);
  EXPECT_EQ(choose_filter_kind(FilterKind::Gaussian, true, 50e3, 1e3, 1e9), FilterKind::Gaussian);
  EXPECT_EQ(choose_filter_kind(FilterKind::Gaussian, true, 1e3 * (kHelmholtzAboveNeighbours + 1), 1e3, 1e9),
            FilterKind::Helmholtz);
  EXPECT_EQ(choose_filter_kind(FilterKind::Gaussian, true, 50e3, 1e3, 1e4), FilterKind::Helmholtz);
}

}  // namespace
}  // namespace topopt::simp
