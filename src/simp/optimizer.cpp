// The SIMP loop (see optimizer.h).
#include "simp/optimizer.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "common/blas_threads.h"
#include "mesh/core/tet_components.h"
#include "common/error.h"
#include "simp/controls/design_map.h"
#include "simp/controls/draw_filter.h"
#include "simp/controls/overhang_filter.h"
#include "simp/density_filter.h"
#include "simp/responses/responses.h"
#include "simp/update.h"

namespace topopt::simp {

double filter_radius(const TetMesh& mesh, const FilterParams& params) {
  return params.radius > 0 ? params.radius : 1.5 * mean_edge_length(mesh);
}

void check_params(const SimpParams& params) {
  if (params.max_iterations < 1) throw Error(ErrorCode::InvalidParameter, "the iteration cap must be at least 1");
  const ProjectionParams& p = params.projection;
  if (p.enabled && !(p.beta_start >= 1 && p.beta_max >= p.beta_start && p.beta_factor > 1 &&
                     p.max_iterations_per_beta >= 1 && p.settle_iterations >= 1 && p.eta > 0 && p.eta < 1))
    throw Error(ErrorCode::InvalidParameter,
                "the projection needs 1 <= beta_start <= beta_max, a factor above 1, at least one iteration per "
                "beta and a threshold eta in (0, 1)");
  if (params.sensitivity_filter && params.controls.any())
    throw Error(
        ErrorCode::InvalidParameter,
        "the geometry controls (symmetry, cyclic, pattern, extrusion, draw direction, overhang) work with the density "
        "filter: turn the sensitivity filter off");
  if (params.controls.member.max_size > 0 && params.update != UpdateKind::MMA)
    throw Error(ErrorCode::InvalidParameter,
                "controls.max_member_size needs the MMA update (a local volume constraint beside the volume "
                "fraction): set \"update\": \"mma\"");
}

void check_volume_fraction(double volume_fraction, const std::string& name) {
  if (!(volume_fraction > 0 && volume_fraction < 1))
    throw Error(ErrorCode::InvalidParameter,
                name + " must lie strictly between 0 and 1 (the share of the design domain to keep, e.g. 0.3)");
}

ComplianceProblem::ComplianceProblem(const TetMesh& mesh, const fem::Material& material, const fem::Supports& supports,
                                     const Eigen::MatrixXd& loads, const std::vector<double>& weights,
                                     const SimpParams& params, const Progress& progress,
                                     const Eigen::Matrix3Xd& gravity)
    : mesh_(mesh), params_(params), loads_(loads), weights_(weights), progress_(progress) {
  proj_.eta = params.projection.eta;
  proj_.beta = params.projection.enabled ? params.projection.beta_start : 1.0;
  const MemberSizeParams& member = params.controls.member;
  robust_ = member.min_size > 0;
  eta_ = robust_ ? robust_thresholds(proj_.eta, member.eta_shift) : RobustThresholds{proj_.eta, proj_.eta, proj_.eta};
  check_volume_fraction(params.volume_fraction);
  if (!(params.law.penalty >= 1)) throw Error(ErrorCode::InvalidParameter, "the SIMP penalty must be at least 1");
  const long nt = mesh.T.rows();
  for (long t = 0; t < nt; ++t)
    if (mesh.domain.size() != nt || mesh.domain[t] == 0) design_.push_back(static_cast<int>(t));
  const int num_design = static_cast<int>(design_.size());
  if (num_design == 0)
    throw Error(ErrorCode::InvalidParameter, "the mesh has no design elements: the non-design solids fill the part");
  if (weights_.empty()) weights_.assign(loads.cols(), 1.0);
  const VecXd volume = tet_volumes(mesh);
  vd_.resize(num_design);
  for (int i = 0; i < num_design; ++i) vd_[i] = volume[design_[i]];
  design_volume_ = vd_.sum();
  check_member_size(member, mean_edge_length(mesh), params.projection.enabled);
  FilterParams fp = params.filter;
  fp.radius =
      robust_ ? robust_filter_radius(member.min_size, fp.kind, eta_, fp.like_gaussian) : filter_radius(mesh, fp);
  fp.pad_free_faces = robust_ && member.pad_faces;  // a member along a free face held too (member_size.h)
  fp.pad_weight = member.pad_weight;
  filter_ = make_filter(mesh, design_, volume, fp, progress,
                        fp.pad_free_faces ? unpadded_nodes(mesh, supports.dofs, loads, member) : std::vector<char>{});
  progress.info("filter: " + filter_->describe());
  const double tolerance = params.controls.tolerance > 0 ? params.controls.tolerance : mean_edge_length(mesh);
  controls_ = std::make_unique<DesignMap>(mesh, design_, params.controls, tolerance);
  if (params.controls.ties()) progress.info("controls: " + controls_->describe());
  if (params.controls.draw.enabled) {
    const double cell = params.controls.draw.cell > 0 ? params.controls.draw.cell : tolerance;
    draw_ = std::make_unique<DrawFilter>(mesh, design_, vd_, params.controls.draw, cell);
    progress.info("controls: " + draw_->describe());
  }
  if (params.controls.overhang.enabled) {
    const double cell = params.controls.overhang.cell > 0 ? params.controls.overhang.cell : tolerance;
    overhang_ = std::make_unique<OverhangFilter>(mesh, design_, params.controls.overhang, cell);
    progress.info("controls: " + overhang_->describe());
  }
  // self-weight: loads holds every tet's full weight; a design tet's share scales with ρ̄
  if (gravity.size() && !gravity.isZero()) {
    if (gravity.cols() != loads.cols())
      throw Error(ErrorCode::InvalidParameter, "self-weight: one gravity vector per load case is needed");
    gravity_ = gravity;
    quarter_mass_ = material.density * vd_ / 4;
    if (params_.law.linear_below <= 0) params_.law.linear_below = 0.1;
  }
  fe_ = std::make_unique<fem::Elasticity>(mesh, material, supports, params.solver);
  scale_ = VecXd::Ones(nt);
  if (!params.projection.enabled && !draw_ && !overhang_)
    volume_weights_ = controls_->apply_transpose(params.sensitivity_filter
                                                     ? vd_
                                                     : filter_->apply_transpose(controls_->orbit_mean_transpose(vd_))) /
                      design_volume_;
}

ComplianceProblem::~ComplianceProblem() = default;

void ComplianceProblem::set_solver_tolerance(double tolerance) { fe_->set_solver_tolerance(tolerance); }

ComplianceProblem::Stages ComplianceProblem::filtered(const VecXd& x) const {
  Stages s;
  const VecXd z = controls_->apply(x);
  s.filtered = params_.sensitivity_filter ? z : controls_->orbit_mean(filter_->apply(z));
  s.drawn = draw_ ? draw_->apply(s.filtered) : s.filtered;
  s.tilde = overhang_ ? overhang_->apply(s.drawn) : s.drawn;
  return s;
}

const ComplianceProblem::Stages& ComplianceProblem::filtered(const VecXd& x, Stages& scratch) const {
  if (x.size() == staged_x_.size() && x == staged_x_) return stages_;
  scratch = filtered(x);
  return scratch;
}

VecXd ComplianceProblem::project(const VecXd& rho_tilde, double eta) const {
  if (!params_.projection.enabled) return rho_tilde;
  Heaviside h = proj_;
  h.eta = eta;
  VecXd rho_bar(rho_tilde.size());
  for (long i = 0; i < rho_bar.size(); ++i) rho_bar[i] = h.value(rho_tilde[i]);
  return rho_bar;
}

int ComplianceProblem::num_variables() const { return controls_->num_variables(); }

VecXd ComplianceProblem::design_field(const VecXd& x) const { return controls_->apply(x); }

VecXd ComplianceProblem::physical(const VecXd& x) const { return project(filtered(x).tilde, eta_.intermediate); }

VecXd ComplianceProblem::physical_to_variables(const VecXd& x, const VecXd& d) const {
  return chain(filtered(x), d, eta_.intermediate);
}

double ComplianceProblem::compliance(const VecXd& x, VecXd* dc) {
  const int num_design = static_cast<int>(design_.size());
  stages_ = filtered(x);
  staged_x_ = x;
  rho_bar_ = project(stages_.tilde, eta_.eroded);
  if (robust_)  // the dilated volume's bound follows the intermediate design (Wang et al. 2011)
    volume_scale_ = volume_of(project(stages_.tilde, eta_.intermediate)) /
                    std::max(1e-300, volume_of(project(stages_.tilde, eta_.dilated)));
  // ---- FE analysis
  for (int i = 0; i < num_design; ++i) scale_[design_[i]] = params_.law.stiffness(rho_bar_[i]);
  fe_->set_scale(scale_);
  // loads: the design tets' weight scaled by ρ̄ (loads_ holds it at ρ̄ = 1), spread to 4 nodes
  Eigen::MatrixXd F = loads_;
  if (gravity_.size())
    for (int i = 0; i < num_design; ++i)
      for (long k = 0; k < F.cols(); ++k)
        for (int a = 0; a < 4; ++a)
          F.block<3, 1>(3 * mesh_.T(design_[i], a), k) += (rho_bar_[i] - 1) * quarter_mass_[i] * gravity_.col(k);
  U_ = fe_->solve(F, progress_);
  // ---- objective c = Σ w Fᵀ U and its sensitivities (w.r.t. ρ̄):
  // dc/dρ̄ = Σ w (2 uᵀ dF/dρ̄ − E'(ρ̄) uᵀ K₀ u) for each element
  double c = 0;
  VecXd dc_bar = VecXd::Zero(num_design);
  for (long k = 0; k < F.cols(); ++k) {
    c += weights_[k] * F.col(k).dot(U_.col(k));
    if (dc) dc_bar += weights_[k] * (load_derivative(2 * U_.col(k), k) - stiffness_derivative(U_.col(k), U_.col(k)));
  }
  if (dc) *dc = chain(stages_, dc_bar, eta_.eroded);
  return c;
}

VecXd ComplianceProblem::chain(const Stages& s, VecXd d_bar, double eta) const {
  if (params_.projection.enabled) {
    Heaviside h = proj_;
    h.eta = eta;
    for (long i = 0; i < d_bar.size(); ++i) d_bar[i] *= h.derivative(s.tilde[i]);
  }
  if (overhang_) d_bar = overhang_->apply_transpose(s.drawn, d_bar);
  if (draw_) d_bar = draw_->apply_transpose(s.filtered, d_bar);
  return controls_->apply_transpose(
      params_.sensitivity_filter ? d_bar : filter_->apply_transpose(controls_->orbit_mean_transpose(d_bar)));
}

VecXd ComplianceProblem::stiffness_derivative(const VecXd& a, const VecXd& b) const {
  // aᵀK0b per element by polarisation: ((a+b)ᵀK0(a+b) − (a−b)ᵀK0(a−b)) / 4
  const bool same = &a == &b || a == b;
  const VecXd energy =
      same ? fe_->element_energy(a) : VecXd((fe_->element_energy(a + b) - fe_->element_energy(a - b)) / 4);
  VecXd d(design_.size());
  for (long i = 0; i < d.size(); ++i) d[i] = params_.law.derivative(rho_bar_[i]) * energy[design_[i]];
  return d;
}

VecXd ComplianceProblem::load_derivative(const VecXd& w, long k) const {
  VecXd d = VecXd::Zero(design_.size());
  if (!gravity_.size()) return d;
  for (long i = 0; i < d.size(); ++i) {
    Eigen::Vector3d w_sum = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) w_sum += w.segment<3>(3 * mesh_.T(design_[i], a));
    d[i] = quarter_mass_[i] * gravity_.col(k).dot(w_sum);
  }
  return d;
}

