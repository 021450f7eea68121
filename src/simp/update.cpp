// OC and MMA updates (see update.h).
#include "simp/update.h"

#include <algorithm>
#include <cmath>

namespace topopt::simp {

namespace {

/// Brackets OC's multiplier around `hint` (> 0, the last iteration's): [l1, l2] with too much
/// material at l1 (or l1 = 0) and not too much at l2, widening by 4 each way as needed.
template <class Excess>
void bracket_near(double hint, const Excess& excess_at, double& l1, double& l2) {
  l1 = 0;
  l2 = 2 * hint;
  while (excess_at(l2) > 0 && l2 < 1e300) l1 = l2, l2 *= 4;
  if (l1 > 0) return;
  for (double lo = hint / 2; lo > 1e-300; lo /= 4) {
    if (excess_at(lo) > 0) {
      l1 = lo;
      return;
    }
    l2 = lo;
  }
}

}  // namespace

VecXd oc_update(const VecXd& x, const VecXd& dc, const VecXd& dv, const VecXd& move,
                const std::function<double(const VecXd&)>& volume_excess, double* multiplier) {
  double l1 = 0, l2 = 1e9;
  VecXd xnew(x.size());
  auto candidate = [&](double lambda) {
    for (long i = 0; i < x.size(); ++i) {
      double b = std::sqrt(std::max(-dc[i], 0.0) / (lambda * dv[i]));
      xnew[i] = std::clamp(x[i] * b, std::max(0.0, x[i] - move[i]), std::min(1.0, x[i] + move[i]));
    }
  };
  auto excess_at = [&](double lambda) {
    candidate(lambda);
    return volume_excess(xnew);
  };
  if (multiplier && *multiplier > 0 && std::isfinite(*multiplier)) {
    bracket_near(*multiplier, excess_at, l1, l2);
  } else {
    // Bracket the multiplier first: compliance sensitivities can be far from 1 in scale.
    while (excess_at(l2) > 0 && l2 <= 1e300) l1 = l2, l2 *= 1e3;
  }
  while ((l2 - l1) / (l1 + l2) > 1e-6) {
    double mid = 0.5 * (l1 + l2);
    if (excess_at(mid) > 0)
      l1 = mid;
    else
      l2 = mid;
  }
  candidate(l2);
  if (multiplier) *multiplier = l2;
  return xnew;
}

MoveLimits::MoveLimits(int n, double largest, double smallest, double shrink, double grow)
    : largest_(largest), smallest_(std::min(smallest, largest)), shrink_(shrink), grow_(grow) {
  limit_ = VecXd::Constant(n, largest);
}

const VecXd& MoveLimits::at(const VecXd& x) {
  if (xold2_.size())
    for (long i = 0; i < x.size(); ++i) {
      const double turn = (x[i] - xold1_[i]) * (xold1_[i] - xold2_[i]);
      if (turn < 0) limit_[i] = std::max(smallest_, shrink_ * limit_[i]);
      if (turn > 0) limit_[i] = std::min(largest_, grow_ * limit_[i]);
    }
  xold2_ = xold1_.size() ? xold1_ : x;
  xold1_ = x;
  return limit_;
}

void MoveLimits::restart() {
  xold1_.resize(0);
  xold2_.resize(0);
}

Mma::Mma(int n, int m, double move) : n_(n), m_(m), move_(move) {}

VecXd Mma::update(const VecXd& x, double f0, const VecXd& df0, const VecXd& f, const Eigen::MatrixXd& df) {
  (void)f0;
  const double asyinit = 0.5, asyincr = 1.2, asydecr = 0.7, raa0 = 1e-5, albefa = 0.1;
  ++iter_;
  if (iter_ <= 2) {
    low_ = x.array() - asyinit;
    upp_ = x.array() + asyinit;
  } else {
    for (int j = 0; j < n_; ++j) {
      double s = (x[j] - xold1_[j]) * (xold1_[j] - xold2_[j]);
      double g = s < 0 ? asydecr : s > 0 ? asyincr : 1.0;
      low_[j] = x[j] - g * (xold1_[j] - low_[j]);
      upp_[j] = x[j] + g * (upp_[j] - xold1_[j]);
      low_[j] = std::clamp(low_[j], x[j] - 10.0, x[j] - 0.01);
      upp_[j] = std::clamp(upp_[j], x[j] + 0.01, x[j] + 10.0);
    }
  }
  VecXd alpha(n_), beta(n_), p0(n_), q0(n_);
  Eigen::MatrixXd P(m_, n_), Q(m_, n_);
  VecXd r = f;
  for (int j = 0; j < n_; ++j) {
    alpha[j] = std::max({0.0, low_[j] + albefa * (x[j] - low_[j]), x[j] - move_});
    beta[j] = std::min({1.0, upp_[j] - albefa * (upp_[j] - x[j]), x[j] + move_});
    double ux = upp_[j] - x[j], xl = x[j] - low_[j];
    double a = std::max(df0[j], 0.0), b = std::max(-df0[j], 0.0), c = 0.001 * std::abs(df0[j]) + raa0;
    p0[j] = ux * ux * (a + c);
    q0[j] = xl * xl * (b + c);
    for (int i = 0; i < m_; ++i) {
      double ai = std::max(df(i, j), 0.0), bi = std::max(-df(i, j), 0.0), ci = 0.001 * std::abs(df(i, j)) + raa0;
      P(i, j) = ux * ux * (ai + ci);
      Q(i, j) = xl * xl * (bi + ci);
      r[i] -= P(i, j) / ux + Q(i, j) / xl;
    }
  }
  // Dual: for λ >= 0, x_j(λ) minimises (p0+λᵀP)/(U−x) + (q0+λᵀQ)/(x−L) on [α, β]; the
  // constraints' values g_i(x(λ)) are the dual gradient, decreasing in λ_i. Artificial
  // variables y_i with cost c y + y²/2 keep the subproblem feasible: y_i = max(0, λ_i − c).
  const double cpen = 1e3;
  VecXd lambda = VecXd::Zero(m_), xs(n_);
  auto primal = [&](const VecXd& lam) {
    for (int j = 0; j < n_; ++j) {
      double pj = p0[j] + lam.dot(P.col(j)), qj = q0[j] + lam.dot(Q.col(j));
      double sp = std::sqrt(pj), sq = std::sqrt(qj);
      xs[j] = std::clamp((sp * low_[j] + sq * upp_[j]) / (sp + sq), alpha[j], beta[j]);
    }
  };
  auto gradient = [&](int i, const VecXd& lam) {
    primal(lam);
    double g = r[i];
    for (int j = 0; j < n_; ++j) g += P(i, j) / (upp_[j] - xs[j]) + Q(i, j) / (xs[j] - low_[j]);
    return g - std::max(0.0, lam[i] - cpen);
  };
  for (int sweep = 0; sweep < (m_ == 1 ? 1 : 60); ++sweep) {
    for (int i = 0; i < m_; ++i) {
      VecXd lam = lambda;
      lam[i] = 0;
      if (gradient(i, lam) <= 0) {
        lambda[i] = 0;
        continue;
      }
      double lo = 0, hi = 1;
      for (lam[i] = hi; gradient(i, lam) > 0 && hi < 1e12; lam[i] = hi) lo = hi, hi *= 10;
      for (int k = 0; k < 100 && (hi - lo) > 1e-12 * hi; ++k) {
        lam[i] = 0.5 * (lo + hi);
        (gradient(i, lam) > 0 ? lo : hi) = lam[i];
      }
      lambda[i] = 0.5 * (lo + hi);
    }
  }
  primal(lambda);
  xold2_ = xold1_.size() ? xold1_ : x;
  xold1_ = x;
  return xs;
}

}  // namespace topopt::simp
