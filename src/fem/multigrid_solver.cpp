// The iterative solver: CG preconditioned by our smoothed-aggregation multigrid (fem/amg.h) on
// the system's K itself (full compressed rows with node blocks, as Elasticity assembles it: no
// copy), warm-started from the previous solution (each load case from its own). Between SIMP
// iterations the hierarchy is kept and only its finest smoother refreshed; its coarse matrices are
// recomputed from the new matrix on the kept aggregates (refresh_galerkin) when the iterations
// the stale ones cost would soon outweigh a refresh, a solve that runs a refresh's cost past the
// reference is cut there and finished on refreshed coarse matrices, and a new hierarchy is set up
// when even refreshed coarse matrices need clearly more iterations than the setup's
// (HierarchyReuse in solver_policy.h). Every solve meets the tolerance whichever happened.
#include <algorithm>
#include <sstream>

#include "common/blas_threads.h"
#include "common/error.h"
#include "common/stopwatch.h"
#include "fem/amg.h"
#include "fem/linear_solver.h"
#include "fem/pcg.h"
#include "fem/solver_policy.h"

namespace topopt::fem {

namespace {

/// K seen by pcg() through the hierarchy's products with its finest matrix (K itself): its 3×3
/// node-block copy where it has one, the same values as K's row walk, faster (multiply_finest).
class FinestOperator final : public LinearOperator {
 public:
  explicit FinestOperator(const SmoothedAggregationAmg& amg, int rows) : amg_(amg), rows_(rows) {}
  int size() const override { return rows_; }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override { amg_.multiply_finest(x.data(), y.data()); }
  void residual(const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) const override {
    Eigen::VectorXd q(rows_);  // as CsrOperator::residual: the product, then b − q
    amg_.multiply_finest(x.data(), q.data());
    r = b - q;
  }

 private:
  const SmoothedAggregationAmg& amg_;
  int rows_;
};

class MultigridSolver final : public LinearSolver {
 public:
  MultigridSolver(const FreeSystem& system, const SolverParams& params)
      : system_(system), params_(params), reuse_(params.recycle_factor) {}

  void update(const Progress& progress) override;
  void solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X, const Progress& progress) override;
  SolverStats stats() const override { return stats_; }
  void set_tolerance(double tolerance) override {
    if (tolerance == params_.tolerance) return;
    reuse_.rebaseline(params_.tolerance, tolerance);
    params_.tolerance = tolerance;  // iteration counts at another tolerance say nothing of a stale hierarchy
  }

 private:
  void set_up(const Progress& progress);
  PcgResult solve_one(const Eigen::VectorXd& b, Eigen::VectorXd& x, const Progress& progress);

  FreeSystem system_;
  SolverParams params_;
  HierarchyReuse reuse_;
  std::vector<double> modes_;  // near_null_space, nf by 6 (made at the first update)
  SmoothedAggregationAmg amg_;
  bool built_ = false;  // a hierarchy exists (perhaps of an earlier matrix)
  bool kept_ = false;   // the hierarchy in use was built for an earlier matrix
  SolverStats stats_;
};

void MultigridSolver::update(const Progress& progress) {
  Stopwatch watch;
  if (modes_.empty()) modes_ = near_null_space(*system_.nodes, *system_.free_dofs);
  kept_ = reuse_.keep(built_);
  if (kept_ && reuse_.refresh_coarse_on_update()) {
    // a recent solve found the kept coarse levels stale: recompute them now (R A P on the kept
    // aggregates) rather than lose the patience's iterations on them first
    amg_.refresh_galerkin();
    ++stats_.refreshes;
    kept_ = false;
    progress.info("multigrid kept, coarse matrices recomputed " + watch.lap());
  } else if (kept_) {
    // SIMP's next matrix: keep the hierarchy, refresh the finest smoother only (a solve that
    // finds the coarse levels stale recomputes them, see solve()).
    amg_.refresh_finest();
    progress.info("multigrid kept, finest level refreshed " + watch.lap());
  } else {
    set_up(progress);
  }
}

void MultigridSolver::set_up(const Progress& progress) {
  Stopwatch watch;
  AmgParams ap = params_.multigrid;
  ap.threads = system_.threads;
  amg_.setup(*system_.K, system_.K->blocks, modes_, ap);
  built_ = true;
  kept_ = false;
  reuse_.set_up();
  ++stats_.preparations;
  std::ostringstream s;
  s << "multigrid setup " << watch.lap() << ", " << amg_.levels() << " levels (";
  const std::vector<int> sizes = amg_.level_sizes();
  for (size_t l = 0; l < sizes.size(); ++l) s << (l ? ", " : "") << sizes[l];
  s << " unknowns), operator complexity " << amg_.complexity();
  progress.info(s.str());
}

PcgResult MultigridSolver::solve_one(const Eigen::VectorXd& b, Eigen::VectorXd& x, const Progress& progress) {
  PcgParams pp;
  pp.tolerance = params_.tolerance;
  pp.max_iterations = kept_ ? reuse_.patience(params_.max_iterations) : params_.max_iterations;
  return pcg(FinestOperator(amg_, system_.K->rows), amg_, b, x, pp, progress);
}

void MultigridSolver::solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X, const Progress& progress) {
  Stopwatch watch;
  const long nf = system_.K->rows;
  if (kept_) ++stats_.reuses;
  // The V-cycle's BLAS work (coarse triangular solves) is small: one BLAS thread, so that
  // OpenBLAS's spinning workers leave the cores to our sparse products.
  BlasThreadLimit blas_limit(1);
  Eigen::MatrixXd out(nf, B.cols());
  int worst = 0;
  bool rebuilt = false;  // a solve was cut short and finished on recomputed coarse levels
  for (long c = 0; c < B.cols(); ++c) {
    Eigen::VectorXd x = (X.rows() == nf && c < X.cols()) ? Eigen::VectorXd(X.col(c)) : Eigen::VectorXd::Zero(nf);
    const Eigen::VectorXd b = B.col(c);
    PcgResult r = solve_one(b, x, progress);
    if (!r.converged && kept_) {
      // the kept coarse levels no longer fit this matrix: recompute them from it on the kept
      // aggregates (R A P) and go on from where CG stopped. Cheaper than a setup; a solve
      // finished from a half-converged start is no reference (not recorded)
      progress.info("multigrid CG slow with the kept hierarchy (" + std::to_string(r.iterations) +
                    " iterations); coarse matrices recomputed");
      amg_.refresh_galerkin();
      ++stats_.refreshes;
      kept_ = false;
      rebuilt = true;
      const int cut = r.iterations;
      r = solve_one(b, x, progress);
      r.iterations += cut;  // the solve's iterations on both
    }
    if (!r.converged) {
      std::ostringstream s;
      s << "the iterative solver did not converge in " << r.iterations << " iterations (relative residual "
        << r.relative_residual << "); try the direct solver (\"solver\": \"direct\")";
      throw Error(ErrorCode::Internal, s.str());
    }
    worst = std::max(worst, r.iterations);
    out.col(c) = x;
  }
  progress.info("multigrid CG: " + std::to_string(worst) + " iterations, " + watch.lap());
  if (rebuilt)
    reuse_.cut(worst);
  else
    reuse_.record(worst);
  stats_.iterations = worst;
  X = out;
}

}  // namespace

std::unique_ptr<LinearSolver> make_multigrid_solver(const FreeSystem& system, const SolverParams& params) {
  return std::make_unique<MultigridSolver>(system, params);
}

}  // namespace topopt::fem