double ComplianceProblem::volume_fraction(const VecXd& x, VecXd* dv) const {
  if (volume_weights_.size()) {  // linear: cheap enough for OC's bisection
    if (dv) *dv = volume_weights_;
    return volume_weights_.dot(x);
  }
  // with a minimum member size: the dilated design's volume, scaled (volume_scale_)
  Stages scratch;
  const Stages& s = filtered(x, scratch);
  if (dv) *dv = volume_scale_ * chain(s, vd_ / design_volume_, eta_.dilated);
  return volume_scale_ * volume_of(project(s.tilde, eta_.dilated));
}

double ComplianceProblem::grey_share(const VecXd& x) const { return grey_of(physical(x)); }

double ComplianceProblem::last_grey_share() const {
  // the physical design is the intermediate one: rho_bar_ itself unless robust (then the eroded)
  return grey_of(robust_ ? project(stages_.tilde, eta_.intermediate) : rho_bar_);
}

double ComplianceProblem::grey_of(const VecXd& rho_bar) const {
  double grey = 0;
  for (long i = 0; i < rho_bar.size(); ++i)
    if (rho_bar[i] > 0.1 && rho_bar[i] < 0.9) grey += vd_[i];
  return grey / design_volume_;
}

VecXd ComplianceProblem::filter_sensitivity(const VecXd& x, const VecXd& dc) const {
  return filter_->filter_sensitivity(x, dc);
}

