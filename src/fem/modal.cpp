// Consistent mass and subspace iteration (see modal.h).
#include "fem/modal.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "common/error.h"

namespace topopt::fem {

VecXd apply_mass(const TetMesh& mesh, double density, const VecXd& factor, const VecXd& x) {
  VecXd y = VecXd::Zero(x.size());
  for (long t = 0; t < mesh.T.rows(); ++t) {
    const Eigen::RowVector3d o = mesh.V.row(mesh.T(t, 0));
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) J.row(k) = mesh.V.row(mesh.T(t, k + 1)) - o;
    const double m = (factor.size() ? factor[t] : 1.0) * density * std::abs(J.determinant()) / 6 / 20;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) sum += x.segment<3>(3 * mesh.T(t, a));
    // row a: m (2 x_a + Σ_{b≠a} x_b) = m (x_a + Σ_b x_b)
    for (int a = 0; a < 4; ++a) y.segment<3>(3 * mesh.T(t, a)) += m * (x.segment<3>(3 * mesh.T(t, a)) + sum);
  }
  return y;
}

namespace {

/// The starting block: random vectors (fixed seed, so runs repeat), the supports applied by
/// the first solve.
Eigen::MatrixXd start_block(long ndof, int block) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::MatrixXd X(ndof, block);
  for (long i = 0; i < X.size(); ++i) X.data()[i] = u(rng);
  return X;
}

/// M times each column of X.
Eigen::MatrixXd mass_times(const TetMesh& mesh, double density, const VecXd& factor, const Eigen::MatrixXd& X) {
  Eigen::MatrixXd Y(X.rows(), X.cols());
  for (long j = 0; j < X.cols(); ++j) Y.col(j) = apply_mass(mesh, density, factor, X.col(j));
  return Y;
}

}  // namespace

ModalResult lowest_modes(Elasticity& fe, double density, const VecXd& mass_factor, const ModalParams& params,
                         const Progress& progress, const Eigen::MatrixXd& start) {
  if (params.modes < 1) throw Error(ErrorCode::InvalidParameter, "ask for at least one eigenmode");
  const TetMesh& mesh = fe.mesh();
  const int p = params.modes;
  const int q = params.block > p ? params.block : std::max(2 * p, p + 6);
  ModalResult r;
  const bool warm = start.rows() == fe.num_dofs() && start.cols() == q;
  Eigen::MatrixXd MX = mass_times(mesh, density, mass_factor, warm ? start : start_block(fe.num_dofs(), q));
  VecXd previous;
  for (r.iterations = 1; r.iterations <= params.max_iterations; ++r.iterations) {
    progress.check_cancel("the eigenvalue analysis");
    // Y = K⁻¹ M X; then Rayleigh-Ritz on span(Y): Yᵀ K Y = Yᵀ M X (K Y = M X on the free dofs,
    // Y = 0 on the fixed ones), Yᵀ M Y
    const Eigen::MatrixXd Y = fe.solve(MX, progress);
    const Eigen::MatrixXd MY = mass_times(mesh, density, mass_factor, Y);
    Eigen::MatrixXd Kr = Y.transpose() * MX, Mr = Y.transpose() * MY;
    Kr = 0.5 * (Kr + Kr.transpose()).eval(), Mr = 0.5 * (Mr + Mr.transpose()).eval();
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ritz(Kr, Mr);
    if (ritz.info() != Eigen::Success)
      throw Error(ErrorCode::Internal, "the eigenvalue analysis lost its subspace (the mass matrix is singular?)");
    r.shapes = Y * ritz.eigenvectors();  // M-orthonormal, ascending λ
    r.eigenvalues = ritz.eigenvalues();
    MX = MY * ritz.eigenvectors();
    if (previous.size() && ((r.eigenvalues.head(p) - previous.head(p)).cwiseAbs().array() <=
                            params.tolerance * r.eigenvalues.head(p).array().abs())
                               .all()) {
      r.converged = true;
      break;
    }
    previous = r.eigenvalues;
  }
  r.iterations = std::min(r.iterations, params.max_iterations);
  r.first_repeated = q > 1 && r.eigenvalues[1] - r.eigenvalues[0] <= params.repeated * std::abs(r.eigenvalues[0]);
  r.block = r.shapes;
  r.eigenvalues.conservativeResize(p);
  r.shapes.conservativeResize(Eigen::NoChange, p);
  r.frequencies = r.eigenvalues.cwiseMax(0).cwiseSqrt() / (2 * M_PI);
  return r;
}

}  // namespace topopt::fem
