// SIMP topology optimisation on a tagged tet mesh: minimum (weighted) compliance under a
// volume fraction of the design domain. Reads like top88: FE analysis → objective and
// sensitivities → filter → update, with the mesh-dependent parts built once outside the loop.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/progress.h"
#include "common/types.h"
#include "fem/elasticity.h"
#include "simp/continuation.h"
#include "simp/controls/controls_params.h"
#include "simp/controls/member_size.h"
#include "simp/filter.h"
#include "simp/responses/response_params.h"
#include "simp/simp_law.h"

namespace topopt::simp {

enum class UpdateKind { OC, MMA };

struct SimpParams {
  double volume_fraction = 0.3;     ///< of the design domain (Ω0), in (0, 1)
  SimpLaw law;                      ///< penalty 3, e_min 1e-9
  FilterParams filter;              ///< Gaussian; radius <= 0: 1.5 × mean edge length
  bool sensitivity_filter = false;  ///< filter sensitivities instead of densities
  ProjectionParams projection;      ///< Heaviside projection and its β continuation (on)
  UpdateKind update = UpdateKind::OC;
  double move = 0.2;  ///< move limit per iteration
  int max_iterations = 100;
  double tol_change = 0.01;     ///< stop when max |Δx| falls below this
  /// ... or the relative objective change stays below this for 5 iterations (at the final β). At
  /// β = 32 the compliance creeps down by a falling ~1e-4–4e-4 an iteration while the last grey
  /// elements sharpen; 1e-4 spent 5 more iterations on the rocker than 2e-4 for 3.6e-4 of its
  /// compliance (BENCHMARKS.md, branch speed6).
  double tol_objective = 2e-4;
  fem::SolverParams solver;
  /// The iterative solver's relative residual while the projection's β is below its final value
  /// (solver_tolerance() in continuation.h); solver.tolerance from the final β on. At or below
  /// solver.tolerance: the same tolerance throughout.
  /// 1e-2 (branch speed12): the compliances below the final β within 1e-5 of 1e-3's, fewer CG
  /// iterations there; the multigrid sets up a new hierarchy at the change to the final tolerance
  /// only where the first solve there outgrows the setup's count scaled to it (HierarchyReuse::
  /// rebaseline): the rocker (100 k tets) yes, 1 377 -> 1 182 CG iterations + 14 x refreshes; the
  /// cantilever (63 k tets) no, keeping its small coarse level, 793 -> 708.
  double early_solver_tolerance = 1e-2;
  ResponseParams responses;  ///< objective and limits beyond the volume fraction (responses/)
  ControlsParams controls;   ///< geometry controls (symmetry, repetition, extrusion, draw direction, member size)
};

/// One iteration, as reported to the caller and kept in the history.
struct IterationRecord {
  int iteration = 0;
  double compliance = 0;       ///< weighted compliance Σ w_k F_kᵀU_k (N·mm)
  double volume_fraction = 0;  ///< of the design domain, with the physical densities
  double change = 0;           ///< max |Δx|
  double beta = 1;             ///< Heaviside sharpness (1 without projection)
  double grey = 0;             ///< share of the design volume with 0.1 < ρ̄ < 0.9
  double seconds = 0;          ///< wall time of this iteration
  /// Per DisplacementLimit, the largest |u_d| over the load cases (mm); empty without limits.
  std::vector<double> displacements;
  /// With a stress limit: the largest relaxed von Mises stress ρ̄^q σ0 of the elements (MPa),
  /// what the constraint holds ...
  double stress_relaxed = 0;
  /// ... and the largest von Mises stress of this iteration's crisp design (ρ̄ >= 0.5 solid, the
  /// rest void, analysed anew; over its solid tets), what the part will see (MPa).
  double stress_crisp = 0;
  /// Frequency objective: the first eigenfrequency (Hz), and whether the second equals it
  /// (within 0.1 %: the eigenvalue's gradient is then not defined).
  double frequency = 0;
  bool repeated = false;
};

struct SimpResult {
  VecXd density;            ///< #T physical densities ρ̄ (non-design tets 1)
  VecXd variables;          ///< #D design field z: the variables x through the geometry controls
  std::vector<int> design;  ///< #D tet index of each variable
  std::vector<IterationRecord> history;
  bool converged = false;
  std::string status;  ///< "converged after N iterations" / "iteration cap (N) reached"
};

/// The objective and constraint of SIMP as functions of the design variables x (#D): the
/// filter, projection and FE model are built once; compliance() runs one FE analysis.
/// With a minimum member size (controls.member.min_size, the robust formulation of
/// member_size.h) the filter radius follows from that size, the FE analysis and the
/// compliance are the eroded design's, the volume is the dilated design's scaled so that it
/// equals the intermediate's at the x of the last compliance() call (the bound's update of
/// Wang et al. 2011, held fixed in dv), and physical() is the intermediate design.
class DesignMap;
class DrawFilter;
class OverhangFilter;

class ComplianceProblem {
 public:
  /// gravity: 3 by #cases accelerations (mm/s², fem::gravity_of) whose full weight `loads`
  /// holds (fem::make_loads); each design tet's share is scaled by its density, so it weighs
  /// ρ̄ ρ_material vol and a non-design tet its full weight. With any gravity the law turns
  /// linear below ρ̄ = 0.1 unless params set linear_below.
  ComplianceProblem(const TetMesh& mesh, const fem::Material& material, const fem::Supports& supports,
                    const Eigen::MatrixXd& loads, const std::vector<double>& weights, const SimpParams& params,
                    const Progress& progress = {}, const Eigen::Matrix3Xd& gravity = {});
  ~ComplianceProblem();
  /// Number of design variables #N: the design elements #D, fewer when controls tie them.
  int num_variables() const;
  /// The design field z (#D) of the variables x (#N): x through the geometry controls.
  VecXd design_field(const VecXd& x) const;
  /// Weighted compliance c(x) (x: #N) and, if dc is given, dc/dx (#N) through projection,
  /// filter and controls.
  double compliance(const VecXd& x, VecXd* dc = nullptr);
  /// Volume fraction of the design domain with the physical densities, and d/dx (#N) if asked.
  double volume_fraction(const VecXd& x, VecXd* dv = nullptr) const;
  /// Physical densities ρ̄ (#D) of x (#N): the design returned (the intermediate one with a
  /// minimum member size).
  VecXd physical(const VecXd& x) const;
  /// Chain rule of physical(): a sensitivity d (#D) w.r.t. physical(x) turned into one w.r.t. x (#N).
  VecXd physical_to_variables(const VecXd& x, const VecXd& d) const;
  /// Share of the design volume whose physical density ρ̄(x) lies strictly between 0.1 and 0.9.
  double grey_share(const VecXd& x) const;
  /// grey_share of the x of the last compliance() call, from the densities that call filtered
  /// (no filter application of its own: with the Helmholtz filter that is a solve).
  double last_grey_share() const;
  /// Sensitivities of compliance filtered by Sigmund's filter (when params ask for it).
  VecXd filter_sensitivity(const VecXd& x, const VecXd& dc) const;
  const std::vector<int>& design() const { return design_; }
  /// The displacements U ((3*#V) by #cases) of the last compliance() call.
  const Eigen::MatrixXd& displacements() const { return U_; }
  /// #D: the physical densities ρ̄ the last compliance() call analysed (the eroded design with a
  /// minimum member size).
  const VecXd& physical_densities() const { return rho_bar_; }
  /// The FE model (for adjoint solves with the stiffness of the last compliance() call).
  fem::Elasticity& elasticity() { return *fe_; }
  /// Chain rule: a sensitivity w.r.t. the physical densities ρ̄ (#D) of the last compliance()
  /// call's x turned into one w.r.t. the design variables x (#D), through projection and filter.
  VecXd to_variables(const VecXd& d_bar) const { return chain(stages_, d_bar, eta_.eroded); }
  /// #D: E'(ρ̄_i) a_iᵀ K0_i b_i for the densities of the last compliance() call; a, b: 3*#V
  /// (the stiffness term of an adjoint sensitivity, −this for λ = a, u = b).
  VecXd stiffness_derivative(const VecXd& a, const VecXd& b) const;
  /// #D: wᵀ ∂F_k/∂ρ̄_i, the self-weight's share of load case k (zero without gravity); w: 3*#V.
  VecXd load_derivative(const VecXd& w, long k) const;
  void set_beta(double b) { proj_.beta = b; }
  /// The FE solver's relative residual from the next compliance() on (iterative solvers).
  void set_solver_tolerance(double tolerance);