namespace {

/// Move limits for OC: adaptive with the projection (a projected design flips its boundary
/// variables by the full limit otherwise), the one fixed limit without it.
MoveLimits move_limits(const SimpParams& params, int num_design) {
  if (params.projection.enabled) return MoveLimits(num_design, params.move);
  return MoveLimits(num_design, params.move, params.move, 1, 1);
}

/// The design update of one iteration: OC with move limits that shrink where the design
/// oscillates, or MMA; both keep what they need from earlier iterations.
class DesignUpdate {
 public:
  DesignUpdate(const SimpParams& params, int num_design, int num_constraints)
      : params_(params), mma_(num_design, num_constraints, params.move), moves_(move_limits(params, num_design)) {}

  /// The next design from x (#D) with compliance sensitivities dc, the volume fraction vol at x
  /// and its sensitivities dv (#D) for OC, or the objective and constraints `mma`
  /// (responses/responses.h) for MMA. OC bisects on the volume linearised at x and corrects
  /// the multiplier on the real volume, which it meets as the exact bisection does (update.h).
  VecXd step(const ComplianceProblem& problem, const VecXd& x, double vol, const VecXd& dc, const VecXd& dv,
             const MmaTerms& mma) {
    if (params_.update == UpdateKind::OC) {
      auto excess = [&](const VecXd& xn) { return problem.volume_fraction(xn) - params_.volume_fraction; };
      const OcLinearisation linear{vol - params_.volume_fraction, {}};
      return oc_update(x, dc, dv.cwiseMax(1e-30), moves_.at(x), excess, &multiplier_, &linear);
    }
    return mma_.update(x, mma.f0, mma.df0, mma.f, mma.df);
  }

