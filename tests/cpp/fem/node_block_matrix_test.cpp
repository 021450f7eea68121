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

/// The products of pattern p (built from M) with M's values in double and in single precision,
/// on 1 and 2 threads, by the scalar kernel and (where the CPU has AVX) the AVX one, against
/// sparse_product's row walk (to the bit) and dense arithmetic, for a random x drawn with `seed`.
template <class Pattern>
void expect_products_equal_the_row_walk(const Pattern& p, const CsrMatrix& M, unsigned seed) {
  std::vector<double> vd, scratch;
  std::vector<float> vf;
  p.fill(M, vd);
  p.fill(M, vf);
  const std::vector<float> single(M.val.begin(), M.val.end());
  std::mt19937 rng(seed);
  std::normal_distribution<double> N;
  Eigen::VectorXd x(M.cols);
  for (int i = 0; i < M.cols; ++i) x[i] = N(rng);
  const Eigen::VectorXd ref = dense(M) * x;
  using Kernel = NodeBlockPattern::Kernel;
  for (Kernel kernel : {Kernel::Scalar, Kernel::Avx})
    for (int threads : {1, 2}) {
      if (kernel == Kernel::Avx && NodeBlockPattern::fastest_kernel() != Kernel::Avx) continue;
      Eigen::VectorXd walk(M.rows), blocks(M.rows), walk_f(M.rows), blocks_f(M.rows);
      sparse_product(M, M.val.data(), x.data(), walk.data(), threads);
      p.multiply(vd, x.data(), blocks.data(), scratch, threads, kernel);
      sparse_product(M, single.data(), x.data(), walk_f.data(), threads);
      p.multiply(vf, x.data(), blocks_f.data(), scratch, threads, kernel);
      const int k = static_cast<int>(kernel);
      EXPECT_EQ(blocks, walk) << "kernel " << k << ", " << threads << " threads";  // the same terms, order
      EXPECT_EQ(blocks_f, walk_f) << "kernel " << k << ", " << threads << " threads";
      EXPECT_LT((blocks - ref).norm(), 1e-13 * ref.norm());
      EXPECT_GT((blocks_f - blocks).norm(), 0.0);  // the float values were read
    }
}

void expect_row_walk_sums(const CsrMatrix& M, bool padded) {
  NodeBlockPattern p;
  ASSERT_TRUE(p.build(M));
  EXPECT_EQ(p.padded, padded);
  expect_products_equal_the_row_walk(p, M, 9);
}

TEST(NodeBlockMatrix, ProductsEqualTheRowWalkToTheBit) {
  expect_row_walk_sums(node_matrix(300, {3}, 1), false);
  // nodes with fixed dofs, about one in six (few enough for the padding: kMaxFill)
  expect_row_walk_sums(node_matrix(300, {3, 3, 3, 2, 3, 3, 3, 3, 1, 3, 3, 3}, 2), true);
}

TEST(NodeBlockMatrix, BothKernelsEqualTheRowWalkToTheBit) {
  // the AVX kernel (a node's three rows in one register's lanes) and the scalar one, each against
  // the row walk in double and single precision, with and without padded nodes, on 1 and 2 threads
  using Kernel = NodeBlockPattern::Kernel;
#if TOPOPT_AVX_KERNELS
  const bool avx = __builtin_cpu_supports("avx");
#else
  const bool avx = false;
#endif
  EXPECT_EQ(NodeBlockPattern::fastest_kernel(), avx ? Kernel::Avx : Kernel::Scalar);
  for (const std::vector<int>& sizes : {std::vector<int>{3}, std::vector<int>{3, 3, 3, 2, 3, 3, 3, 3, 1, 3, 3, 3}}) {
    const CsrMatrix M = node_matrix(400, sizes, 31);
    NodeBlockPattern p;
    ASSERT_TRUE(p.build(M));
    std::vector<double> vd, scratch;
    std::vector<float> vf;
    p.fill(M, vd);
    p.fill(M, vf);
    ASSERT_EQ(vd.size(), p.values());
    const std::vector<float> single(M.val.begin(), M.val.end());
    std::mt19937 rng(32);
    std::normal_distribution<double> N;
    Eigen::VectorXd x(M.cols), walk(M.rows), walk_f(M.rows);
    for (int i = 0; i < M.cols; ++i) x[i] = N(rng);
    sparse_product(M, M.val.data(), x.data(), walk.data(), 1);
    sparse_product(M, single.data(), x.data(), walk_f.data(), 1);
    for (Kernel kernel : {Kernel::Scalar, Kernel::Avx}) {
      if (kernel == Kernel::Avx && !avx) continue;
      for (int threads : {1, 2}) {
        Eigen::VectorXd y(M.rows), y_f(M.rows);
        p.multiply(vd, x.data(), y.data(), scratch, threads, kernel);
        p.multiply(vf, x.data(), y_f.data(), scratch, threads, kernel);
        EXPECT_EQ(y, walk) << static_cast<int>(kernel) << ", " << threads << " threads";
        EXPECT_EQ(y_f, walk_f) << static_cast<int>(kernel) << ", " << threads << " threads";
      }
    }
  }
}