 private:
  const TetMesh& mesh_;
  SimpParams params_;
  std::vector<int> design_;
  VecXd vd_;
  VecXd volume_weights_;  // without projection the volume is linear in x: w·x
  double design_volume_ = 0;
  std::unique_ptr<DesignMap> controls_;  // x → z before the filter, the orbit mean after it
  std::unique_ptr<Filter> filter_;
  std::unique_ptr<DrawFilter> draw_;          // draw direction: after the filter, before the projection
  std::unique_ptr<OverhangFilter> overhang_;  // overhang: after the draw direction, before the projection
  std::unique_ptr<fem::Elasticity> fe_;
  Eigen::MatrixXd loads_;     // as given: with every tet's full weight
  Eigen::Matrix3Xd gravity_;  // 3 x #cases, empty without self-weight
  VecXd quarter_mass_;        // #D: ρ_material vol / 4 of each design tet (t)
  std::vector<double> weights_;
  Heaviside proj_;
  RobustThresholds eta_;     // all three the projection's η without a minimum member size
  bool robust_ = false;      // a minimum member size: the three designs of the robust formulation
  double volume_scale_ = 1;  // robust: V_intermediate / V_dilated at the last compliance() call
  Progress progress_;
  VecXd scale_;
  Eigen::MatrixXd U_;  // displacements of the last compliance() call
  /// #D each: a design's densities after the density filter, after the draw direction (its
  /// input without it) and after the overhang filter (the projection's input; its input
  /// without it) — each stage's input is what its chain rule needs.
  struct Stages {
    VecXd filtered, drawn, tilde;
  };
  Stages stages_;   // of the last compliance() call
  VecXd staged_x_;  // #N: its x
  VecXd rho_bar_;   // #D: its physical densities
  VecXd chain(const Stages& s, VecXd d_bar, double eta) const;
  Stages filtered(const VecXd& x) const;
  /// filtered(x): stages_ itself when x is the last compliance() call's (SIMP's volume and its
  /// gradient at the x just analysed: one filter application less an iteration), else made in
  /// `scratch`.
  const Stages& filtered(const VecXd& x, Stages& scratch) const;
  VecXd project(const VecXd& rho_tilde, double eta) const;
  double volume_of(const VecXd& rho_bar) const { return vd_.dot(rho_bar) / design_volume_; }
  double grey_of(const VecXd& rho_bar) const;  // share of the design volume with 0.1 < ρ̄ < 0.9
};

/// Runs SIMP. loads: (3*#V) by #cases (fem::make_loads), weights: #cases (empty: all 1),
/// gravity: design-dependent self-weight as for ComplianceProblem (empty: none).
/// on_iteration is called after every iteration; progress.cancelled stops at the next
/// iteration with Error(Cancelled). Throws Error(InvalidParameter) for a volume fraction
/// outside (0, 1) or a mesh without design tets, Error(NoSupport) for a singular system.
SimpResult optimize(const TetMesh& mesh, const fem::Material& material, const fem::Supports& supports,
                    const Eigen::MatrixXd& loads, const std::vector<double>& weights, const SimpParams& params,
                    const Progress& progress = {}, const std::function<void(const IterationRecord&)>& on_iteration = {},
                    const Eigen::Matrix3Xd& gravity = {});

/// The filter radius SIMP uses for `params` on `mesh`: the given one, or 1.5 × the mean
/// edge length when it is <= 0.
double filter_radius(const TetMesh& mesh, const FilterParams& params);

/// Throws Error(InvalidParameter) for an iteration cap below 1 or a projection schedule
/// that cannot run (β below 1 or above its maximum at the start, a factor not above 1).
void check_params(const SimpParams& params);

/// The one check of a volume fraction's range, (0, 1). Throws Error(InvalidParameter)
/// "`name` must lie strictly between 0 and 1 (...)".
void check_volume_fraction(double volume_fraction, const std::string& name = "the volume fraction");

}  // namespace topopt::simp