  /// The problem changed (β raised): the oscillation history no longer applies.
  void restart() {
    mma_.restart();
    moves_.restart();
  }

 private:
  const SimpParams& params_;
  Mma mma_;
  MoveLimits moves_;
  double multiplier_ = 0;  // OC's last Lagrange multiplier: where the next bisection starts
};

/// The maximum member size's constraint (member_size.h) appended to MMA's terms at x (#N),
/// when one is set (`local` not null).
void add_local_volume(const ComplianceProblem& problem, LocalVolumeConstraint* local, const VecXd& x, MmaTerms& t) {
  if (!local) return;
  VecXd grad;
  const VecXd rho = problem.physical(x);
  local->adapt(rho);
  const double f = local->evaluate(rho, &grad);
  const long m = t.f.size();
  t.f.conservativeResize(m + 1);
  t.df.conservativeResize(m + 1, x.size());
  t.f[m] = f;
  t.df.row(m) = problem.physical_to_variables(x, grad).transpose();
}

/// Keeps an iteration in the history and reports it (callback and progress line).
void report_iteration(const IterationRecord& rec, int max_iterations, SimpResult& res,
                      const std::function<void(const IterationRecord&)>& on_iteration, const Progress& progress) {
  res.history.push_back(rec);
  if (on_iteration) on_iteration(rec);
  std::ostringstream msg;
  msg << "iteration " << rec.iteration << ": compliance " << rec.compliance << ", volume " << rec.volume_fraction
      << ", change " << rec.change;
  for (double u : rec.displacements) msg << ", displacement " << u << " mm";
  if (rec.stress_relaxed > 0)
    msg << ", stress " << rec.stress_relaxed << " MPa relaxed, " << rec.stress_crisp << " MPa crisp";
  if (rec.frequency > 0)
    msg << ", first eigenfrequency " << rec.frequency << " Hz" << (rec.repeated ? " (repeated)" : "");
  if (rec.beta != 1) msg << ", beta " << rec.beta << ", grey " << 100 * rec.grey << " %";
  progress.say("simp", static_cast<double>(rec.iteration) / max_iterations, msg.str());
}

/// With a minimum member size: whether the eroded design (the physical densities `eroded`, #D, of
/// the design tets `design`) joins the supports to the loads — its tets at ρ̄ ≥ ½ and the
/// non-design tets, joined when they share a node (mesh::node_components, the hygiene's rule for
/// crisp pieces), hold a piece that touches a supported node (`supported_dofs`, 3 per node) and a
/// loaded one (`loads`, 3#V by cases).
bool eroded_design_joins(const TetMesh& mesh, const std::vector<int>& design, const VecXd& eroded,
                         const std::vector<int>& supported_dofs, const Eigen::MatrixXd& loads) {
  const long nt = mesh.T.rows(), nv = mesh.V.rows();
  std::vector<char> solid(static_cast<size_t>(nt), 1), supported(static_cast<size_t>(nv), 0),
      loaded(static_cast<size_t>(nv), 0);
  for (size_t i = 0; i < design.size(); ++i) solid[design[i]] = eroded[static_cast<long>(i)] >= 0.5;
  for (int dof : supported_dofs) supported[dof / 3] = 1;
  for (long i = 0; i < loads.rows() && i / 3 < nv; ++i)
    if (loads.row(i).cwiseAbs().maxCoeff() > 0) loaded[i / 3] = 1;
  int count = 0;
  const VecXi piece = mesh::node_components(mesh, solid, count);
  std::vector<char> holds_support(static_cast<size_t>(count), 0), holds_load(static_cast<size_t>(count), 0);
  for (long t = 0; t < nt; ++t)
    for (int a = 0; a < 4 && piece[t] >= 0; ++a) {
      holds_support[piece[t]] |= supported[mesh.T(t, a)];
      holds_load[piece[t]] |= loaded[mesh.T(t, a)];
    }
  for (int c = 0; c < count; ++c)
    if (holds_support[c] && holds_load[c]) return true;
  return false;
}

/// With a minimum member size: warns, in the user's terms, when the eroded design (the one
/// analysed) has come apart: its last compliance above 1e3 × the lowest of the run (E_min carries
/// the load then; the first iteration's is no reference: at a low volume its eroded design is
/// weak already), or, below that, `joined` false (eroded_design_joins: grey tets bridge a gap and
/// the compliance reads only tens of times the lowest — the bench's cantilever at 6 mm, 40 ×).
/// Either way no member of that size carries the load within the part and the volume fraction.
void warn_if_eroded_apart(const SimpParams& params, const SimpResult& res, bool joined, const Progress& progress) {
  if (params.controls.member.min_size <= 0 || res.history.size() < 2) return;
  double lowest = res.history.front().compliance;
  for (const IterationRecord& r : res.history) lowest = std::min(lowest, r.compliance);
  std::ostringstream msg;
  msg << "controls.min_member_size " << params.controls.member.min_size << " mm: ";
  if (res.history.back().compliance > 1e3 * lowest)
    msg << "the eroded design came apart (compliance " << res.history.back().compliance << ", " << lowest
        << " at its lowest)";
  else if (!joined)
    msg << "the eroded design (the thinnest of the three the size is imposed through) does not join the supports "
           "to the loads (compliance "
        << res.history.back().compliance << ", " << lowest
        << " at its lowest), so members there may be thinner than the size";
  else
    return;
  msg << ": no member of that size carries the load within the part and the volume fraction; raise the volume "
         "fraction or lower the size";
  progress.warn(msg.str());
}

}  // namespace