TEST(NodeBlockMatrix, OneWalkFillsBothPrecisionsAndARefillKeepsThePaddingZero) {
  CsrMatrix M = node_matrix(200, {3, 3, 3, 2, 3, 3, 3, 3, 1, 3, 3, 3}, 6);
  NodeBlockPattern p;
  ASSERT_TRUE(p.build(M));
  ASSERT_TRUE(p.padded);
  std::vector<double> exact, fresh_d;
  std::vector<float> single, fresh_f;
  p.fill(M, exact, single);
  for (int round = 0; round < 2; ++round) {  // the first fill, then a refill of new values
    p.fill(M, fresh_d);
    p.fill(M, fresh_f);
    EXPECT_EQ(exact, fresh_d) << round;
    EXPECT_EQ(single, fresh_f) << round;
    for (double& v : M.val) v = 2 * v + 0.25;  // every entry changes (none becomes 0)
    p.fill(M, exact, single);
  }
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

/// A rows-by-cols matrix whose row blocks (`row_sizes` cycled) share their columns and whose
/// columns come in blocks (`col_sizes` cycled; the offsets in `col_first`): each row block reaches
/// random column blocks, in a random order (as the prolongator's rows meet their aggregates), a
/// block's columns consecutive and increasing, some of them left out.
CsrMatrix transfer_matrix(int row_blocks, const std::vector<int>& row_sizes, int col_blocks,
                          const std::vector<int>& col_sizes, unsigned seed, std::vector<int>& col_first) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> value(-1, 1);
  std::bernoulli_distribution reach(0.2), drop(0.04);
  col_first.assign(1, 0);
  for (int j = 0; j < col_blocks; ++j) col_first.push_back(col_first.back() + col_sizes[j % col_sizes.size()]);
  CsrMatrix M;
  M.blocks.assign(1, 0);
  for (int b = 0; b < row_blocks; ++b) M.blocks.push_back(M.blocks.back() + row_sizes[b % row_sizes.size()]);
  M.rows = M.blocks.back();
  M.cols = col_first.back();
  M.ptr.assign(1, 0);
  for (int b = 0; b < row_blocks; ++b) {
    std::vector<int> reached;
    for (int j = 0; j < col_blocks; ++j)
      if (reach(rng) || j == b % col_blocks) reached.push_back(j);
    std::shuffle(reached.begin(), reached.end(), rng);
    std::vector<int> cols;
    for (int j : reached) {
      const size_t before = cols.size();
      for (int c = col_first[j]; c < col_first[j + 1]; ++c)
        if (!drop(rng)) cols.push_back(c);
      if (cols.size() == before) cols.push_back(col_first[j]);
    }
    for (int r = M.blocks[b]; r < M.blocks[b + 1]; ++r) {
      for (int c : cols) M.col.push_back(c), M.val.push_back(value(rng));
      M.ptr.push_back(static_cast<int>(M.col.size()));
    }
  }
  return M;
}

template <int RB, int CB>
void expect_transfer_row_walk_sums(const CsrMatrix& M, const std::vector<int>& col_first) {
  BlockPattern<RB, CB> p;
  ASSERT_TRUE(p.build(M, col_first));
  expect_products_equal_the_row_walk(p, M, 13);
}

TEST(NodeBlockMatrix, TransferProductsEqualTheRowWalkToTheBit) {
  // the prolongator's shape: node blocks of 1-3 rows by aggregates of 1-6 coarse dofs, and the
  // restriction's (its transpose's): aggregates by nodes; full blocks only, and some padded
  std::vector<int> cf;
  for (const auto& [rows, cols] : {std::pair<std::vector<int>, std::vector<int>>{{3}, {6}},
                                   {{3, 3, 3, 2, 3, 3, 3, 3, 3, 1}, {6, 6, 6, 6, 5, 6, 6, 6, 6, 3}}}) {
    CsrMatrix P = transfer_matrix(400, rows, 60, cols, 21, cf);
    expect_transfer_row_walk_sums<3, 6>(P, cf);
    CsrMatrix R = transfer_matrix(60, cols, 400, rows, 22, cf);
    expect_transfer_row_walk_sums<6, 3>(R, cf);
  }
}

TEST(NodeBlockMatrix, TransfersTheBlocksDoNotFitAreRefused) {
  std::vector<int> cf;
  const CsrMatrix P = transfer_matrix(100, {3}, 20, {6}, 23, cf);
  ProlongatorBlocks p;
  ASSERT_TRUE(p.build(P, cf));
  EXPECT_FALSE(p.empty());
  RestrictionBlocks r;
  EXPECT_FALSE(r.build(P, cf));  // row blocks of 3 fit, but column blocks of 6 are more than 3
  std::vector<int> wide;
  EXPECT_FALSE(p.build(transfer_matrix(100, {3}, 20, {7}, 24, wide), wide));  // 7 columns a block
  EXPECT_TRUE(p.empty());
  // rows over two column blocks of 6: the blocks in any order, each block's columns
  // consecutive in the row and increasing
  auto one_row = [](const std::vector<int>& cols) {  // a block of 3 rows with these columns
    CsrMatrix M;
    const int n = static_cast<int>(cols.size());
    M.rows = 3, M.cols = 12, M.blocks = {0, 3}, M.ptr = {0, n, 2 * n, 3 * n};
    for (int r = 0; r < 3; ++r) M.col.insert(M.col.end(), cols.begin(), cols.end());
    M.val.assign(M.col.size(), 1.0);
    return M;
  };
  const std::vector<int> two = {0, 6, 12};
  EXPECT_TRUE(p.build(one_row({6, 7, 8, 9, 10, 11, 0, 1, 2, 3, 4, 5}), two));
  EXPECT_FALSE(p.build(one_row({0, 1, 2, 6, 7, 8, 9, 10, 11, 3, 4, 5}), two));  // block 0 met twice
  EXPECT_FALSE(p.build(one_row({1, 0, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11}), two));  // not increasing
  CsrMatrix no_blocks = P;
  no_blocks.blocks.clear();
  EXPECT_FALSE(p.build(no_blocks, cf));
  std::vector<int> scalar(P.cols + 1);  // one column a block: 18 values stored for at most 3
  for (int c = 0; c <= P.cols; ++c) scalar[c] = c;
  EXPECT_FALSE(p.build(P, scalar));
}

}  // namespace
}  // namespace topopt::fem
