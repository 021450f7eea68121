// The distributed SIMP loop (see dist_simp.h).
#include "dist/dist_simp.h"

#include <chrono>
#include <sstream>

#include "common/error.h"
#include "dist/dist_helmholtz.h"
#include "simp/density_filter.h"
#include "simp/helmholtz_filter.h"
#include "simp/update.h"

namespace topopt::dist {
namespace {

double sum_all(const MpiSession& s, double v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_SUM, s.comm());
  return v;
}

double max_all(const MpiSession& s, double v) {
  MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_DOUBLE, MPI_MAX, s.comm());
  return v;
}

/// Compliance and volume as functions of this rank's design variables x (#D local), as
/// simp::ComplianceProblem on one machine; every method is collective.
class DistProblem {
 public:
  DistProblem(const MpiSession& s, const DistMesh& mesh, const fem::Material& material,
              const std::vector<double>& weights, const simp::SimpParams& params, const DistSolverParams& solver)
      : s_(s), mesh_(mesh), params_(params), weights_(weights), fe_(s, mesh, material, solver) {
    for (long t = 0; t < mesh.local.T.rows(); ++t)
      if (mesh.local.domain[t] == 0) design_.push_back(static_cast<int>(t));
    const VecXd volume = simp::tet_volumes(mesh.local);
    vd_.resize(static_cast<long>(design_.size()));
    for (size_t i = 0; i < design_.size(); ++i) vd_[static_cast<long>(i)] = volume[design_[i]];
    design_volume_ = sum_all(s, vd_.sum());
    if (!(design_volume_ > 0))
      throw Error(ErrorCode::InvalidParameter, "the mesh has no design elements: the non-design solids fill the part");
    filter_ = std::make_unique<DistHelmholtz>(
        s, mesh, design_, simp::helmholtz_length(params.filter.radius, params.filter.like_gaussian));
    proj_.eta = params.projection.eta;
    scale_ = VecXd::Ones(mesh.local.T.rows());
    if (!params.projection.enabled) volume_weights_ = filter_->apply_transpose(vd_) / design_volume_;
  }

  const std::vector<int>& design() const { return design_; }
  void set_beta(double beta) { proj_.beta = beta; }
  int solver_iterations() const { return fe_.last_iterations(); }
  int solver_setups() const { return fe_.setups(); }
  void set_solver_tolerance(double tolerance) { fe_.set_tolerance(tolerance); }

  void forward(const VecXd& x, VecXd& rho_tilde, VecXd& rho_bar) const {
    rho_tilde = filter_->apply(x);
    rho_bar = rho_tilde;
    if (params_.projection.enabled)
      for (long i = 0; i < rho_bar.size(); ++i) rho_bar[i] = proj_.value(rho_tilde[i]);
  }

  /// Weighted compliance and its gradient dc (#D local).
  double compliance(const VecXd& x, VecXd& dc) {
    VecXd rho_tilde, rho_bar;
    forward(x, rho_tilde, rho_bar);
    last_grey_ = grey_share(rho_bar);
    for (size_t i = 0; i < design_.size(); ++i) scale_[design_[i]] = params_.law.stiffness(rho_bar[i]);
    fe_.set_scale(scale_);
    const Eigen::MatrixXd U = fe_.solve(mesh_.loads);
    double c = 0;
    VecXd dc_bar = VecXd::Zero(static_cast<long>(design_.size()));
    for (long k = 0; k < mesh_.loads.cols(); ++k) {
      c += weights_[k] * mesh_.loads.col(k).dot(U.col(k).head(mesh_.loads.rows()));
      const VecXd energy = fe_.element_energy(U.col(k));
      for (size_t i = 0; i < design_.size(); ++i)
        dc_bar[i] -= weights_[k] * params_.law.derivative(rho_bar[i]) * energy[design_[i]];
    }
    if (params_.projection.enabled)
      for (long i = 0; i < dc_bar.size(); ++i) dc_bar[i] *= proj_.derivative(rho_tilde[i]);
    dc = filter_->apply_transpose(dc_bar);
    return sum_all(s_, c);
  }

