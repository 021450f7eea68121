// Free vibration: the consistent mass, subspace iteration against a dense generalised
// eigensolver, and the first eigenfrequency against CalculiX's *FREQUENCY on the same mesh.
#include "fem/modal.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <filesystem>

#include "fem/boundary_conditions.h"
#include "mesh/core/structured_box.h"
#include "testing/ccx_modes.h"

namespace topopt::fem {
namespace {
namespace fs = std::filesystem;

TetMesh plate(std::array<int, 3> cells) {
  mesh::StructuredBoxParams p;
  p.size = {40, 8, 3};
  p.cells = cells;
  TetMesh m = mesh::structured_box_mesh(p);
  // bend the interior a little so that the elements are not all alike
  for (long i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 0) > 1e-9 && m.V(i, 0) < 40 - 1e-9) m.V(i, 1) += 0.1 * std::sin(m.V(i, 0));
  return m;
}

TEST(Modal, ConsistentMassWeighsThePart) {
  const TetMesh m = plate({4, 2, 1});
  const double rho = 7.85e-9;
  VecXd t(3 * m.V.rows());
  for (long n = 0; n < m.V.rows(); ++n) t.segment<3>(3 * n) = Eigen::Vector3d(1, 2, 2);  // |t|² = 9
  const double volume = 40 * 8 * 3;
  EXPECT_NEAR(t.dot(apply_mass(m, rho, {}, t)), 9 * rho * volume, 1e-12 * rho * volume);
  // factors scale each tet's share
  const VecXd half = VecXd::Constant(m.T.rows(), 0.5);
  EXPECT_NEAR(t.dot(apply_mass(m, rho, half, t)), 4.5 * rho * volume, 1e-12 * rho * volume);
}

TEST(Modal, SubspaceIterationMatchesADenseEigensolver) {
  const TetMesh m = plate({6, 2, 1});
  const Material mat;
  const Supports s = make_supports(m, {support_on(SupportSpec::Kind::Fixed, {1})});
  Elasticity fe(m, mat, s);
  ModalParams mp;
  mp.modes = 3;
  const ModalResult r = lowest_modes(fe, mat.density, {}, mp);
  ASSERT_TRUE(r.converged);
  // dense K and M on the free dofs, column by column from unit vectors
  std::vector<char> fixed(fe.num_dofs(), 0);
  for (int d : s.dofs) fixed[d] = 1;
  std::vector<int> free;
  for (int d = 0; d < fe.num_dofs(); ++d)
    if (!fixed[d]) free.push_back(d);
  const long nf = static_cast<long>(free.size());
  Eigen::MatrixXd K(nf, nf), M(nf, nf);
  // K⁻¹ by solves of unit loads, then K = inverse
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(fe.num_dofs(), nf), Kinv(nf, nf);
  for (long j = 0; j < nf; ++j) E(free[j], j) = 1;
  const Eigen::MatrixXd X = fe.solve(E);
  for (long j = 0; j < nf; ++j) {
    const VecXd mj = apply_mass(m, mat.density, {}, E.col(j));
    for (long i = 0; i < nf; ++i) Kinv(i, j) = X(free[i], j), M(i, j) = mj[free[i]];
  }
  K = Kinv.inverse();
  K = 0.5 * (K + K.transpose()).eval();
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> dense(K, M);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(r.eigenvalues[k], dense.eigenvalues()[k], 1e-8 * dense.eigenvalues()[k]);
  // the shapes are M-orthonormal
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      EXPECT_NEAR(r.shapes.col(a).dot(apply_mass(m, mat.density, {}, r.shapes.col(b))), a == b ? 1.0 : 0.0, 1e-8);
}

TEST(Modal, RepeatedFirstEigenvalueIsReported) {
  // a bar of 40 × 4 × 4 mm clamped at one end: its two bending modes are 25 % apart on this
  // mesh (the tets' split is not symmetric in y and z), so a bar's first eigenvalue counts as
  // repeated with a tolerance above that gap and as simple below it
  mesh::StructuredBoxParams p;
  p.size = {40, 4, 4};
  p.cells = {10, 2, 2};
  const TetMesh m = mesh::structured_box_mesh(p);
  const Material mat;
  Elasticity fe(m, mat, make_supports(m, {support_on(SupportSpec::Kind::Fixed, {1})}));
  ModalParams mp;
  mp.modes = 2;
  mp.repeated = 0.3;
  const ModalResult wide = lowest_modes(fe, mat.density, {}, mp);
  const double gap = (wide.eigenvalues[1] - wide.eigenvalues[0]) / wide.eigenvalues[0];
  ASSERT_GT(gap, 0.01);
  ASSERT_LT(gap, 0.3);
  EXPECT_TRUE(wide.first_repeated);
  mp.repeated = 0.5 * gap;
  EXPECT_FALSE(lowest_modes(fe, mat.density, {}, mp).first_repeated);
}

TEST(CalculixAgreement, FirstEigenfrequenciesAgreeWithCcx) {
  if (!testing::have_ccx()) GTEST_SKIP() << "ccx is not installed";
  const TetMesh m = plate({12, 3, 2});
  const Material mat{70000, 0.33, 2.7e-9};
  const Supports s = make_supports(m, {support_on(SupportSpec::Kind::Fixed, {1})});
  Elasticity fe(m, mat, s);
  ModalParams mp;
  mp.modes = 3;
  const ModalResult ours = lowest_modes(fe, mat.density, {}, mp);
  const fs::path dir = fs::temp_directory_path() / ("topopt_ccx_modes_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::vector<double> theirs = testing::ccx_frequencies(m, mat, s, 3, dir);
  ASSERT_EQ(theirs.size(), 3u) << "no eigenvalue table from ccx; see " << dir;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(ours.frequencies[k], theirs[k], 0.01 * theirs[k]) << "mode " << k + 1;
  EXPECT_GT(ours.frequencies[0], 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace topopt::fem
