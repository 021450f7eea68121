// The iterative solver: CG preconditioned by our smoothed-aggregation multigrid (fem/amg.h) on
// a full CSR copy of K, warm-started from the previous solution. Between SIMP iterations the
// hierarchy is kept (only its finest smoother refreshed) until the iteration count grows by
// half (HierarchyReuse in solver_policy.h); a solve on a kept hierarchy that reaches that growth
// is cut there, the coarse matrices are recomputed from the new matrix on the kept aggregates
// (refresh_galerkin) and CG goes on. Cantilever, 63 k tets, 20 SIMP iterations: 6 setups and 431
// CG iterations before, 1 setup, 9 coarse refreshes and ~460 CG iterations after, at about the
// same CPU time (BENCHMARKS.md, speed targets).
#include <algorithm>
#include <sstream>

#include "common/blas_threads.h"
#include "common/error.h"
#include "common/parallel.h"
#include "common/stopwatch.h"
#include "fem/amg.h"
#include "fem/linear_solver.h"
#include "fem/pcg.h"
#include "fem/solver_policy.h"

namespace topopt::fem {

namespace {

/// K (lower triangle, compressed columns) in full compressed rows, and for each of K's
/// entries its one or two positions there (the second -1 on the diagonal), so that new values
/// of K are copied over without a search.
struct FullCopy {
  CsrMatrix full;
  std::vector<int> pos;  // 2 * nnz(K)
};

FullCopy full_copy(const SparseLower& K) {
  FullCopy f;
  CsrMatrix& full = f.full;
  const int nf = static_cast<int>(K.rows());
  const int* op = K.outerIndexPtr();
  const int* ip = K.innerIndexPtr();
  full.rows = full.cols = nf;
  full.ptr.assign(nf + 1, 0);
  for (int c = 0; c < nf; ++c)
    for (int k = op[c]; k < op[c + 1]; ++k) {
      ++full.ptr[ip[k] + 1];
      if (ip[k] != c) ++full.ptr[c + 1];
    }
  for (int i = 0; i < nf; ++i) full.ptr[i + 1] += full.ptr[i];
  full.col.assign(full.ptr[nf], 0);
  full.val.assign(full.ptr[nf], 0.0);
  f.pos.assign(2 * static_cast<size_t>(K.nonZeros()), -1);
  std::vector<int> fill(full.ptr.begin(), full.ptr.end() - 1);
  for (int c = 0; c < nf; ++c)
    for (int k = op[c]; k < op[c + 1]; ++k) {
      const int r = ip[k];
      f.pos[2 * k] = fill[r];
      full.col[fill[r]++] = c;
      if (r != c) {
        f.pos[2 * k + 1] = fill[c];
        full.col[fill[c]++] = r;
      }
    }
  return f;
}

class MultigridSolver final : public LinearSolver {
 public:
  MultigridSolver(const FreeSystem& system, const SolverParams& params)
      : system_(system), params_(params), reuse_(params.recycle_factor) {}

  void update(const Progress& progress) override;
  void solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X, const Progress& progress) override;
  SolverStats stats() const override { return stats_; }

 private:
  void refill();
  void set_up(const Progress& progress);
  PcgResult solve_one(const Eigen::VectorXd& b, Eigen::VectorXd& x, const Progress& progress);

  FreeSystem system_;
  SolverParams params_;
  HierarchyReuse reuse_;
  FullCopy copy_;              // K in full rows (built at the first update)
  std::vector<int> blocks_;    // node_blocks of the free dofs
  std::vector<double> modes_;  // near_null_space, nf by 6
  SmoothedAggregationAmg amg_;
  bool built_ = false;  // a hierarchy exists (perhaps of an earlier matrix)
  bool kept_ = false;   // the hierarchy in use was built for an earlier matrix
  SolverStats stats_;
};

void MultigridSolver::update(const Progress& progress) {
  Stopwatch watch;
  if (copy_.full.rows != system_.K->rows()) {
    copy_ = full_copy(*system_.K);
    blocks_ = node_blocks(*system_.free_dofs);
    copy_.full.blocks = blocks_;  // a node's rows share their columns (the pattern is per node pair)
    modes_ = near_null_space(*system_.nodes, *system_.free_dofs);
  }
  refill();
  kept_ = reuse_.keep(built_);
  if (kept_ && reuse_.refresh_coarse_on_update()) {
    // a recent solve found the kept coarse levels stale: recompute them now (R A P on the kept
    // aggregates) rather than lose the patience's iterations on them first
    amg_.refresh_galerkin();
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

void MultigridSolver::refill() {
  const double* v = system_.K->valuePtr();
  const std::vector<int>& pos = copy_.pos;
  std::vector<double>& val = copy_.full.val;
  parallel_for(
      system_.K->nonZeros(), system_.threads,
      [&](long b, long e) {
        for (long k = b; k < e; ++k) {
          val[pos[2 * k]] = v[k];
          if (pos[2 * k + 1] >= 0) val[pos[2 * k + 1]] = v[k];
        }
      },
      1 << 16);
}

void MultigridSolver::set_up(const Progress& progress) {
  Stopwatch watch;
  AmgParams ap = params_.multigrid;
  ap.threads = system_.threads;
  amg_.setup(copy_.full, blocks_, modes_, ap);
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
  return pcg(CsrOperator(copy_.full, system_.threads), amg_, b, x, pp, progress);
}

void MultigridSolver::solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X, const Progress& progress) {
  Stopwatch watch;
  const long nf = system_.K->rows();
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
      // aggregates (R A P) and go on from where CG stopped. Cheaper than a setup, and as good
      // for the next solves; the baseline stays the last setup's (a solve finished from a
      // half-converged start is none)
      progress.info("multigrid CG slow with the kept hierarchy (" + std::to_string(r.iterations) +
                    " iterations); coarse matrices recomputed");
      amg_.refresh_galerkin();
      reuse_.cut();
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
  if (!rebuilt) reuse_.record(worst);
  stats_.iterations = worst;
  X = out;
}

}  // namespace

std::unique_ptr<LinearSolver> make_multigrid_solver(const FreeSystem& system, const SolverParams& params) {
  return std::make_unique<MultigridSolver>(system, params);
}

}  // namespace topopt::fem
