// Design updates: optimality criteria (top88) and the method of moving asymptotes
// (Svanberg 1987, with the asymptote rules of his 2007 notes).
#pragma once
#include <functional>
#include <vector>

#include "common/types.h"

namespace topopt::simp {

/// What OC's linearised bisection needs beyond oc_update's arguments.
struct OcLinearisation {
  /// volume_excess(x) at the current design, which the caller has computed already.
  double excess_at_x = 0;
  /// A rank's partial dot product → the global one (an MPI all-reduce); the identity when empty.
  std::function<double(double)> global_sum;
};

/// OC's candidate for one variable at multiplier λ: x sqrt(−dc / (λ dv)) within [x − move,
/// x + move] ∩ [0, 1] (top88's heuristic update), taken as 0 before the clamp where x is 0 or
/// dc ≥ 0 (no stiffening; under a steep projection the chain rule underflows to exactly 0): computed
/// as written, those would be NaN (0 × ∞, 0 / 0) when λ dv underflows to 0 — the bracket searches λ
/// down to 1e-300 — and the clamp would let the NaN through.
double oc_candidate(double x, double dc, double dv, double move, double lambda);

/// oc_candidate for every variable (x, dc, dv, move: #D) into out (#D, resized): two at a time in
/// SSE2 where the compiler targets it (every x86-64), the same operations in the same order (IEEE
/// division and square root are correctly rounded in either form): the same values to the bit,
/// about half the time of the scalar loop, whose square roots and divisions OC's bisection repeats
/// per step (5 % of the rocker's SIMP profile, BENCHMARKS.md, speed14).
void oc_candidates(const VecXd& x, const VecXd& dc, const VecXd& dv, const VecXd& move, double lambda, VecXd& out);

/// Optimality criteria with move limits. x: #D current design variables in [0, 1]; dc: #D
/// objective sensitivities (<= 0 for compliance); dv: #D constraint sensitivities (> 0);
/// move: #D largest change of each variable (MoveLimits, or one value for all);
/// volume_excess(x_new): the volume constraint's value for a candidate (> 0 means too much
/// material). The Lagrange multiplier is found by bisection (to 1e-6 relative) so the
/// constraint is met. multiplier (optional, in/out): the last iteration's multiplier, > 0, to
/// bracket around (about 24 volume evaluations instead of ~40 from a blind bracket); receives
/// this one's. Null or <= 0: a blind bracket from 1e9.
///
/// linearised (optional): the bisection then runs on the volume linearised at x,
/// excess(x) + Σ dv_i (x_new,i − x_i) — a dot product per step instead of volume_excess, which
/// under the projection is a filter application and a projection of every element — and the
/// multiplier is corrected on the real volume (one volume_excess per round: the model's
/// constant and slope along the candidates' path refitted through the real values, a secant)
/// until the real volume is met as the exact bisection meets it (not over the target, and short
/// of it by less than the volume change across the last bracket). dv must then be the gradient of volume_excess at x. Rounds
/// that do not get there (a volume far from linear: draw direction, overhang) end in the exact
/// bisection from the last multiplier, so the result meets the volume either way.
VecXd oc_update(const VecXd& x, const VecXd& dc, const VecXd& dv, const VecXd& move,
                const std::function<double(const VecXd&)>& volume_excess, double* multiplier = nullptr,
                const OcLinearisation* linearised = nullptr);

/// Move limits per variable for OC that let an oscillating design settle: a variable whose
/// last two steps went opposite ways gets its limit multiplied by `shrink`, one that kept
/// its direction by `grow` (as MMA moves its asymptotes, Svanberg 1987), between `smallest`
/// and `largest`. A projected design (large β) otherwise keeps flipping the variables at its
/// boundary by the full move limit and never converges.
class MoveLimits {
 public:
  /// n variables starting at `largest`.
  MoveLimits(int n, double largest, double smallest = 0.005, double shrink = 0.7, double grow = 1.2);
  /// The limits (#n) for the step from x, given the steps that led to x.
  const VecXd& at(const VecXd& x);
  /// Forgets the past steps (the problem changed, e.g. β was raised); limits stay.
  void restart();

 private:
  double largest_, smallest_, shrink_, grow_;
  VecXd limit_, xold1_, xold2_;
};

/// MMA for  min f0(x)  s.t.  f_i(x) <= 0 (i = 1..m),  0 <= x <= 1. Keeps the history the
/// asymptote rule needs; call update() once per iteration.
class Mma {
 public:
  /// n design variables, m constraints, move limit as a share of [0, 1].
  Mma(int n, int m, double move = 0.2);
  /// f0, df0 (#n): objective and gradient; f (#m), df (m by n): constraints and gradients.
  /// Returns the next x. The subproblem's dual is solved by coordinate bisection, exact for
  /// m = 1 and convergent for a few constraints.
  VecXd update(const VecXd& x, double f0, const VecXd& df0, const VecXd& f, const Eigen::MatrixXd& df);
  /// Starts the asymptotes afresh at the next update (the problem changed, e.g. β was raised).
  void restart() {
    iter_ = 0;
    xold1_.resize(0);
  }

 private:
  int n_, m_;
  double move_;
  int iter_ = 0;
  VecXd xold1_, xold2_, low_, upp_;
};

}  // namespace topopt::simp
