// Preconditioned conjugate gradients: the one CG loop of the code base. The multigrid solver
// runs it with its V-cycle, the direct solver with an earlier matrix's Cholesky factor (SIMP's
// stiffness changes little from one iteration to the next). Operator and preconditioner are
// interfaces so that a distributed implementation (PETSc's Mat and PC, issue 21) can sit
// behind the same loop or replace it wholesale.
#pragma once
#include <Eigen/Core>

#include "common/progress.h"

namespace topopt::fem {

/// A symmetric positive definite operator on vectors of size() entries.
class LinearOperator {
 public:
  virtual ~LinearOperator() = default;
  virtual int size() const = 0;
  /// y = A x. x, y: size(); y is overwritten.
  virtual void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const = 0;
  /// r = b − A x. b, x, r: size(). A call of its own (not apply and a subtraction) so that an
  /// operator keeps its own rounding: Eigen's self-adjoint product accumulates onto b.
  virtual void residual(const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) const = 0;
};

/// A symmetric positive definite approximation of A⁻¹.
class Preconditioner {
 public:
  virtual ~Preconditioner() = default;
  /// z = M⁻¹ r. r, z: the operator's size(); z is overwritten.
  virtual void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const = 0;
};

struct PcgParams {
  double tolerance = 1e-8;    ///< stop when ||b − A x|| <= tolerance ||b||
  int max_iterations = 5000;  ///< at most this many iterations (then not converged)
  /// After 6 iterations, give up when the residual's mean rate of decrease so far says that
  /// max_iterations would not reach the tolerance: for a recycled preconditioner that no longer
  /// fits, rebuilding it is cheaper than iterating on.
  bool give_up_when_slow = false;
};

struct PcgResult {
  int iterations = 0;
  double relative_residual = 0;  ///< ||b − A x|| / ||b|| at exit (0 for b = 0)
  bool converged = false;
};

/// Solves A x = b by conjugate gradients preconditioned by M, starting from x (a warm start;
/// x = 0 is returned at once for b = 0). b, x: A.size(); x holds the last iterate on exit.
/// Stops at the tolerance, at max_iterations, when giving up (see PcgParams) or at a breakdown
/// (pᵀAp <= 0: A or M is not positive definite); `converged` tells which. Checks `progress`
/// for cancellation every 16 iterations (throws Error(Cancelled)).
PcgResult pcg(const LinearOperator& A, const Preconditioner& M, const Eigen::VectorXd& b, Eigen::VectorXd& x,
              const PcgParams& params, const Progress& progress = {});

}  // namespace topopt::fem
