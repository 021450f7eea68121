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

/// y = M x with M's pattern and the values `val` (M.nonzeros() of them: M.val itself, or a
/// single-precision copy: the products are memory-bound, and 4-byte values cut the bytes read
/// by a third). x: M.cols, y: M.rows.
template <class Value>
void sparse_product(const CsrMatrix& M, const Value* val, const double* x, double* y, int threads) {
  const std::vector<int>& ptr = M.ptr;
  const std::vector<int>& col = M.col;
  if (M.blocks.empty()) {
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
    return;
  }
  const long nb = static_cast<long>(M.blocks.size()) - 1;
  parallel_for(
      nb, threads,
      [&](long bb, long be) {
        for (long blk = bb; blk < be; ++blk) {
          const int r0 = M.blocks[blk], nr = M.blocks[blk + 1] - r0, len = ptr[r0 + 1] - ptr[r0];
          const int* c = &col[ptr[r0]];
          for (int r = 0; r < nr; ++r) {
            const Value* v = &val[ptr[r0 + r]];
            double acc = 0;
            for (int k = 0; k < len; ++k) acc += v[k] * x[c[k]];
            y[r0 + r] = acc;
          }
        }
      },
      1024);
}

/// C = A B (A.cols == B.rows), on `threads` threads. With row blocks in A, the rows of a block
/// are formed together and C inherits A's blocks.
CsrMatrix multiply(const CsrMatrix& A, const CsrMatrix& B, int threads);

/// C = A B again for new values of A and B on the patterns C was computed from: C must be the
/// result of multiply(A', B') with A' and B' of A's and B's patterns (and row blocks); only
/// C.val is rewritten, in place, with the additions in multiply's order (the same values to
/// the bit). No allocation but one column-slot array per thread: the multigrid's Galerkin
/// refresh of kept coarse levels (fem/amg.h) without fresh pages to fault in.
void multiply_values(const CsrMatrix& A, const CsrMatrix& B, CsrMatrix& C, int threads);

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
