// OC and MMA updates (see update.h).
#include "simp/update.h"

#include <algorithm>
#include <cmath>
#include <optional>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

/// The multiplier's last bracket: too much material at lo (or lo = 0), not too much at hi.
struct Bracket {
  double lo = 0, hi = 1e9;
};

/// Brackets the multiplier (around hint when it is a usable one, else blind from 1e9: compliance
/// sensitivities can be far from 1 in scale) and bisects it to 1e-6 relative.
template <class Excess>
Bracket bisect(const Excess& excess_at, double hint) {
  Bracket b;
  if (hint > 0 && std::isfinite(hint))
    bracket_near(hint, excess_at, b.lo, b.hi);
  else
    while (excess_at(b.hi) > 0 && b.hi <= 1e300) b.lo = b.hi, b.hi *= 1e3;
  while ((b.hi - b.lo) / (b.lo + b.hi) > 1e-6) {
    const double mid = 0.5 * (b.lo + b.hi);
    (excess_at(mid) > 0 ? b.lo : b.hi) = mid;
  }
  return b;
}

/// OC's candidate design for a multiplier λ (oc_candidates), in a vector of its own.
class Candidates {
 public:
  Candidates(const VecXd& x, const VecXd& dc, const VecXd& dv, const VecXd& move)
      : x_(x), dc_(dc), dv_(dv), move_(move), xnew_(x.size()) {}
  const VecXd& at(double lambda) {
    oc_candidates(x_, dc_, dv_, move_, lambda, xnew_);
    return xnew_;
  }

 private:
  const VecXd &x_, &dc_, &dv_, &move_;
  VecXd xnew_;
};

/// The real volume's excess r at a candidate whose linear part Σ dv_i x_i(λ) is g.
struct Sample {
  double g, r;
};

/// Where the real volume's excess is zero, on g, from its samples: regula falsi with the
/// Illinois rule once samples of both signs bracket it (r falls as g falls, so the bracket
/// always holds the zero), else the secant through the last two samples, else the tangent at x
/// (slope 1: the volume linearised at x).
class ZeroOnG {
 public:
  /// The g to try after sample s.
  double next(const Sample& s) {
    const bool repeat = last_ && (last_->r > 0) == (s.r > 0);
    std::optional<Sample>& same = s.r > 0 ? above_ : below_;
    std::optional<Sample>& other = s.r > 0 ? below_ : above_;
    if (repeat && other) other->r *= 0.5;  // Illinois: the far end stayed twice, halve its weight
    const double secant = last_ && s.g != last_->g ? (s.r - last_->r) / (s.g - last_->g) : 0;
    if (secant > 0 && std::isfinite(secant)) slope_ = secant;  // the volume grows with g: else keep it
    same = s, last_ = s;
    if (above_ && below_) {
      slope_ = (above_->r - below_->r) / (above_->g - below_->g);
      return below_->g - below_->r / slope_;
    }
    return s.g - s.r / slope_;
  }
  /// The slope of the real excess over g last used.
  double slope() const { return slope_; }

 private:
  std::optional<Sample> above_, below_, last_;
  double slope_ = 1;
};

/// The linearised bisection with its corrections on the real volume (oc_update in update.h):
/// each round bisects the multiplier for a target of g(λ) = Σ dv_i x_i(λ) (dot products only),
/// first the tangent at x (the volume linearised at x), then one from the real values found
/// (ZeroOnG). Returns the multiplier, or 0 when the rounds do not meet the real volume as
/// tightly as the exact bisection would (the caller then bisects exactly from `hint`, which
/// receives the last multiplier).
double corrected_linear_multiplier(Candidates& candidates, const VecXd& x, const VecXd& dv,
                                   const std::function<double(const VecXd&)>& volume_excess,
                                   const OcLinearisation& linear, double& hint) {
  // Near a settled design one or two rounds; from a design far off the target at β = 32 up to 8.
  constexpr int kRounds = 10;
  const auto sum = [&](double local) { return linear.global_sum ? linear.global_sum(local) : local; };
  const auto g_at = [&](double lambda) { return sum(dv.dot(candidates.at(lambda))); };
  double target = sum(dv.dot(x)) - linear.excess_at_x;
  ZeroOnG zero;
  for (int round = 0; round < kRounds; ++round) {
    const Bracket b = bisect([&](double lambda) { return g_at(lambda) - target; }, hint);
    hint = b.hi;
    const Sample s{g_at(b.hi), volume_excess(candidates.at(b.hi))};
    // as the exact bisection's result: not too much material, and short of the target by less
    // than the volume change across its last bracket
    if (s.r <= 0 && -s.r <= zero.slope() * (g_at(b.lo) - s.g)) return b.hi;
    target = zero.next(s);
  }
  return 0;
}

}  // namespace

