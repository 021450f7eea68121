// The first eigenvalue as a SIMP response (see frequency.h).
#include "simp/responses/frequency.h"

#include "simp/density_filter.h"

namespace topopt::simp {

fem::ModalResult first_eigenvalue(ComplianceProblem& problem, double density, const ResponseParams& params,
                                  Eigen::MatrixXd& warm, VecXd* grad) {
  const std::vector<int>& design = problem.design();
  const VecXd& rho = problem.physical_densities();
  const TetMesh& mesh = problem.elasticity().mesh();
  const MassLaw law;
  VecXd factor = VecXd::Ones(mesh.T.rows());
  for (size_t i = 0; i < design.size(); ++i) factor[design[i]] = law.value(rho[i]);
  fem::ModalParams mp;
  mp.modes = 2;
  mp.tolerance = params.eigen_tolerance;
  mp.repeated = 1e-3;
  const fem::ModalResult r = lowest_modes(problem.elasticity(), density, factor, mp, {}, warm);
  warm = r.block;
  if (!grad) return r;
  const VecXd phi = r.shapes.col(0);
  const double lambda = r.eigenvalues[0];
  // φ_iᵀ M0_i φ_i = ρ vol / 20 (Σ_a |φ_a|² + |Σ_a φ_a|²)
  const VecXd vol = tet_volumes(mesh);
  VecXd d_bar = problem.stiffness_derivative(phi, phi);
  for (size_t i = 0; i < design.size(); ++i) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double squares = 0;
    for (int a = 0; a < 4; ++a) {
      const Eigen::Vector3d p = phi.segment<3>(3 * mesh.T(design[i], a));
      sum += p, squares += p.squaredNorm();
    }
    d_bar[i] -= lambda * law.derivative(rho[i]) * density * vol[design[i]] / 20 * (squares + sum.squaredNorm());
  }
  *grad = problem.to_variables(d_bar);
  return r;
}

}  // namespace topopt::simp
