// The one conjugate-gradient loop: it reaches the tolerance with the true residual, takes one
// iteration with an exact preconditioner, stops for b = 0, a warm start at the solution, a
// breakdown, the iteration cap, a hopeless rate (when asked) and a cancellation.
#include "fem/pcg.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "fem/csr_matrix.h"

namespace topopt::fem {
namespace {

/// A dense symmetric matrix as an operator.
class DenseOperator final : public LinearOperator {
 public:
  explicit DenseOperator(Eigen::MatrixXd A) : A_(std::move(A)) {}
  int size() const override { return static_cast<int>(A_.rows()); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override { y = A_ * x; }
  void residual(const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) const override {
    r = b - A_ * x;
  }
  const Eigen::MatrixXd& matrix() const { return A_; }

 private:
  Eigen::MatrixXd A_;
};

class Identity final : public Preconditioner {
 public:
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override { z = r; }
};

class Jacobi final : public Preconditioner {
 public:
  explicit Jacobi(const Eigen::MatrixXd& A) : d_(A.diagonal()) {}
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override { z = r.cwiseQuotient(d_); }

 private:
  Eigen::VectorXd d_;
};

class ExactInverse final : public Preconditioner {
 public:
  explicit ExactInverse(const Eigen::MatrixXd& A) : llt_(A) {}
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override { z = llt_.solve(r); }

 private:
  Eigen::LLT<Eigen::MatrixXd> llt_;
};

/// The 1D Laplacian with n unknowns (condition number ~ 0.4 n²): CG needs ~n iterations.
Eigen::MatrixXd laplacian(int n) {
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    A(i, i) = 2;
    if (i > 0) A(i, i - 1) = A(i - 1, i) = -1;
  }
  return A;
}

TEST(Pcg, ReachesTheToleranceWithTheTrueResidual) {
  const int n = 60;
  Eigen::MatrixXd R = Eigen::MatrixXd::Random(n, n);
  const DenseOperator A(R * R.transpose() + n * Eigen::MatrixXd::Identity(n, n));
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1, 2);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  PcgParams p;
  p.tolerance = 1e-10;
  const PcgResult r = pcg(A, Jacobi(A.matrix()), b, x, p);
  ASSERT_TRUE(r.converged);
  EXPECT_LE(r.iterations, n);
  const double true_residual = (b - A.matrix() * x).norm() / b.norm();
  EXPECT_LE(true_residual, 1.01e-10);
  EXPECT_NEAR(r.relative_residual, true_residual, 1e-12);
}

TEST(Pcg, AnExactPreconditionerTakesOneIteration) {
  const DenseOperator A(laplacian(50));
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(50);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(50);
  const PcgResult r = pcg(A, ExactInverse(A.matrix()), b, x, PcgParams{});
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 1);
}

TEST(Pcg, ZeroRightHandSideAndExactWarmStartsNeedNoIteration) {
  const DenseOperator A(laplacian(10));
  Eigen::VectorXd x = Eigen::VectorXd::Ones(10);
  PcgResult r = pcg(A, Identity(), Eigen::VectorXd::Zero(10), x, PcgParams{});
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(x.norm(), 0.0);  // the solution of A x = 0, not the warm start
  const Eigen::VectorXd solution = Eigen::VectorXd::LinSpaced(10, 1, 3);
  x = solution;
  r = pcg(A, Identity(), A.matrix() * solution, x, PcgParams{});
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_EQ(x, solution);
}

TEST(Pcg, StopsAtABreakdownOfAnIndefiniteOperator) {
  const DenseOperator A(Eigen::Vector2d(1, -1).asDiagonal().toDenseMatrix());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2);
  const PcgResult r = pcg(A, Identity(), Eigen::VectorXd::Ones(2), x, PcgParams{});  // pᵀAp = 0
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_TRUE(x.allFinite());
}

TEST(Pcg, StopsAtTheCapAndGivesUpEarlyWhenTheRateIsHopeless) {
  const DenseOperator A(laplacian(400));
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(400);
  PcgParams p;
  p.tolerance = 1e-9;
  p.max_iterations = 20;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(400);
  PcgResult r = pcg(A, Identity(), b, x, p);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 20);
  p.give_up_when_slow = true;  // six iterations tell that 20 will not do
  x.setZero();
  r = pcg(A, Identity(), b, x, p);
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 6);
  // ... but a fast solve is not given up
  Eigen::MatrixXd D = laplacian(400) + 2 * Eigen::MatrixXd::Identity(400, 400);  // condition 3
  const DenseOperator easy(D);
  x.setZero();
  r = pcg(easy, Jacobi(D), b, x, p);
  EXPECT_TRUE(r.converged);
  EXPECT_GT(r.iterations, 6);
}

TEST(Pcg, CancellationIsCheckedWhileIterating) {
  const DenseOperator A(laplacian(200));
  Eigen::VectorXd x = Eigen::VectorXd::Zero(200);
  int asked = 0;
  Progress progress;
  progress.cancelled = [&asked] { return ++asked >= 2; };
  PcgParams p;
  p.tolerance = 1e-12;
  try {
    pcg(A, Identity(), Eigen::VectorXd::Ones(200), x, p, progress);
    FAIL() << "not cancelled";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Cancelled);
  }
  EXPECT_EQ(asked, 2);  // asked at iterations 16 and 32
}

TEST(Pcg, CsrOperatorResidualIsTheTrueResidual) {
  CsrMatrix M;  // [[4, 1], [1, 3]]
  M.rows = M.cols = 2;
  M.ptr = {0, 2, 4};
  M.col = {0, 1, 0, 1};
  M.val = {4, 1, 1, 3};
  const CsrOperator A(M, 1);
  Eigen::VectorXd r(2), y(2);
  A.residual(Eigen::Vector2d(1, 2), Eigen::Vector2d(1, -1), r);
  EXPECT_EQ(r, Eigen::Vector2d(1 - 3, 2 + 2));
  A.apply(Eigen::Vector2d(1, -1), y);
  EXPECT_EQ(y, Eigen::Vector2d(3, -2));
}

}  // namespace
}  // namespace topopt::fem
