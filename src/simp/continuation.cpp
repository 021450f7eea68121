// β continuation and the convergence test (see continuation.h).
#include "simp/continuation.h"

#include <algorithm>
#include <cmath>

namespace topopt::simp {

Continuation::Continuation(const ProjectionParams& params, double tol_change, double tol_objective)
    : params_(params), tol_change_(tol_change), tol_objective_(tol_objective) {
  beta_ = params_.enabled ? params_.beta_start : 1.0;
}

bool Continuation::sharp() const { return !params_.enabled || beta_ >= params_.beta_max; }

NextStep Continuation::next(double compliance, double change) {
  ++iterations_;
  // the first iteration at a β has no predecessor at that β to compare with
  const double relative = std::abs(compliance - previous_) / std::max(1e-300, std::abs(compliance));
  const bool compared = iterations_ > 1;
  calm_final_ = compared && relative < tol_objective_ ? calm_final_ + 1 : 0;
  calm_settle_ = compared && relative < params_.settle_tolerance ? calm_settle_ + 1 : 0;
  previous_ = compliance;
  const bool still = compared && change < tol_change_;
  if (sharp()) return still || calm_final_ >= 5 ? NextStep::Converged : NextStep::Continue;
  const bool settled = still || calm_settle_ >= params_.settle_iterations;
  if (!settled && iterations_ < params_.max_iterations_per_beta) return NextStep::Continue;
  beta_ = std::min(params_.beta_max, beta_ * params_.beta_factor);
  iterations_ = 0;
  calm_final_ = calm_settle_ = 0;
  return NextStep::RaiseBeta;
}

double solver_tolerance(const Continuation& schedule, double final_tolerance, double early) {
  return schedule.sharp() ? final_tolerance : std::max(final_tolerance, early);
}

}  // namespace topopt::simp
