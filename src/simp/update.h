// Design updates: optimality criteria (top88) and the method of moving asymptotes
// (Svanberg 1987, with the asymptote rules of his 2007 notes).
#pragma once
#include <functional>
#include <vector>

#include "common/types.h"

namespace topopt::simp {

/// Optimality criteria with move limit. x: #D current design variables in [0, 1]; dc: #D
/// objective sensitivities (<= 0 for compliance); dv: #D constraint sensitivities (> 0);
/// volume_excess(x_new): the volume constraint's value for a candidate (> 0 means too much
/// material). The Lagrange multiplier is found by bisection so the constraint is met.
VecXd oc_update(const VecXd& x, const VecXd& dc, const VecXd& dv, double move,
                const std::function<double(const VecXd&)>& volume_excess);

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

 private:
  int n_, m_;
  double move_;
  int iter_ = 0;
  VecXd xold1_, xold2_, low_, upp_;
};

}  // namespace topopt::simp
