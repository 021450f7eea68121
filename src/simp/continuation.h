// When to sharpen the projection and when to stop: the β continuation of the Heaviside
// projection (Guest, Prévost & Belytschko 2004; Wang, Lazarov & Sigmund 2011) and SIMP's
// convergence test, in one place so that "converged" always means the same thing.
#pragma once

namespace topopt::simp {

/// The Heaviside projection ρ̄ = H_β(ρ̃) and its continuation. β starts at beta_start and is
/// multiplied by beta_factor (up to beta_max) each time the design has settled at the
/// current β — the compliance changed by less than settle_tolerance (relative) in
/// settle_iterations iterations running, or no variable moved by more than the tolerance on
/// the change — or after max_iterations_per_beta iterations at one β, whichever comes
/// first. Convergence is judged at beta_max only, so the design returned is the sharp one.
struct ProjectionParams {
  bool enabled = true;               ///< false: ρ̄ = ρ̃ (no projection, β stays 1)
  double eta = 0.5;                  ///< the projection's threshold
  double beta_start = 1;             ///< β of the first iteration, >= 1
  double beta_max = 32;              ///< the final sharpness; >= beta_start
  double beta_factor = 2;            ///< β ← min(beta_max, beta_factor β) when settled, > 1
  int max_iterations_per_beta = 40;  ///< raise β after this many iterations at one β anyway
  /// Relative compliance change that counts as settled (the job's "settle"). 1e-2 would save the
  /// rocker 8 of its 61 iterations (compliance −1.5e-4), the cantilever 8 of 69, the bracket 5 of
  /// 50 and the lever 25 of 98 (its compliance +0.38 %), and the two Controls tests it broke were
  /// measuring unfairly (corrected, branch speed8); but Overhang.BeamHasLessOverhangWithTheControl
  /// then ends on a design whose crisp iso-surface overhangs 2.4 % (bound 1 %; 0.81 % at 2e-3),
  /// not looked into yet (BENCHMARKS.md, branches speed6 and speed8): not the default.
  double settle_tolerance = 2e-3;
  int settle_iterations = 3;         ///< ... for this many iterations running
};

/// What the loop does after an iteration.
enum class NextStep { Continue, RaiseBeta, Converged };

/// The continuation schedule and the convergence test. Call next() once per iteration with
/// its compliance and design change; read beta() for the projection of the next iteration.
class Continuation {
 public:
  /// tol_change: converged (or settled) when no design variable moved by more than this;
  /// tol_objective: converged when the compliance changed by less than this (relative) for
  /// 5 iterations running. Both are judged at the final β only.
  Continuation(const ProjectionParams& params, double tol_change, double tol_objective);

  /// β to use now (1 without projection).
  double beta() const { return beta_; }
  /// True once β has reached beta_max (always without projection).
  bool sharp() const;

  /// Records an iteration (its compliance and max |Δx|) and says what comes next. On
  /// RaiseBeta, beta() already holds the new β and the settling count starts again.
  NextStep next(double compliance, double change);

 private:
  ProjectionParams params_;
  double tol_change_, tol_objective_;
  double beta_ = 1;
  double previous_ = 0;
  int iterations_ = 0;   // iterations recorded at the current β
  int calm_final_ = 0;   // running count below tol_objective
  int calm_settle_ = 0;  // running count below settle_tolerance
};

/// The FE solver's relative residual for the next iteration: `early` (when looser) while β is
/// below its final value, `final_tolerance` once it is there (and always without projection).
/// The designs at a lower β are stepping stones that the final phase reshapes; convergence is
/// judged at the final β only, so every compliance it compares and the design returned come from
/// solves at `final_tolerance`. Measured on the rocker (100 k tets, the 25 iterations at β = 1):
/// CG iterations 540 at 1e-5, 471 at 1e-4, 383 at 1e-3, the compliance of iteration 25 the same
/// to 6 digits (BENCHMARKS.md, branch speed4).
double solver_tolerance(const Continuation& schedule, double final_tolerance, double early);

}  // namespace topopt::simp
