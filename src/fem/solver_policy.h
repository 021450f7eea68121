// SIMP-time reuse rules of the linear solvers, as named decisions. SIMP solves a long series of
// stiffness matrices with one pattern whose values change a little from one iteration to the
// next; what is expensive to build (a Cholesky factor, a multigrid hierarchy) is kept while it
// still pays and rebuilt when it stops paying.
#pragma once
#include <algorithm>
#include <cmath>

namespace topopt::fem {

/// When the direct solver factorises a new matrix and when it solves it by CG preconditioned
/// with an earlier matrix's factor ("recycling").
class FactorReuse {
 public:
  /// allowed: SolverParams::recycle_factor.
  explicit FactorReuse(bool allowed) : allowed_(allowed) {}

  /// A new matrix arrived: factorise it at once? Yes without a factor, or if reuse is off.
  bool factorise_on_update(bool have_factor) const { return !have_factor || !allowed_; }

  /// About to solve with an earlier matrix's factor: factorise instead? Yes for the
  /// kSkipAfterFailure solves after a recycling failed (the designs are then changing fast:
  /// a failed attempt costs its CG iterations on top of the factorisation). Counts down.
  bool factorise_before_solve() {
    if (skip_ == 0) return false;
    --skip_;
    return true;
  }

  /// A recycling attempt gave up (too slow, see PcgParams::give_up_when_slow).
  void recycling_failed() { skip_ = kSkipAfterFailure; }

  static constexpr int kSkipAfterFailure = 2;

 private:
  bool allowed_;
  int skip_ = 0;
};

/// When the multigrid solver keeps its hierarchy for a new matrix, when it recomputes the kept
/// hierarchy's coarse matrices (a Galerkin refresh: R A P on the kept aggregates, about
/// kRefreshCost CG iterations' work) and when it sets up a new one.
///
/// A stale preconditioner is still a valid one for CG (the V-cycle stays symmetric positive
/// definite), so staleness costs iterations, never accuracy: each solve meets its tolerance
/// whatever the hierarchy. The rule weighs the two costs. The first solve on coarse matrices that
/// fit its matrix (after a setup or a refresh) is the reference; every later solve on the kept
/// coarse matrices (only the finest smoother refreshed) adds its iterations beyond the reference
/// to an excess. The coarse matrices are refreshed before the next solve once waiting one more
/// matrix would bring the excess to a refresh's cost (the next solve's excess taken as the
/// last one's: a lower bound while the staleness grows) — the rent-or-buy balance, which for an
/// excess growing linearly refreshes at the period that minimises iterations plus refreshes.
/// A single kept solve that runs kRefreshCost past the reference is cut there and finished on
/// refreshed coarse matrices (patience()). A new hierarchy is set up when even a solve on
/// refreshed coarse matrices needs clearly more than the first solve after the setup (1.5 times
/// as many, plus 4: the aggregates no longer fit the design).
///
/// Measured (BENCHMARKS.md, branch speed11) against the rule it replaced (a kept solve cut at
/// 1.5 × the setup's count + 4, then two refreshes up front): rocker (100 k tets, 61 SIMP
/// iterations) 908 → 999 CG iterations, 35 → 27 refreshes (CG + 14 × refreshes −1.5 %); cantilever
/// (63 k tets) 712 → 674 and 9 → 7 (−8 %); the same designs within 3e-4 of the compliance.
class HierarchyReuse {
 public:
  /// allowed: SolverParams::recycle_factor.
  explicit HierarchyReuse(bool allowed) : allowed_(allowed) {}

  /// A new matrix arrived: keep the hierarchy? Yes if one is built, reuse is allowed and no
  /// solve on refreshed coarse matrices has outgrown the setup's count.
  bool keep(bool built) const { return built && allowed_ && !grown_; }

  /// A new hierarchy was set up: the next solve's iteration count is the new baseline and
  /// reference.
  void set_up() {
    grown_ = false;
    baseline_ = reference_ = -1;
    excess_ = last_ = 0;
    expected_ = -1.0;
    fresh_ = true;
  }