SimpResult optimize(const TetMesh& mesh, const fem::Material& material, const fem::Supports& supports,
                    const Eigen::MatrixXd& loads, const std::vector<double>& weights, const SimpParams& params,
                    const Progress& progress, const std::function<void(const IterationRecord&)>& on_iteration,
                    const Eigen::Matrix3Xd& gravity) {
  check_params(params);
  // One BLAS thread for the whole loop. CHOLMOD's BLAS calls (factorisations, triangular solves
  // in the recycled-factor CG and the multigrid's coarse level) come between our own threaded
  // work every iteration, and OpenBLAS's idle workers spin (sched_yield, futex) after each call,
  // taking the cores that work needs. Measured on the cantilever (63 k tets, 30 iterations,
  // 2 threads, Debian's OpenBLAS 0.3.21): 24.6 s user + 13.3 s system with OpenBLAS's threads,
  // 21.2 s user + 3.6 s system with one (strace: 390 k futex and 340 k sched_yield calls).
  BlasThreadLimit one_blas_thread(1);
  ComplianceProblem problem(mesh, material, supports, loads, weights, params, progress, gravity);
  SimpResult res;
  res.design = problem.design();
  const int num_design = static_cast<int>(res.design.size());
  check_responses(params, 3 * mesh.V.rows());
  Responses responses(params, material, supports);
  const int num_variables = problem.num_variables();
  const SimpParams stepping = update_settings(params);  // smaller steps under a stress limit
  std::unique_ptr<LocalVolumeConstraint> local;         // the maximum member size
  if (params.controls.member.max_size > 0)
    local = std::make_unique<LocalVolumeConstraint>(mesh, res.design, tet_volumes(mesh), params.controls.member);
  DesignUpdate update(stepping, num_variables, responses.constraints(static_cast<int>(loads.cols())) + (local ? 1 : 0));
  Continuation schedule(stepping.projection, params.tol_change, params.tol_objective);
  VecXd x = VecXd::Constant(num_variables, params.volume_fraction);
  for (int it = 1; it <= params.max_iterations; ++it) {
    const auto t0 = std::chrono::steady_clock::now();
    progress.check_cancel("the optimisation (iteration " + std::to_string(it) + ")");
    problem.set_beta(schedule.beta());
    problem.set_solver_tolerance(solver_tolerance(schedule, params.solver.tolerance, params.early_solver_tolerance));
    // ---- FE analysis, objective and sensitivities
    VecXd dc, dv;
    const double c = problem.compliance(x, &dc);
    const double vol = problem.volume_fraction(x, &dv);
    // ---- filter (sensitivity filtering; the density filter is inside the chain rule)
    if (params.sensitivity_filter) dc = problem.filter_sensitivity(x, dc);
    // ---- update
    MmaTerms mma = params.update == UpdateKind::MMA ? responses.terms(problem, c, dc, vol, dv) : MmaTerms{};
    add_local_volume(problem, local.get(), x, mma);
    const VecXd xnew = update.step(problem, x, vol, dc, dv, mma);
    IterationRecord rec{it,
                        c,
                        vol,
                        (xnew - x).cwiseAbs().maxCoeff(),
                        schedule.beta(),
                        problem.last_grey_share(),
                        0,
                        mma.displacements,
                        mma.stress_relaxed,
                        mma.stress_crisp,
                        mma.frequency,
                        mma.repeated};
    x = xnew;
    rec.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    report_iteration(rec, params.max_iterations, res, on_iteration, progress);
    // ---- continuation and convergence (judged at the final β only)
    const NextStep next = schedule.next(params.update == UpdateKind::MMA ? mma.objective : c, rec.change);
    if (next == NextStep::Converged) {
      res.converged = true;
      res.status = "converged after " + std::to_string(it) + " iterations";
      break;
    }
    if (next == NextStep::RaiseBeta) update.restart();
  }
  if (!res.converged) res.status = "iteration cap (" + std::to_string(params.max_iterations) + ") reached";
  const bool joined = params.controls.member.min_size <= 0 ||
                      eroded_design_joins(mesh, res.design, problem.physical_densities(), supports.dofs, loads);
  warn_if_eroded_apart(params, res, joined, progress);
  res.variables = problem.design_field(x);
  problem.set_beta(schedule.beta());
  const VecXd rho = problem.physical(x);
  res.density = VecXd::Ones(mesh.T.rows());
  for (int i = 0; i < num_design; ++i) res.density[res.design[i]] = rho[i];
  return res;
}

}  // namespace topopt::simp
