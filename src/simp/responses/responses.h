// The responses of SIMP beyond compliance and volume (issue 22): the displacement of a face
// along a direction by an adjoint load case, and the objective and constraints MMA is handed
// for each Objective. A response is a value and its gradient w.r.t. the physical densities ρ̄,
// chained to the design variables through projection and filter by ComplianceProblem.
#pragma once
#include <vector>

#include "simp/optimizer.h"
#include "simp/responses/frequency.h"
#include "simp/responses/stress.h"

namespace topopt::simp {

/// The displacement u_d,k = gᵀU_k of a DisplacementLimit in every load case k, for the design
/// of the last problem.compliance() call. grad (optional): #D by #cases, du_d,k/dx, from one
/// adjoint solve K λ = g: du/dρ̄_i = λᵀ ∂F_k/∂ρ̄_i − E'(ρ̄_i) λ_iᵀ K0_i u_i. Returns #cases
/// values (mm). The supports must prescribe zero displacements (the adjoint is solved with them).
VecXd face_displacement(ComplianceProblem& problem, const DisplacementLimit& limit, Eigen::MatrixXd* grad = nullptr);

/// What MMA minimises and the constraints f_i <= 0 it keeps, all scaled to about 1.
struct MmaTerms {
  double f0 = 0;                      ///< objective
  VecXd df0;                          ///< #D
  VecXd f;                            ///< #m constraint values
  Eigen::MatrixXd df;                 ///< m by #D
  std::vector<double> displacements;  ///< per DisplacementLimit, the largest |u_d| over the cases (mm)
  double stress_relaxed = 0;          ///< with a stress limit: the largest relaxed von Mises ρ̄^q σ0 (MPa)
  double stress_crisp = 0;            ///< ... and the crisp design's largest (crisp_max_von_mises, MPa)
  double frequency = 0;               ///< Frequency objective: the first eigenfrequency (Hz)
  bool repeated = false;              ///< ... and whether it is repeated (the second within 0.1 %)
  double objective = 0;               ///< the objective's own value: c, the volume fraction or λ1
};

/// The MMA terms of each iteration for `params.responses`. Keeps what the stress constraint's
/// adaptive normalisation needs from the earlier iterations.
class Responses {
 public:
  /// material: its mass density (t/mm³) is the Frequency objective's; material, supports and
  /// params.responses.load_cases are the crisp design's analysis under a stress limit. All are
  /// kept by reference and must outlive this object.
  Responses(const SimpParams& params, const fem::Material& material, const fem::Supports& supports)
      : params_(params), material_(material), supports_(supports) {}
  /// The number of constraints terms() gives with `num_cases` load cases.
  int constraints(int num_cases) const;
  /// The terms at the design of the last problem.compliance() call, given its compliance c,
  /// volume fraction vol and their gradients dc, dv (#D):
  /// - Compliance: f0 = c / |c|, f = [vol / volume_fraction − 1, limits];
  /// - Mass: f0 = vol, f = [c / compliance_limit − 1 (if set), limits];
  /// - Frequency: f0 = −λ1 / λ1 of the first iteration, f = [vol / volume_fraction − 1, limits];
  /// per displacement limit and load case (u_d / limit)² − 1; per load case with a stress
  /// limit c_k σ_PN,k / limit − 1, c_k = max_e σ_e / σ_PN,k averaged with the previous
  /// iteration's (Le et al. 2010; held fixed in the gradient).
  MmaTerms terms(ComplianceProblem& problem, double c, const VecXd& dc, double vol, const VecXd& dv);

 private:
  const SimpParams& params_;
  const fem::Material& material_;
  const fem::Supports& supports_;
  VecXd stress_scale_;           // #cases: c_k of the last iteration (empty before the first)
  double first_eigenvalue_ = 0;  // λ1 of the first iteration (the objective's scale)
  Eigen::MatrixXd modes_;        // the last eigen subspace (the next one's start)
  void add_objective(ComplianceProblem& problem, MmaTerms& t, int& row, double c, const VecXd& dc, double vol,
                     const VecXd& dv);
  void add_stress(ComplianceProblem& problem, MmaTerms& t, int& row);
};

/// The settings the design update and the β continuation run with: `params`, except that under
/// a stress limit the move limit is at most 0.05 and β stops at 8. The p-norm's linearisation
/// does not see that thinning every member at once raises the stress of all of them: with the
/// move limit 0.2, MMA emptied the cantilever in six iterations. At high β only the grey
/// surface layer can still move (the projection is flat elsewhere) and removing it lowers its
/// own relaxed stress: the cantilever eroded to nothing after β was raised to 32, and in
/// another run to 16, at the move limit 0.05 (docs/optimization.md).
SimpParams update_settings(const SimpParams& params);

/// Throws Error(InvalidParameter) for responses that cannot run: a mass objective without any
/// limit, a compliance or displacement limit that is not positive, a gauge of the wrong size
/// (num_dofs = 3 #V), or an update other than MMA when anything beyond compliance under a
/// volume fraction is asked for.
void check_responses(const SimpParams& params, long num_dofs);

}  // namespace topopt::simp
