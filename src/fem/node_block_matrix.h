// The elasticity matrix in 3×3 node blocks (block compressed rows, BSR): one column index per
// block of nine values instead of one per value, and a product whose three rows of a block are
// summed in one walk. For the products that dominate an iterative solve (CG's matvec, the
// multigrid's finest smoother and residual): on a matrix shaped like the rocker's K (5 M entries,
// one thread) 1.4–2.2 ms a product in single precision against 2.4–2.9 ms for the row walk of
// sparse_product (BENCHMARKS.md, branch speed10).
#pragma once
#include <vector>

#include "fem/csr_matrix.h"

namespace topopt::fem {

/// The pattern of a square CsrMatrix whose row blocks (CsrMatrix::blocks: a mesh node's free
/// dofs) have at most 3 rows, seen as 3×3 blocks: block row b is row block b padded to 3 rows,
/// and it holds one 3×3 block per row block its columns reach (padded to 3 columns). Padding is
/// zeros in the values and in the padded copy of x, and padded rows are never written, so a
/// product adds the same non-zero terms in the same order as sparse_product's row walk (columns
/// increasing): the same values to the bit (a zero sum may differ in its sign).
struct NodeBlockPattern {
  int nodes = 0;           ///< row blocks
  std::vector<int> first;  ///< nodes+1: the first row of each row block (M.blocks)
  std::vector<int> ptr;    ///< nodes+1 offsets into col
  std::vector<int> col;    ///< the block column (a row block of M) of each 3×3 block
  bool padded = false;     ///< some row block has fewer than 3 rows (x is copied into a padded vector)
  /// At most this many padded values per entry of M, else the blocks do not pay (a scalar problem).
  static constexpr double kMaxFill = 1.3;

  /// Builds the pattern of M. Returns false (and leaves the pattern empty) if M does not fit:
  /// not square, no row blocks, a block of more than 3 rows, columns not increasing within a
  /// row, or more than kMaxFill padded values per entry.
  bool build(const CsrMatrix& M);
  bool empty() const { return nodes == 0; }
  /// Values of M (M.val, same pattern as build's) in the blocks' layout: 9 per block, row-major
  /// within a block, padding 0. `out` is resized.
  template <class Value>
  void fill(const CsrMatrix& M, std::vector<Value>& out) const;
  /// y = M x with the block values `val` (fill's), on `threads` threads. x, y: M.rows.
  /// `scratch`: a work vector (the padded x), resized here.
  template <class Value>
  void multiply(const std::vector<Value>& val, const double* x, double* y, std::vector<double>& scratch,
                int threads) const;
};

}  // namespace topopt::fem
