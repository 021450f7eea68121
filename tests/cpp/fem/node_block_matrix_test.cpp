// The 3×3 node-block products against the row walk of sparse_product (the same sums to the bit,
// in double and in single precision) and dense arithmetic, on matrices whose node blocks have 1
// to 3 rows (nodes with fixed dofs: padded blocks); and the matrices the blocks refuse.
#include "fem/node_block_matrix.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <random>
#include <utility>

#include "fem/dense_of.h"

namespace topopt::fem {
namespace {

/// A square matrix of `nodes` node blocks with 1 to 3 rows each (`sizes` cycled), each node
/// coupled to itself and to random other nodes, columns increasing within a row (as K's).
CsrMatrix node_matrix(int nodes, const std::vector<int>& sizes, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(-1, 1);
  std::bernoulli_distribution couple(0.15);
  CsrMatrix M;
  M.blocks.assign(1, 0);
  for (int n = 0; n < nodes; ++n) M.blocks.push_back(M.blocks.back() + sizes[n % sizes.size()]);
  M.rows = M.cols = M.blocks.back();
  M.ptr.assign(1, 0);
  for (int n = 0; n < nodes; ++n) {
    std::vector<int> cols;
    for (int m = 0; m < nodes; ++m)
      if (m == n || couple(rng))
        for (int c = M.blocks[m]; c < M.blocks[m + 1]; ++c) cols.push_back(c);
    for (int r = M.blocks[n]; r < M.blocks[n + 1]; ++r) {
      for (int c : cols) M.col.push_back(c), M.val.push_back(value(rng));
      M.ptr.push_back(static_cast<int>(M.col.size()));
    }
  }
  return M;
}

void expect_row_walk_sums(const CsrMatrix& M, bool padded) {
  NodeBlockPattern p;
  ASSERT_TRUE(p.build(M));
  EXPECT_EQ(p.padded, padded);
  std::vector<double> vd, scratch;
  std::vector<float> vf;
  p.fill(M, vd);
  p.fill(M, vf);
  const std::vector<float> single(M.val.begin(), M.val.end());
  std::mt19937 rng(9);
  std::normal_distribution<double> N;
  Eigen::VectorXd x(M.rows);
  for (int i = 0; i < M.rows; ++i) x[i] = N(rng);
  const Eigen::VectorXd ref = dense(M) * x;
  for (int threads : {1, 2}) {
    Eigen::VectorXd walk(M.rows), blocks(M.rows), walk_f(M.rows), blocks_f(M.rows);
    sparse_product(M, M.val.data(), x.data(), walk.data(), threads);
    p.multiply(vd, x.data(), blocks.data(), scratch, threads);
    sparse_product(M, single.data(), x.data(), walk_f.data(), threads);
    p.multiply(vf, x.data(), blocks_f.data(), scratch, threads);
    EXPECT_EQ(blocks, walk) << threads << " threads";  // the same terms in the same order
    EXPECT_EQ(blocks_f, walk_f) << threads << " threads";
    EXPECT_LT((blocks - ref).norm(), 1e-13 * ref.norm());
    EXPECT_GT((blocks_f - blocks).norm(), 0.0);  // the float values were read
  }
}

TEST(NodeBlockMatrix, ProductsEqualTheRowWalkToTheBit) {
  expect_row_walk_sums(node_matrix(300, {3}, 1), false);
  // nodes with fixed dofs, about one in six (few enough for the padding: kMaxFill)
  expect_row_walk_sums(node_matrix(300, {3, 3, 3, 2, 3, 3, 3, 3, 1, 3, 3, 3}, 2), true);
}

TEST(NodeBlockMatrix, MatrixProductFromTheBlocksEqualsTheRowWalksToTheBit) {
  // M B with B = M X: B has M's row blocks, each block's rows sharing their columns (as the
  // smoothed prolongator has them); the refresh forms M B a slice of row blocks at a time.
  for (const std::vector<int>& sizes : {std::vector<int>{3}, std::vector<int>{3, 3, 3, 2, 3, 3, 3, 3, 1, 3, 3, 3}}) {
    const CsrMatrix M = node_matrix(120, sizes, 11);
    CsrMatrix X;  // a sparse random M.cols by 40 matrix
    std::mt19937 rng(12);
    std::uniform_real_distribution<double> value(-1, 1);
    X.rows = M.cols;
    X.cols = 40;
    X.ptr.assign(1, 0);
    for (int i = 0; i < X.rows; ++i) {
      for (int c = 0; c < X.cols; ++c)
        if (rng() % 5 == 0) X.col.push_back(c), X.val.push_back(value(rng));
      X.ptr.push_back(static_cast<int>(X.col.size()));
    }
    const CsrMatrix B = multiply(M, X, 1);
    ASSERT_EQ(B.blocks, M.blocks);
    ASSERT_TRUE(B.blocks_consistent());
    NodeBlockPattern p;
    ASSERT_TRUE(p.build(M));
    std::vector<double> v;
    p.fill(M, v);
    const long nb = row_blocks(M);
    for (const auto& [first, last] : {std::pair<long, long>{0, nb}, {17, 61}, {nb - 5, nb}})
      for (int threads : {1, 2}) {
        const CsrMatrix by_rows = multiply_rows(M, B, first, last, threads);
        const CsrMatrix by_blocks = multiply_rows(p, v, M, B, first, last, threads);
        EXPECT_EQ(by_blocks.rows, by_rows.rows);
        EXPECT_EQ(by_blocks.ptr, by_rows.ptr);
        EXPECT_EQ(by_blocks.col, by_rows.col);
        EXPECT_EQ(by_blocks.val, by_rows.val) << first << ".." << last << ", " << threads << " threads";
        EXPECT_EQ(by_blocks.blocks, by_rows.blocks);
      }
    const Eigen::MatrixXd ref = dense(M) * dense(B);  // and the product is the product
    EXPECT_LT((dense(multiply_rows(p, v, M, B, 0, nb, 1)) - ref).norm(), 1e-12 * ref.norm());
  }
}

TEST(NodeBlockMatrix, MatricesTheBlocksDoNotFitAreRefused) {
  NodeBlockPattern p;
  CsrMatrix M = node_matrix(50, {3}, 3);
  ASSERT_TRUE(p.build(M));
  EXPECT_FALSE(p.empty());
  CsrMatrix four = node_matrix(50, {4}, 4);  // a block of more than 3 rows
  EXPECT_FALSE(p.build(four));
  EXPECT_TRUE(p.empty());
  EXPECT_FALSE(p.build(node_matrix(200, {1}, 5)));  // a scalar problem: 9 values stored for 1
  CsrMatrix unsorted = M;                           // a row's columns not increasing
  for (int i = 0; i < unsorted.rows; ++i)
    std::reverse(&unsorted.col[unsorted.ptr[i]], &unsorted.col[unsorted.ptr[i + 1]]);
  EXPECT_FALSE(p.build(unsorted));
  CsrMatrix no_blocks = M;
  no_blocks.blocks.clear();
  EXPECT_FALSE(p.build(no_blocks));
}

}  // namespace
}  // namespace topopt::fem
