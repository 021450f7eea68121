// Sparse matrix kernels against dense arithmetic: products with and without row blocks, the
// single-precision product, the matrix product (whole, a slice of rows at a time, and values
// only on a kept pattern by slices of its right factor) and the transpose.
#include "fem/csr_matrix.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <random>
#include <utility>

#include "fem/dense_of.h"

namespace topopt::fem {
namespace {

/// A random sparse matrix whose rows come in blocks of `block` rows sharing their columns.
CsrMatrix random_blocked(int rows, int cols, int block, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(-1, 1);
  std::bernoulli_distribution keep(0.3);
  CsrMatrix M;
  M.rows = rows;
  M.cols = cols;
  M.ptr.assign(1, 0);
  for (int r0 = 0; r0 < rows; r0 += block) {
    std::vector<int> cols_of_block;
    for (int c = cols - 1; c >= 0; --c)  // any order within a row
      if (keep(rng)) cols_of_block.push_back(c);
    const int nr = std::min(block, rows - r0);
    for (int r = 0; r < nr; ++r) {
      for (int c : cols_of_block) M.col.push_back(c), M.val.push_back(value(rng));
      M.ptr.push_back(static_cast<int>(M.col.size()));
    }
    M.blocks.push_back(r0);
  }
  M.blocks.push_back(rows);
  return M;
}

TEST(CsrMatrix, ProductsEqualDenseArithmetic) {
  const CsrMatrix A = random_blocked(30, 20, 3, 1);
  ASSERT_TRUE(A.blocks_consistent());
  CsrMatrix plain = A;
  plain.blocks.clear();
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(20, -2, 3);
  const Eigen::VectorXd ref = dense(A) * x;
  Eigen::VectorXd y(30), z(30), w(30);
  A.multiply(x.data(), y.data(), 2);
  plain.multiply(x.data(), z.data(), 1);
  EXPECT_LT((y - ref).norm(), 1e-13 * ref.norm());
  EXPECT_EQ(y, z);  // blocks change the walk, not the sums
  const std::vector<float> single(A.val.begin(), A.val.end());
  sparse_product(A, single.data(), x.data(), w.data(), 2);
  EXPECT_LT((w - ref).norm(), 1e-6 * ref.norm());
  EXPECT_GT((w - ref).norm(), 0.0);  // it did use the float values
  Eigen::VectorXd w1(30);  // the V-cycle's single-precision product, one thread and two alike
  sparse_product(plain, single.data(), x.data(), w1.data(), 1);
  EXPECT_EQ(w1, w);
}

TEST(CsrMatrix, MatrixProductAndTransposeEqualDenseArithmetic) {
  const CsrMatrix A = random_blocked(24, 18, 4, 2), B = random_blocked(18, 11, 1, 3);
  const CsrMatrix C = multiply(A, B, 2);
  EXPECT_LT((dense(C) - dense(A) * dense(B)).norm(), 1e-12 * (dense(A) * dense(B)).norm());
  EXPECT_EQ(C.blocks, A.blocks);
  EXPECT_TRUE(C.blocks_consistent());
  const CsrMatrix T = transpose(A);
  EXPECT_EQ(T.rows, A.cols);
  EXPECT_EQ(T.cols, A.rows);
  EXPECT_EQ(dense(T), dense(A).transpose());
}

/// Rows first .. last − 1 of M as a matrix of their own.
CsrMatrix rows_of(const CsrMatrix& M, int first, int last) {
  CsrMatrix S;
  S.rows = last - first;
  S.cols = M.cols;
  S.ptr.assign(1, 0);
  for (int i = first; i < last; ++i) {
    S.col.insert(S.col.end(), M.col.begin() + M.ptr[i], M.col.begin() + M.ptr[i + 1]);
    S.val.insert(S.val.end(), M.val.begin() + M.ptr[i], M.val.begin() + M.ptr[i + 1]);
    S.ptr.push_back(static_cast<int>(S.col.size()));
  }
  return S;
}

TEST(CsrMatrix, ProductBySlicesMatchesAFreshProductToTheBit) {
  for (const bool blocked : {true, false}) {
    CsrMatrix A = random_blocked(24, 18, 4, 5), B = random_blocked(18, 11, 1, 6);
    if (!blocked) A.blocks.clear();
    for (int i = 0; i < A.rows; ++i) {  // add_product_rows wants increasing columns (as a transpose has)
      std::vector<std::pair<int, double>> row;
      for (int k = A.ptr[i]; k < A.ptr[i + 1]; ++k) row.push_back({A.col[k], A.val[k]});
      std::sort(row.begin(), row.end());
      for (size_t k = 0; k < row.size(); ++k) A.col[A.ptr[i] + k] = row[k].first, A.val[A.ptr[i] + k] = row[k].second;
    }
    // the rows of a product a slice of row blocks at a time are the whole product's
    const CsrMatrix whole = multiply(A, B, 2);
    const long blocks = row_blocks(A);
    const CsrMatrix top = multiply_rows(A, B, 0, blocks / 2, 2), bottom = multiply_rows(A, B, blocks / 2, blocks, 1);
    const int split = blocked ? A.blocks[blocks / 2] : static_cast<int>(blocks / 2);
    for (const auto& [part, first] : {std::pair{&top, 0}, std::pair{&bottom, split}}) {
      const CsrMatrix expected = rows_of(whole, first, first + part->rows);
      EXPECT_EQ(part->col, expected.col);
      EXPECT_EQ(part->val, expected.val);
      EXPECT_TRUE(part->blocks_consistent());
    }
    // new values, same patterns (SIMP's next stiffness on kept aggregates): C = A B again by
    // slices of B's rows, the values of a fresh product to the bit
    CsrMatrix C = whole;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> value(-2, 2);
    for (double& v : A.val) v = value(rng);
    for (double& v : B.val) v = value(rng);
    const CsrMatrix fresh = multiply(A, B, 2);
    std::fill(C.val.begin(), C.val.end(), 0.0);
    std::vector<int> cursor(blocks);
    for (long b = 0; b < blocks; ++b) cursor[b] = A.ptr[blocked ? A.blocks[b] : b];
    for (const auto& [first, last] : {std::pair{0, 5}, std::pair{5, 6}, std::pair{6, 13}, std::pair{13, 18}})
      add_product_rows(A, rows_of(B, first, last), first, cursor, C, 2);
    EXPECT_EQ(C.ptr, fresh.ptr);
    EXPECT_EQ(C.col, fresh.col);
    EXPECT_EQ(C.val, fresh.val) << (blocked ? "blocked" : "one row a block");
    EXPECT_NE(C.val, whole.val);  // the values were rewritten
    EXPECT_LT((dense(C) - dense(A) * dense(B)).norm(), 1e-12 * (dense(A) * dense(B)).norm());
  }
}

TEST(CsrMatrix, ProductBySlicesTakesANodesThreeRowsInOnePassToTheBit) {
  // R = Pᵀ with P's rows in node blocks of 3 sharing their columns (the prolongator's), so R's
  // rows meet a node's three rows together; X = B's rows in node blocks of 3, a slice at a time on
  // block boundaries with its blocks (the refresh's A P): add_product_rows adds a node's three
  // rows of X in one pass where R's entries reach all three. The fresh product's values to the bit.
  const CsrMatrix P = random_blocked(30, 8, 3, 41), B = random_blocked(30, 7, 3, 42);
  const CsrMatrix R = transpose(P);  // one row a block, columns increasing
  const CsrMatrix fresh = multiply(R, B, 1);
  for (int threads : {1, 2}) {
    CsrMatrix C = fresh;
    std::fill(C.val.begin(), C.val.end(), 0.0);
    std::vector<int> cursor(R.ptr.begin(), R.ptr.end() - 1);
    for (const auto& [first, last] : {std::pair{0, 9}, std::pair{9, 12}, std::pair{12, 30}}) {
      CsrMatrix X = rows_of(B, first, last);
      for (int r = 0; r <= X.rows; r += 3) X.blocks.push_back(r);
      ASSERT_TRUE(X.blocks_consistent());
      add_product_rows(R, X, first, cursor, C, threads);
    }
    EXPECT_EQ(C.val, fresh.val) << threads << " threads";
  }
}

TEST(CsrMatrix, InconsistentBlocksAreDetected) {
  CsrMatrix A;  // rows 0 and 1 on columns {0, 1}, row 2 on {2}, row 3 on {2, 3}
  A.rows = A.cols = 4;
  A.ptr = {0, 2, 4, 5, 7};
  A.col = {0, 1, 0, 1, 2, 2, 3};
  A.val.assign(7, 1.0);
  A.blocks = {0, 2, 3, 4};
  EXPECT_TRUE(A.blocks_consistent());
  A.blocks = {0, 2, 4};  // rows 2 and 3 differ
  EXPECT_FALSE(A.blocks_consistent());
  A.blocks = {0, 2, 3};  // does not end at the last row
  EXPECT_FALSE(A.blocks_consistent());
  CsrMatrix tall;  // nine rows on the same column: one block too many rows
  tall.rows = 9;
  tall.cols = 1;
  for (int i = 0; i <= 9; ++i) tall.ptr.push_back(i);
  tall.col.assign(9, 0);
  tall.val.assign(9, 1.0);
  tall.blocks = {0, 9};
  EXPECT_FALSE(tall.blocks_consistent());
  tall.blocks = {0, 8, 9};
  EXPECT_TRUE(tall.blocks_consistent());
}

}  // namespace
}  // namespace topopt::fem