  /// Volume fraction of the design domain with the physical densities, and d/dx if asked.
  double volume_fraction(const VecXd& x, VecXd* dv) const {
    if (volume_weights_.size()) {
      if (dv) *dv = volume_weights_;
      return sum_all(s_, volume_weights_.dot(x));
    }
    VecXd rho_tilde, rho_bar;
    forward(x, rho_tilde, rho_bar);
    if (dv) {
      VecXd g = vd_ / design_volume_;
      for (long i = 0; i < g.size(); ++i) g[i] *= proj_.derivative(rho_tilde[i]);
      *dv = filter_->apply_transpose(g);
    }
    return sum_all(s_, vd_.dot(rho_bar)) / design_volume_;
  }

  /// The grey share of the design of the last compliance() (its physical densities), read off
  /// that analysis as the serial loop does: a filter solve per iteration fewer than filtering x again.
  double last_grey_share() const { return last_grey_; }

 private:
  double grey_share(const VecXd& rho_bar) const {
    double grey = 0;
    for (long i = 0; i < rho_bar.size(); ++i)
      if (rho_bar[i] > 0.1 && rho_bar[i] < 0.9) grey += vd_[i];
    return sum_all(s_, grey) / design_volume_;
  }

  const MpiSession& s_;
  const DistMesh& mesh_;
  simp::SimpParams params_;
  std::vector<double> weights_;
  DistElasticity fe_;
  std::unique_ptr<DistHelmholtz> filter_;
  std::vector<int> design_;
  VecXd vd_, volume_weights_, scale_;
  double design_volume_ = 0, last_grey_ = 0;
  simp::Heaviside proj_;
};

/// The serial answer on rank 0: this rank's design variables and physical densities gathered
/// into the serial mesh's numbering.
void gather_result(const MpiSession& s, const DistMesh& mesh, DistProblem& problem, const VecXd& x,
                   simp::SimpResult& res) {
  VecXd rho_tilde, rho_bar;
  problem.forward(x, rho_tilde, rho_bar);
  VecXd density = VecXd::Ones(mesh.local.T.rows()), variables = VecXd::Zero(mesh.local.T.rows());
  for (size_t i = 0; i < problem.design().size(); ++i) {
    density[problem.design()[i]] = rho_bar[static_cast<long>(i)];
    variables[problem.design()[i]] = x[static_cast<long>(i)];
  }
  VecXd domain(mesh.local.T.rows());
  for (long t = 0; t < domain.size(); ++t) domain[t] = mesh.local.domain[t];
  res.density = gather_tets(s, mesh, density);
  const VecXd all_variables = gather_tets(s, mesh, variables);
  const VecXd all_domains = gather_tets(s, mesh, domain);
  if (s.rank() != 0) return;
  std::vector<double> kept;
  for (long t = 0; t < res.density.size(); ++t)
    if (all_domains[t] == 0) res.design.push_back(static_cast<int>(t)), kept.push_back(all_variables[t]);
  res.variables = Eigen::Map<const VecXd>(kept.data(), static_cast<long>(kept.size()));
}

}  // namespace

void check_distributable(const simp::SimpParams& params, bool gravity) {
  if (params.update != simp::UpdateKind::OC)
    throw Error(ErrorCode::InvalidParameter,
                "under mpirun the design update is OC only: set \"update\": \"oc\" or run without mpirun for MMA");
  if (params.sensitivity_filter)
    throw Error(ErrorCode::InvalidParameter,
                "under mpirun the sensitivity filter is not available: remove \"sensitivity_filter\" or run "
                "without mpirun");
  if (gravity)
    throw Error(ErrorCode::InvalidParameter,
                "under mpirun self-weight (a \"gravity\" load) is not available yet: remove it or run without mpirun");
  if (params.controls.any())
    throw Error(ErrorCode::InvalidParameter,
                "under mpirun the geometry controls are not available yet: remove \"controls\" or run without mpirun");
  if (params.responses.objective != simp::Objective::Compliance || params.responses.stress_limit > 0 ||
      !params.responses.displacements.empty())
    throw Error(ErrorCode::InvalidParameter,
                "under mpirun only compliance under a volume fraction is optimised: remove \"objective\" and the "
                "limits, or run without mpirun");
}

