// The p-norm stress response and the crisp design's largest stress (see stress.h).
#include "simp/responses/stress.h"

#include <algorithm>
#include <cmath>

#include "fem/kept_part.h"

namespace topopt::simp {
namespace {

/// η(ρ) = ρ^q and its derivative; below 1e-6 it stays at its value there (η' = 0), as ρ^q's
/// slope is unbounded at 0.
struct Relaxation {
  double q;
  double value(double rho) const { return std::pow(std::max(rho, 1e-6), q); }
  double derivative(double rho) const { return rho < 1e-6 ? 0.0 : q * std::pow(rho, q - 1); }
};

}  // namespace

VecXd pnorm_stress(ComplianceProblem& problem, const ResponseParams& params, Eigen::MatrixXd* grad, VecXd* largest) {
  const Eigen::MatrixXd& U = problem.displacements();
  const std::vector<int>& design = problem.design();
  const VecXd& rho = problem.physical_densities();
  const Relaxation eta{params.stress_relaxation};
  const double P = params.stress_pnorm, limit = params.stress_limit;
  const long nt = problem.elasticity().mesh().T.rows();
  VecXd relax = VecXd::Ones(nt);  // η of each tet, 1 off the design
  for (size_t i = 0; i < design.size(); ++i) relax[design[i]] = eta.value(rho[i]);
  VecXd out(U.cols());
  if (largest) largest->resize(U.cols());
  if (grad) grad->resize(static_cast<long>(design.size()), U.cols());
  for (long k = 0; k < U.cols(); ++k) {
    const VecXd vm0 = problem.elasticity().solid_von_mises(U.col(k)) / limit;
    const VecXd s = relax.cwiseProduct(vm0);
    const double top = s.maxCoeff();
    if (largest) (*largest)[k] = top;
    // (Σ s^P)^(1/P) = top (Σ (s/top)^P)^(1/P), without overflow
    const double sum = top > 0 ? (s / top).array().pow(P).sum() : 0;
    out[k] = top * std::pow(sum, 1 / P);
    if (!grad || !(top > 0)) {
      if (grad) grad->col(k).setZero();
      continue;
    }
    // ∂g/∂s_e = (s_e / g)^(P−1)
    const VecXd dg_ds = (s / out[k]).array().pow(P - 1);
    const VecXd lambda =
        problem.elasticity()
            .solve(problem.elasticity().solid_von_mises_gradient(U.col(k), dg_ds.cwiseProduct(relax) / limit))
            .col(0);
    VecXd d_bar(design.size());
    for (size_t i = 0; i < design.size(); ++i) d_bar[i] = dg_ds[design[i]] * eta.derivative(rho[i]) * vm0[design[i]];
    d_bar += problem.load_derivative(lambda, k) - problem.stiffness_derivative(lambda, U.col(k));
    grad->col(k) = problem.to_variables(d_bar);
  }
  return out;
}

double crisp_max_von_mises(const TetMesh& mesh, const fem::Material& material, const fem::Supports& supports,
                           const std::vector<fem::LoadCase>& cases, const VecXd& density, double threshold,
                           double e_min) {
  VecXd scale(mesh.T.rows());
  std::vector<char> solid(mesh.T.rows());
  for (long t = 0; t < scale.size(); ++t) solid[t] = density[t] >= threshold, scale[t] = solid[t] ? 1.0 : e_min;
  const Eigen::MatrixXd loads = fem::make_loads(fem::kept_part(mesh, solid), material, cases);
  fem::SolverParams exact;
  exact.recycle_factor = false;
  fem::Elasticity fe(mesh, material, supports, exact);
  fe.set_scale(scale);
  const Eigen::MatrixXd U = fe.solve(loads);
  double top = 0;
  for (long k = 0; k < U.cols(); ++k) {
    const VecXd vm = fe.solid_von_mises(U.col(k));
    for (long t = 0; t < vm.size(); ++t)
      if (scale[t] == 1.0) top = std::max(top, vm[t]);
  }
  return top;
}

}  // namespace topopt::simp
