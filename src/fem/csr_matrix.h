// A sparse matrix in compressed rows, with the kernels the multigrid needs: the product with a
// vector (in double, or with single-precision copies of the values), the product of two
// matrices and the transpose. It stays a matrix and not a common/adjacency.h Adjacency: it
// carries values, a column count and row blocks, and what is done with it is matrix algebra.
#pragma once
#include <Eigen/Core>
#include <algorithm>
#include <vector>

#include "common/parallel.h"

#include "fem/pcg.h"

namespace topopt::fem {

/// A sparse matrix in compressed rows, full storage (both triangles of a symmetric one).
struct CsrMatrix {
  int rows = 0, cols = 0;
  std::vector<int> ptr;     ///< rows+1 offsets into col/val
  std::vector<int> col;     ///< column of each entry (any order within a row)
  std::vector<double> val;  ///< value of each entry
  /// Optional row blocks (offsets, first 0, last rows): the rows of a block have the same
  /// columns in the same order (a mesh node's dofs, an aggregate's coarse dofs), so products
  /// read each column index once per block. At most kMaxBlock rows a block. Empty: none.
  std::vector<int> blocks;
  static constexpr int kMaxBlock = 8;
  long nonzeros() const { return static_cast<long>(col.size()); }
  /// y = A x, on `threads` threads. x: cols, y: rows.
  void multiply(const double* x, double* y, int threads) const;
  /// True if `blocks` is empty or describes rows with identical column lists.
  bool blocks_consistent() const;
};

namespace detail {

/// Rows r0 .. r0 + NR − 1 of y = M x for one row block of M (its `len` columns c, shared by its
/// rows): each row's terms added in column order, as a row at a time would add them, while each
/// column index and x value is read once for all the block's rows. The value of row r, entry k
/// is v[k·NR + r] if Interleaved (interleaved_values), else v[r·len + k] (M's own order).
template <int NR, bool Interleaved, class Value>
inline void block_rows(const Value* v, const int* c, int len, const double* x, double* y) {
  double acc[NR] = {};
  for (int k = 0; k < len; ++k) {
    const double xk = x[c[k]];
    for (int r = 0; r < NR; ++r) acc[r] += v[Interleaved ? k * NR + r : r * len + k] * xk;
  }
  for (int r = 0; r < NR; ++r) y[r] = acc[r];
}

/// block_rows for a block of nr rows (1 .. CsrMatrix::kMaxBlock), the count known at compile time.
template <bool Interleaved, class Value>
inline void block_rows(int nr, const Value* v, const int* c, int len, const double* x, double* y) {
  switch (nr) {
    case 1: return block_rows<1, Interleaved>(v, c, len, x, y);
    case 2: return block_rows<2, Interleaved>(v, c, len, x, y);
    case 3: return block_rows<3, Interleaved>(v, c, len, x, y);
    case 4: return block_rows<4, Interleaved>(v, c, len, x, y);
    case 5: return block_rows<5, Interleaved>(v, c, len, x, y);
    case 6: return block_rows<6, Interleaved>(v, c, len, x, y);
    case 7: return block_rows<7, Interleaved>(v, c, len, x, y);
    default: return block_rows<8, Interleaved>(v, c, len, x, y);
  }
}

/// y = M x over M's row blocks, the values in M's order or interleaved (block_rows).
template <bool Interleaved, class Value>
void blocked_product(const CsrMatrix& M, const Value* val, const double* x, double* y, int threads) {
  const long nb = static_cast<long>(M.blocks.size()) - 1;
  parallel_for(
      nb, threads,
      [&](long bb, long be) {
        for (long blk = bb; blk < be; ++blk) {
          const int r0 = M.blocks[blk], base = M.ptr[r0];
          block_rows<Interleaved>(M.blocks[blk + 1] - r0, val + base, &M.col[base], M.ptr[r0 + 1] - base, x, y + r0);
        }
      },
      1024);
}

}  // namespace detail

/// y = M x with M's pattern and the values `val` (M.nonzeros() of them: M.val itself, or a
/// single-precision copy: the products are memory-bound, and 4-byte values cut the bytes read
/// by a third). x: M.cols, y: M.rows. The rows of a row block are summed together (one read
/// of each column index and x value for the block), each in the order of a row alone.
template <class Value>
void sparse_product(const CsrMatrix& M, const Value* val, const double* x, double* y, int threads) {
  if (!M.blocks.empty()) return detail::blocked_product<false>(M, val, x, y, threads);
  const std::vector<int>& ptr = M.ptr;
  const std::vector<int>& col = M.col;
  parallel_for(
      M.rows, threads,
      [&](long b, long e) {
        for (long i = b; i < e; ++i) {
          double s = 0;
          for (int k = ptr[i]; k < ptr[i + 1]; ++k) s += val[k] * x[col[k]];
          y[i] = s;
        }
      },
      4096);
}

/// M's values converted to Value and rearranged for interleaved_product: within each row block
/// (r0, nr rows, len entries each) entry k of row r0 + r goes to ptr[r0] + k·nr + r, so that a
/// block's values are one stream (3×3 node blocks side by side for elasticity, the layout of a
/// block-sparse matrix without its padding). Without row blocks: the values in M's order.
template <class Value>
void interleaved_values(const CsrMatrix& M, std::vector<Value>& out) {
  out.resize(M.val.size());
  if (M.blocks.empty()) {
    std::copy(M.val.begin(), M.val.end(), out.begin());
    return;
  }
  for (size_t blk = 0; blk + 1 < M.blocks.size(); ++blk) {
    const int r0 = M.blocks[blk], nr = M.blocks[blk + 1] - r0, base = M.ptr[r0], len = M.ptr[r0 + 1] - base;
    for (int r = 0; r < nr; ++r)
      for (int k = 0; k < len; ++k) out[base + k * nr + r] = static_cast<Value>(M.val[base + r * len + k]);
  }
}

/// y = M x with M's pattern and values `ival` from interleaved_values: the same terms added in
/// the same order as sparse_product with the values in M's order (the same y to the bit), the
/// values of a row block read as one stream. x: M.cols, y: M.rows.
template <class Value>
void interleaved_product(const CsrMatrix& M, const Value* ival, const double* x, double* y, int threads) {
  if (M.blocks.empty()) return sparse_product(M, ival, x, y, threads);
  detail::blocked_product<true>(M, ival, x, y, threads);
}

/// C = A B (A.cols == B.rows), on `threads` threads. With row blocks in A, the rows of a block
/// are formed together and C inherits A's blocks.
CsrMatrix multiply(const CsrMatrix& A, const CsrMatrix& B, int threads);

/// The number of row blocks of A: its blocks, or its rows when it has none.
long row_blocks(const CsrMatrix& A);

/// The rows of A B from A's row blocks first .. last − 1 (rows, without blocks), as multiply
/// forms them (the same values to the bit), in a matrix of their own: its row 0 is the first
/// row of block `first`, its blocks are those blocks shifted. A product taken a slice at a time.
CsrMatrix multiply_rows(const CsrMatrix& A, const CsrMatrix& B, long first, long last, int threads);

/// C += the terms of A X that come from X's rows first .. first + Xs.rows − 1, given as Xs (its
/// row 0 is X's row `first`); C has the pattern (and row blocks) of multiply(A, X), A's columns
/// increase within each row. cursor (one per row block of A) holds the first entry of each
/// block's rows whose column is not yet added; it moves past the entries added. Called for
/// consecutive slices of X from the first row to the last, with C zero and the cursors at A's
/// row starts before the first, it leaves in C the values of multiply(A, X) — each entry's terms
/// added in the same order, the same values to the bit — while only a slice of X is held: the
/// multigrid's Galerkin refresh R (A P) on the kept pattern without the whole of A P (fem/amg.h).
void add_product_rows(const CsrMatrix& A, const CsrMatrix& Xs, int first, std::vector<int>& cursor, CsrMatrix& C,
                      int threads);

/// Aᵀ in compressed rows (no blocks).
CsrMatrix transpose(const CsrMatrix& A);

/// A CsrMatrix seen by pcg(): a square, symmetric positive definite matrix. Keeps references:
/// the matrix must outlive the operator.
class CsrOperator final : public LinearOperator {
 public:
  CsrOperator(const CsrMatrix& A, int threads) : A_(A), threads_(threads) {}
  int size() const override { return A_.rows; }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override;
  void residual(const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) const override;

 private:
  const CsrMatrix& A_;
  int threads_;
};

}  // namespace topopt::fem