simp::SimpResult optimize_mesh(const MpiSession& session, const DistMesh& mesh, const fem::Material& material,
                               const std::vector<double>& weights, const simp::SimpParams& params,
                               const DistSolverParams& solver, const Progress& progress,
                               const std::function<void(const simp::IterationRecord&)>& on_iteration) {
  DistProblem problem(session, mesh, material, weights, params, solver);
  const int num_design = static_cast<int>(problem.design().size());
  simp::MoveLimits moves = params.projection.enabled ? simp::MoveLimits(num_design, params.move)
                                                     : simp::MoveLimits(num_design, params.move, params.move, 1, 1);
  simp::Continuation schedule(params.projection, params.tol_change, params.tol_objective);
  simp::SimpResult res;
  VecXd x = VecXd::Constant(num_design, params.volume_fraction);
  for (int it = 1; it <= params.max_iterations; ++it) {
    const auto t0 = std::chrono::steady_clock::now();
    problem.set_beta(schedule.beta());
    problem.set_solver_tolerance(
        simp::solver_tolerance(schedule, solver.tolerance, params.early_solver_tolerance));
    // ---- FE analysis, objective and sensitivities (through filter and projection)
    VecXd dc, dv;
    const double c = problem.compliance(x, dc);
    const double vol = problem.volume_fraction(x, &dv);
    // ---- update: OC, its multiplier's bisection on the global volume linearised at x (one
    // all-reduce a step), corrected on the real global volume as the serial loop does
    auto excess = [&](const VecXd& xn) { return problem.volume_fraction(xn, nullptr) - params.volume_fraction; };
    const simp::OcLinearisation linear{vol - params.volume_fraction,
                                       [&](double local) { return sum_all(session, local); }};
    const VecXd xnew = simp::oc_update(x, dc, dv.cwiseMax(1e-30), moves.at(x), excess, nullptr, &linear);
    const double change = max_all(session, num_design ? (xnew - x).cwiseAbs().maxCoeff() : 0.0);
    simp::IterationRecord rec;
    rec.iteration = it, rec.compliance = c, rec.volume_fraction = vol, rec.change = change;
    rec.beta = schedule.beta(), rec.grey = problem.last_grey_share();
    x = xnew;
    rec.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    res.history.push_back(rec);
    if (session.rank() == 0) {
      if (on_iteration) on_iteration(rec);
      std::ostringstream msg;
      msg << "iteration " << it << ": compliance " << c << ", volume " << vol << ", change " << change;
      if (rec.beta != 1) msg << ", beta " << rec.beta << ", grey " << 100 * rec.grey << " %";
      msg << " (" << session.size() << " ranks, CG " << problem.solver_iterations() << ", multigrid set-ups "
          << problem.solver_setups() << ")";
      progress.say("simp", static_cast<double>(it) / params.max_iterations, msg.str());
    }
    // ---- continuation and convergence (judged at the final β only)
    const simp::NextStep next = schedule.next(c, change);
    if (next == simp::NextStep::Converged) {
      res.converged = true;
      res.status = "converged after " + std::to_string(it) + " iterations";
      break;
    }
    if (next == simp::NextStep::RaiseBeta) moves.restart();
  }
  if (!res.converged) res.status = "iteration cap (" + std::to_string(params.max_iterations) + ") reached";
  problem.set_beta(schedule.beta());
  gather_result(session, mesh, problem, x, res);
  return res;
}

}  // namespace topopt::dist
