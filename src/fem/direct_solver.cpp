// The direct solver: CHOLMOD's supernodal Cholesky (METIS ordering, symbolic analysis once per
// pattern). Between SIMP iterations the previous factor preconditions CG (warm-started from the
// previous displacements), and a new factor is made only when that would take more than
// SolverParams::recycle_iterations iterations (the rules: FactorReuse in solver_policy.h).
#include <Eigen/CholmodSupport>
#include <algorithm>
#include <vector>

#include "common/error.h"
#include "common/float_mode.h"
#include "common/stopwatch.h"
#include "fem/linear_solver.h"
#include "fem/pcg.h"
#include "fem/solver_policy.h"

namespace topopt::fem {

namespace {

using Cholesky = Eigen::CholmodSupernodalLLT<SparseLower, Eigen::Lower>;

/// The symmetric matrix whose lower triangle K holds, for pcg().
class LowerOperator final : public LinearOperator {
 public:
  explicit LowerOperator(const SparseLower& K) : K_(K) {}
  int size() const override { return static_cast<int>(K_.rows()); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override {
    y.noalias() = K_.selfadjointView<Eigen::Lower>() * x;
  }
  void residual(const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) const override {
    r = b - K_.selfadjointView<Eigen::Lower>() * x;
  }

 private:
  const SparseLower& K_;
};

/// The lower triangle of a symmetric matrix K held in full compressed rows (columns increasing
/// in each row) as the compressed columns CHOLMOD factorises, and where each of its entries
/// sits in K, so that K's new values are copied over without a search. Row c of K from the
/// diagonal on is column c of its lower triangle (K is symmetric).
struct LowerTriangle {
  SparseLower L;
  std::vector<int> from;  // nnz(L): the position in K.val of each entry of L

  explicit LowerTriangle(const CsrMatrix& K) {
    std::vector<int> outer(K.rows + 1, 0), inner;
    for (int c = 0; c < K.rows; ++c) {
      for (int k = K.ptr[c]; k < K.ptr[c + 1]; ++k)
        if (K.col[k] >= c) inner.push_back(K.col[k]), from.push_back(k);
      outer[c + 1] = static_cast<int>(inner.size());
    }
    const std::vector<double> zeros(inner.size(), 0.0);
    L = Eigen::Map<const SparseLower>(K.rows, K.cols, static_cast<long>(inner.size()), outer.data(), inner.data(),
                                      zeros.data());
    refill(K);
  }

  /// K has new values (same pattern): copies them into L.
  void refill(const CsrMatrix& K) {
    double* v = L.valuePtr();
    for (size_t k = 0; k < from.size(); ++k) v[k] = K.val[from[k]];
  }
};

/// A Cholesky factor (of this or an earlier matrix) as a preconditioner.
class FactorPreconditioner final : public Preconditioner {
 public:
  explicit FactorPreconditioner(const Cholesky& factor) : factor_(factor) {}
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override { z = factor_.solve(r); }

 private:
  const Cholesky& factor_;
};

class DirectSolver final : public LinearSolver {
 public:
  DirectSolver(const FreeSystem& system, const SolverParams& params)
      : full_(*system.K), lower_(full_), K_(lower_.L), params_(params), reuse_(params.recycle_factor) {}

  void update(const Progress& progress) override {
    lower_.refill(full_);
    if (factor_ == Factor::Current) factor_ = Factor::Earlier;
    if (reuse_.factorise_on_update(factor_ != Factor::None)) factorise(progress);
  }

  void solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X, const Progress& progress) override {
    if (factor_ == Factor::Earlier && reuse_.factorise_before_solve()) factorise(progress);
    if (factor_ == Factor::Earlier) {
      if (solve_with_earlier_factor(B, X, progress)) return;
      reuse_.recycling_failed();
      factorise(progress);
    }
    X = cholesky_.solve(B);
    stats_.iterations = 0;
  }

  SolverStats stats() const override { return stats_; }

 private:
  enum class Factor { None, Earlier, Current };  // the factor is of no, an earlier, this matrix

  void factorise(const Progress& progress);
  bool solve_with_earlier_factor(const Eigen::MatrixXd& B, Eigen::MatrixXd& X, const Progress& progress);

  const CsrMatrix& full_;  // the system's K, full storage
  LowerTriangle lower_;    // its lower triangle, refilled at each update
  const SparseLower& K_;   // lower_.L
  SolverParams params_;
  FactorReuse reuse_;
  Cholesky cholesky_;
  Factor factor_ = Factor::None;
  SolverStats stats_;
};

void DirectSolver::factorise(const Progress& progress) {
  Stopwatch watch;
  if (factor_ == Factor::None) {
    // Nested dissection (METIS) only: on 3D meshes it gives far less fill than AMD, and trying
    // several orderings (CHOLMOD's default) costs more than it saves.
    cholmod_common& c = cholesky_.cholmod();
    c.nmethods = 1;
    c.method[0].ordering = CHOLMOD_METIS;
    c.postorder = 1;
    cholesky_.analyzePattern(K_);
    progress.info("symbolic analysis " + watch.lap());
  }
  {
    // With SIMP's 1e-9 void stiffness, fill entries decay through void regions into the
    // subnormal range, where every operation costs ~100 times more (the factorisation slowed
    // 4x over a run without this).
    FlushSubnormals flush;
    cholesky_.factorize(K_);
  }
  if (cholesky_.info() != Eigen::Success)
    throw Error(ErrorCode::NoSupport,
                "the stiffness matrix is not positive definite (a part of the structure is "
                "not held, or elements are degenerate); check the supports");
  factor_ = Factor::Current;
  ++stats_.preparations;
  progress.info("factorisation " + watch.lap() + ", " + std::to_string(K_.rows()) + " unknowns");
}

/// CG preconditioned by the factor of an earlier matrix, warm-started from X, to
/// recycle_tolerance within recycle_iterations, giving up early when it would need more.
/// Returns false (X unchanged) if that failed for any load case or X does not fit B.
bool DirectSolver::solve_with_earlier_factor(const Eigen::MatrixXd& B, Eigen::MatrixXd& X, const Progress& progress) {
  Stopwatch watch;
  const long nf = K_.rows();
  if (X.rows() != nf || X.cols() != B.cols()) {
    progress.info("recycling abandoned after " + watch.lap());
    return false;
  }
  const LowerOperator A(K_);
  const FactorPreconditioner M(cholesky_);
  PcgParams pp;
  pp.tolerance = params_.recycle_tolerance;
  pp.max_iterations = params_.recycle_iterations;
  pp.give_up_when_slow = true;
  Eigen::MatrixXd out(nf, B.cols());
  int worst = 0;
  for (long c = 0; c < B.cols(); ++c) {
    Eigen::VectorXd x = X.col(c), b = B.col(c);
    const PcgResult r = pcg(A, M, b, x, pp, progress);
    worst = std::max(worst, r.iterations);
    if (!r.converged) {
      progress.info("recycling abandoned after " + watch.lap());
      return false;
    }
    out.col(c) = x;
  }
  X = out;
  ++stats_.reuses;
  stats_.iterations = worst;
  progress.info("recycled factor: " + std::to_string(worst) + " CG iterations, " + watch.lap());
  return true;
}

}  // namespace

std::unique_ptr<LinearSolver> make_direct_solver(const FreeSystem& system, const SolverParams& params) {
  return std::make_unique<DirectSolver>(system, params);
}

}  // namespace topopt::fem
