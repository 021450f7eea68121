// SIMP-time reuse rules of the linear solvers, as named decisions. SIMP solves a long series of
// stiffness matrices with one pattern whose values change a little from one iteration to the
// next; what is expensive to build (a Cholesky factor, a multigrid hierarchy) is kept while it
// still pays and rebuilt when it stops paying.
#pragma once
#include <algorithm>

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

/// When the multigrid solver keeps its hierarchy for a new matrix (refreshing only the finest
/// level's smoother) and when it sets up a new one: kept until a solve needs clearly more CG
/// iterations than the first solve after the setup (more than 1.5 times as many, plus 4).
class HierarchyReuse {
 public:
  /// allowed: SolverParams::recycle_factor.
  explicit HierarchyReuse(bool allowed) : allowed_(allowed) {}

  /// A new matrix arrived: keep the hierarchy? Yes if one is built, reuse is allowed and the
  /// iteration count has not grown by half since its setup.
  bool keep(bool built) const { return built && allowed_ && !grown_; }

  /// A new hierarchy was set up: the next solve's iteration count is the new baseline.
  void set_up() {
    grown_ = false;
    baseline_ = -1;
    refresh_ = 0;
  }

  /// The tolerance changed: the next solve's iteration count is the new baseline (the hierarchy
  /// stays as it is).
  void rebaseline() { baseline_ = -1; }

  /// A solve on the kept hierarchy was cut short (patience reached) and finished on recomputed
  /// coarse levels: the designs are changing fast, so the next kRefreshAfterCut kept matrices
  /// get their coarse levels recomputed before their solve instead of losing `patience`
  /// iterations each on stale ones first.
  void cut() { refresh_ = kRefreshAfterCut; }

  /// A kept hierarchy for a new matrix: recompute its coarse levels now (not only the finest
  /// smoother)? Yes within kRefreshAfterCut matrices of the last cut. Counts down.
  bool refresh_coarse_on_update() {
    if (refresh_ == 0) return false;
    --refresh_;
    return true;
  }

  static constexpr int kRefreshAfterCut = 2;

  /// Records a solve's CG iterations (its worst load case).
  void record(int iterations) {
    if (baseline_ < 0)
      baseline_ = iterations;
    else if (iterations > limit())
      grown_ = true;
  }

  /// The most CG iterations a solve with the kept hierarchy may take before it is cut short and
  /// finished on recomputed coarse levels (from where it stopped): the growth that would make the next matrix
  /// rebuild anyway. Without a baseline yet (the first solve after a setup) `cap`. Bounds what a
  /// stale hierarchy wastes: on the cantilever (63 k tets) the second SIMP iteration took 89 CG
  /// iterations on the first one's hierarchy where a new one needs 13.
  int patience(int cap) const { return baseline_ < 0 ? cap : std::min(cap, limit()); }

 private:
  /// Clearly more iterations than the baseline: 1.5 times as many, plus 4.
  int limit() const { return static_cast<int>(1.5 * baseline_) + 4; }

  bool allowed_;
  bool grown_ = false;
  int baseline_ = -1;  // iterations of the first solve after the last setup
  int refresh_ = 0;    // kept matrices still to get their coarse levels recomputed up front
};

}  // namespace topopt::fem
