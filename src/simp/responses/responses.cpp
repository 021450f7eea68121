// Displacement responses and the MMA terms of each objective (see responses.h).
#include "simp/responses/responses.h"

#include <algorithm>
#include <cmath>

#include "common/error.h"

namespace topopt::simp {

VecXd face_displacement(ComplianceProblem& problem, const DisplacementLimit& limit, Eigen::MatrixXd* grad) {
  const Eigen::MatrixXd& U = problem.displacements();
  const VecXd u = U.transpose() * limit.gauge;
  if (!grad) return u;
  const VecXd lambda = problem.elasticity().solve(limit.gauge).col(0);
  grad->resize(static_cast<long>(problem.design().size()), U.cols());
  for (long k = 0; k < U.cols(); ++k)
    grad->col(k) =
        problem.to_variables(problem.load_derivative(lambda, k) - problem.stiffness_derivative(lambda, U.col(k)));
  return u;
}

int Responses::constraints(int num_cases) const {
  const ResponseParams& r = params_.responses;
  const int base = r.objective != Objective::Mass ? 1 : (r.compliance_limit > 0 ? 1 : 0);
  return base + static_cast<int>(r.displacements.size()) * num_cases + (r.stress_limit > 0 ? num_cases : 0);
}

MmaTerms Responses::terms(ComplianceProblem& problem, double c, const VecXd& dc, double vol, const VecXd& dv) {
  const ResponseParams& r = params_.responses;
  const long num_cases = problem.displacements().cols();
  MmaTerms t;
  t.f.resize(constraints(static_cast<int>(num_cases)));
  t.df.resize(t.f.size(), dc.size());
  int row = 0;
  add_objective(problem, t, row, c, dc, vol, dv);
  for (const DisplacementLimit& limit : r.displacements) {
    Eigen::MatrixXd du;
    const VecXd u = face_displacement(problem, limit, &du);
    const double l2 = limit.limit * limit.limit;
    for (long k = 0; k < num_cases; ++k) {
      t.f[row] = u[k] * u[k] / l2 - 1;
      t.df.row(row++) = (2 * u[k] / l2) * du.col(k).transpose();
    }
    t.displacements.push_back(u.cwiseAbs().maxCoeff());
  }
  if (r.stress_limit > 0) add_stress(problem, t, row);
  return t;
}

void Responses::add_objective(ComplianceProblem& problem, MmaTerms& t, int& row, double c, const VecXd& dc, double vol,
                              const VecXd& dv) {
  const ResponseParams& r = params_.responses;
  if (r.objective == Objective::Mass) {
    t.f0 = vol, t.df0 = dv, t.objective = vol;
    if (r.compliance_limit > 0) {
      t.f[row] = c / r.compliance_limit - 1;
      t.df.row(row++) = dc.transpose() / r.compliance_limit;
    }
    return;
  }
  t.f[row] = vol / params_.volume_fraction - 1;
  t.df.row(row++) = dv.transpose() / params_.volume_fraction;
  if (r.objective == Objective::Compliance) {
    // objective scaled to about 1 so MMA's regularisation terms are well sized
    const double s = 1.0 / std::max(1e-300, std::abs(c));
    t.f0 = c * s, t.df0 = dc * s, t.objective = c;
    return;
  }
  VecXd grad;
  const fem::ModalResult modes = first_eigenvalue(problem, material_.density, r, modes_, &grad);
  const double lambda = modes.eigenvalues[0];
  if (first_eigenvalue_ <= 0) first_eigenvalue_ = std::max(1e-300, std::abs(lambda));
  t.f0 = -lambda / first_eigenvalue_, t.df0 = -grad / first_eigenvalue_, t.objective = lambda;
  t.frequency = modes.frequencies[0], t.repeated = modes.first_repeated;
}

void Responses::add_stress(ComplianceProblem& problem, MmaTerms& t, int& row) {
  Eigen::MatrixXd grad;
  VecXd largest;
  const VecXd pn = pnorm_stress(problem, params_.responses, &grad, &largest);
  const VecXd ratio = largest.cwiseQuotient(pn.cwiseMax(1e-300));
  stress_scale_ = stress_scale_.size() ? VecXd(0.5 * (stress_scale_ + ratio)) : ratio;
  for (long k = 0; k < pn.size(); ++k) {
    t.f[row] = stress_scale_[k] * pn[k] - 1;
    t.df.row(row++) = stress_scale_[k] * grad.col(k).transpose();
  }
  t.stress_relaxed = largest.maxCoeff() * params_.responses.stress_limit;
  const TetMesh& mesh = problem.elasticity().mesh();
  VecXd density = VecXd::Ones(mesh.T.rows());
  const VecXd& rho = problem.physical_densities();
  for (size_t i = 0; i < problem.design().size(); ++i) density[problem.design()[i]] = rho[i];
  t.stress_crisp = crisp_max_von_mises(mesh, material_, supports_, params_.responses.load_cases, density);
}

SimpParams update_settings(const SimpParams& params) {
  SimpParams s = params;
  if (params.responses.stress_limit > 0) {
    s.move = std::min(s.move, 0.05);
    s.projection.beta_max = std::min(s.projection.beta_max, std::max(8.0, s.projection.beta_start));
  }
  return s;
}

void check_responses(const SimpParams& params, long num_dofs) {
  const ResponseParams& r = params.responses;
  if (r.objective == Objective::Mass && r.compliance_limit <= 0 && r.displacements.empty() && r.stress_limit <= 0)
    throw Error(ErrorCode::InvalidParameter,
                "minimising the mass needs a limit: set a compliance limit (N·mm), a displacement limit on a face or a "
                "stress limit (MPa)");
  if (!(r.compliance_limit >= 0) || !std::isfinite(r.compliance_limit))
    throw Error(ErrorCode::InvalidParameter, "the compliance limit must be a positive number (N·mm), or 0 for none");
  for (const DisplacementLimit& d : r.displacements) {
    if (!(d.limit > 0) || !std::isfinite(d.limit))
      throw Error(ErrorCode::InvalidParameter, "the displacement limit of " + d.name + " must be positive (mm)");
    if (d.gauge.size() != num_dofs || d.gauge.isZero())
      throw Error(
          ErrorCode::InvalidParameter,
          "the displacement limit of " + d.name + " has no gauge on the mesh: give a face of the part and a direction");
  }
  if (r.stress_limit > 0 &&
      !(r.stress_pnorm >= 2 && r.stress_pnorm <= 64 && r.stress_relaxation > 0 && r.stress_relaxation <= 1))
    throw Error(ErrorCode::InvalidParameter,
                "the stress limit needs a p-norm exponent in [2, 64] (8 is usual) and a relaxation exponent in (0, 1] "
                "(0.5 is usual)");
  if (r.stress_limit > 0 && r.load_cases.empty())
    throw Error(ErrorCode::InvalidParameter,
                "the stress limit needs the load cases of the loads (responses.load_cases) for the crisp design's "
                "stress");
  if (r.needs_mma() && params.update != UpdateKind::MMA)
    throw Error(ErrorCode::InvalidParameter,
                "a mass objective, a displacement limit or a stress limit needs the MMA update (\"update\": \"mma\"); "
                "optimality criteria handle one volume constraint only");
}

}  // namespace topopt::simp