double oc_candidate(double x, double dc, double dv, double move, double lambda) {
  const double gain = std::max(-dc, 0.0);
  const double scaled = gain > 0 && x > 0 ? x * std::sqrt(gain / (lambda * dv)) : 0.0;
  return std::clamp(scaled, std::max(0.0, x - move), std::min(1.0, x + move));
}

void oc_candidates(const VecXd& x, const VecXd& dc, const VecXd& dv, const VecXd& move, double lambda, VecXd& out) {
  const long n = x.size();
  out.resize(n);
  long i = 0;
#if defined(__SSE2__)
  // oc_candidate's operations two at a time; its selections as masks with its own comparisons
  // (a NaN compares false either way), so the same values to the bit
  const __m128d lam = _mm_set1_pd(lambda), zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0);
  const auto select = [](__m128d mask, __m128d a, __m128d b) {
    return _mm_or_pd(_mm_and_pd(mask, a), _mm_andnot_pd(mask, b));
  };
  for (; i + 2 <= n; i += 2) {
    const __m128d xi = _mm_loadu_pd(&x[i]), mv = _mm_loadu_pd(&move[i]);
    // 0 − dc is −dc but for dc = 0 (+0, not −0): a case the mask drops, as gain > 0 does
    const __m128d minus_dc = _mm_sub_pd(zero, _mm_loadu_pd(&dc[i]));
    const __m128d take = _mm_and_pd(_mm_cmplt_pd(zero, minus_dc), _mm_cmplt_pd(zero, xi));
    const __m128d root = _mm_sqrt_pd(_mm_div_pd(minus_dc, _mm_mul_pd(lam, _mm_loadu_pd(&dv[i]))));
    const __m128d scaled = _mm_and_pd(take, _mm_mul_pd(xi, root));
    const __m128d below = _mm_sub_pd(xi, mv), above = _mm_add_pd(xi, mv);
    const __m128d lo = select(_mm_cmplt_pd(zero, below), below, zero);  // std::max(0, x − move)
    const __m128d hi = select(_mm_cmplt_pd(above, one), above, one);    // std::min(1, x + move)
    // std::clamp(scaled, lo, hi): lo if scaled < lo, else hi if hi < scaled, else scaled
    const __m128d upper = select(_mm_cmplt_pd(hi, scaled), hi, scaled);
    _mm_storeu_pd(&out[i], select(_mm_cmplt_pd(scaled, lo), lo, upper));
  }
#endif
  for (; i < n; ++i) out[i] = oc_candidate(x[i], dc[i], dv[i], move[i], lambda);
}

VecXd oc_update(const VecXd& x, const VecXd& dc, const VecXd& dv, const VecXd& move,
                const std::function<double(const VecXd&)>& volume_excess, double* multiplier,
                const OcLinearisation* linearised) {
  Candidates candidates(x, dc, dv, move);
  double hint = multiplier ? *multiplier : 0;
  double lambda =
      linearised ? corrected_linear_multiplier(candidates, x, dv, volume_excess, *linearised, hint) : 0;
  if (lambda <= 0) lambda = bisect([&](double l) { return volume_excess(candidates.at(l)); }, hint).hi;
  if (multiplier) *multiplier = lambda;
  return candidates.at(lambda);
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
