// Preconditioned conjugate gradients (see pcg.h).
#include "fem/pcg.h"

#include <cmath>

namespace topopt::fem {

namespace {

/// The give-up test of PcgParams::give_up_when_slow, made after 6 iterations: at the mean
/// rate (rnorm / r0)^(1/6) per iteration, would max_iterations reach `goal`?
bool too_slow(int iteration, double rnorm, double r0, double goal, const PcgParams& params) {
  if (!params.give_up_when_slow || iteration != 6) return false;
  return std::pow(rnorm / r0, static_cast<double>(params.max_iterations) / 6) > goal / r0;
}

}  // namespace

PcgResult pcg(const LinearOperator& A, const Preconditioner& M, const Eigen::VectorXd& b, Eigen::VectorXd& x,
              const PcgParams& params, const Progress& progress) {
  const int n = A.size();
  Eigen::VectorXd r(n), z(n), p(n), q(n);
  PcgResult res;
  const double bnorm = b.norm();
  if (bnorm == 0) {
    x.setZero();
    res.converged = true;
    return res;
  }
  A.residual(b, x, r);
  double rnorm = r.norm();
  const double r0 = rnorm, goal = params.tolerance * bnorm;
  M.apply(r, z);
  p = z;
  double rz = r.dot(z);
  int it = 0;
  for (; rnorm > goal && it < params.max_iterations && !too_slow(it, rnorm, r0, goal, params); ++it) {
    if (it % 16 == 15) progress.check_cancel("the FE solve");
    A.apply(p, q);
    const double pq = p.dot(q);
    if (!(pq > 0)) break;  // breakdown: A (or the preconditioner) is not positive definite
    const double alpha = rz / pq;
    x += alpha * p;
    r -= alpha * q;
    rnorm = r.norm();
    if (rnorm <= goal) {
      ++it;
      break;
    }
    M.apply(r, z);
    const double rz_new = r.dot(z);
    p = z + (rz_new / rz) * p;
    rz = rz_new;
  }
  res.iterations = it;
  res.relative_residual = rnorm / bnorm;
  res.converged = rnorm <= goal;
  return res;
}

}  // namespace topopt::fem