  /// The tolerance changed from `from` to `to` (relative residuals in (0, 1)): the counts at the
  /// old tolerance are not those at the new one. The next solve is the new baseline and
  /// reference, on the hierarchy as it is (a refresh forced here cost the cantilever's β = 32
  /// phase refreshes the kept hierarchy did without) — unless it needs clearly more than the
  /// current baseline scaled to the new tolerance (CG's iterations grow as log(1 / tolerance):
  /// a baseline of 9 at 1e-2 expects 22.5 at 1e-5): then the aggregates no longer fit the
  /// design and the next matrix gets a new hierarchy. Without the scaled test the rocker, solved
  /// at 1e-2 below its final β, ran the whole β = 32 phase on the uniform start's aggregates:
  /// its first solve at 1e-5 (53 iterations) became the baseline, so nothing ever outgrew it.
  void rebaseline(double from, double to) {
    const bool scalable = baseline_ > 0 && from > 0 && from < 1 && to > 0 && to < 1;
    expected_ = scalable ? baseline_ * std::log(to) / std::log(from) : -1.0;
    baseline_ = reference_ = -1;
    excess_ = last_ = 0;
  }

  /// A solve on the kept hierarchy was cut short (patience reached) and finished on refreshed
  /// coarse matrices, in `iterations` in all (-1: not known): the designs are changing fast, so
  /// the next kept matrix gets its coarse matrices refreshed before its solve too (its count is
  /// then the new reference), and what one matrix's staleness cost — the solve's excess and the
  /// refresh it needed anyway — is remembered for the matrices after it. (The excess alone
  /// understates it: the solve was cut. Without the refresh's share the rocker's β = 32 phase,
  /// whose cut solves take 28-31 iterations against 10-13 refreshed, tried a kept solve every
  /// other matrix.)
  void cut(int iterations = -1) {
    excess_ = kRefreshCost;
    last_ = std::max(0, iterations - reference_) + kRefreshCost;
  }

  /// A kept hierarchy for a new matrix: recompute its coarse matrices now (not only the finest
  /// smoother)? Yes when the excess plus one more solve's like the last kept one would reach
  /// kRefreshCost, or after a cut or a tolerance change. Call once per kept matrix. The last
  /// kept solve's excess (or a cut one's cost) outlives the refresh, fading by a third at each:
  /// while one matrix's staleness alone costs a refresh (the rocker at β = 32) every matrix is
  /// refreshed, and a kept solve is tried again every few matrices.
  bool refresh_coarse_on_update() {
    fresh_ = excess_ + last_ >= kRefreshCost;
    if (fresh_) {
      excess_ = 0;
      last_ = last_ * 2 / 3;
    }
    return fresh_;
  }

  /// A Galerkin refresh's work in CG iterations of the same system: measured on main's rocker
  /// log (100 k tets, two levels, 7 320 coarse unknowns), 3.66 s per refresh against 0.257 s
  /// per CG iteration (wall, the same run: the ratio, not the seconds).
  static constexpr int kRefreshCost = 14;

  /// Records a solve's CG iterations (its worst load case); not called for a solve that was
  /// cut and finished on refreshed coarse matrices.
  void record(int iterations) {
    if (fresh_ || reference_ < 0) {
      if (baseline_ < 0) {
        baseline_ = iterations;
        if (expected_ > 0 && iterations > limit(expected_)) grown_ = true;  // the first at a new tolerance
        expected_ = -1.0;
      } else if (iterations > limit(baseline_)) {
        grown_ = true;
      }
      reference_ = iterations;
      excess_ = 0;
    } else if (reference_ >= 0) {
      last_ = std::max(0, iterations - reference_);
      excess_ += last_;
    }
    fresh_ = false;
  }

  /// The most CG iterations a solve on the kept coarse matrices may take before it is cut short
  /// and finished on refreshed ones (from where it stopped): the reference plus a refresh's
  /// cost (half of it cut the cantilever's solves that a kept hierarchy finished at less cost).
  /// Without a reference (coarse matrices that fit, or the first solve at a new tolerance) `cap`.
  int patience(int cap) const {
    return fresh_ || reference_ < 0 ? cap : std::min(cap, reference_ + kRefreshCost);
  }

 private:
  /// Clearly more iterations than `baseline`: 1.5 times as many, plus 4.
  static int limit(double baseline) { return static_cast<int>(1.5 * baseline) + 4; }

  bool allowed_;
  bool grown_ = false;
  bool fresh_ = true;   // the coarse matrices fit the current matrix (set up or refreshed for it)
  int baseline_ = -1;   // iterations of the first solve after the last setup (or tolerance change)
  int reference_ = -1;  // iterations of the first solve after the last setup or refresh
  int excess_ = 0;      // iterations beyond the reference of the kept solves since then
  int last_ = 0;        // the last kept solve's iterations beyond the reference
  double expected_ = -1.0;  // after a tolerance change, the old baseline scaled to the new tolerance
};

}  // namespace topopt::fem
