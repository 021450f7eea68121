// A sparse matrix in compressed rows, with the kernels the multigrid needs: the product with a
// vector (in double, or with single-precision copies of the values), the product of two
// matrices and the transpose. It stays a matrix and not a common/adjacency.h Adjacency: it
// carries values, a column count and row blocks, and what is done with it is matrix algebra.
#pragma once
#include <Eigen/Core>
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
  /// columns in the same order (a mesh node's dofs, an aggregate's coarse dofs), so the matrix
  /// products (multiply, multiply_rows, add_product_rows) read each column index once per block;
  /// sparse_product ignores them. At most kMaxBlock rows a block. Empty: none.
  std::vector<int> blocks;
  static constexpr int kMaxBlock = 8;
  long nonzeros() const { return static_cast<long>(col.size()); }
  /// y = A x, on `threads` threads. x: cols, y: rows.
  void multiply(const double* x, double* y, int threads) const;
  /// True if `blocks` is empty or describes rows with identical column lists.
  bool blocks_consistent() const;
};

/// y = M x with M's pattern and the values `val` (M.nonzeros() of them: M.val itself, or a
/// single-precision copy: the products are memory-bound, and 4-byte values cut the bytes read
/// by a third). x: M.cols, y: M.rows. Row by row even where M has row blocks: a walk by blocks
/// (each column index read once for a block's rows) measured 2-3 times slower on a matrix shaped
/// like the elasticity one (branch speed7 in BENCHMARKS.md); the sums are the same either way.
template <class Value>
void sparse_product(const CsrMatrix& M, const Value* val, const double* x, double* y, int threads) {
  const int* ptr = M.ptr.data();
  const int* col = M.col.data();
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

/// C = A B (A.cols == B.rows), on `threads` threads. With row blocks in A, the rows of a block
/// are formed together and C inherits A's blocks.
CsrMatrix multiply(const CsrMatrix& A, const CsrMatrix& B, int threads);

/// The number of row blocks of A: its blocks, or its rows when it has none.
long row_blocks(const CsrMatrix& A);

/// The rows of A B from A's row blocks first .. last − 1 (rows, without blocks), as multiply
/// forms them (the same values to the bit), in a matrix of their own: its row 0 is the first
/// row of block `first`, its blocks are those blocks shifted. A product taken a slice at a time.
CsrMatrix multiply_rows(const CsrMatrix& A, const CsrMatrix& B, long first, long last, int threads);

struct NodeBlockPattern;
/// The same rows of A B (the same values to the bit) with A's values read from its 3×3 node
/// blocks `val` (nb's pattern of A, fem/node_block_matrix.h): one column check per 3×3 block
/// of A and column of B instead of one per entry of A. B's row blocks must be A's (nb.first), the
/// rows of each sharing their columns — the smoothed prolongator's, made from A by multiply.
CsrMatrix multiply_rows(const NodeBlockPattern& nb, const std::vector<double>& val, const CsrMatrix& A,
                        const CsrMatrix& B, long first, long last, int threads);

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
