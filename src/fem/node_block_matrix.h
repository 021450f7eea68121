// The elasticity matrix in 3×3 node blocks (block compressed rows, BSR): one column index per
// block of nine values instead of one per value, and a product whose three rows of a block are
// summed in one walk. For the products that dominate an iterative solve (CG's matvec, the
// multigrid's finest smoother and residual): on a matrix shaped like the rocker's K (5 M entries,
// one thread) 1.4–2.2 ms a product in single precision against 2.4–2.9 ms for the row walk of
// sparse_product (BENCHMARKS.md, branch speed10); a node's three rows in one AVX register's lanes
// cut it by a third more (branch speed17). The multigrid's transfers (prolongator and restriction)
// in blocks of a node's rows by an aggregate's coarse dofs (BlockPattern, branch speed14).
#pragma once
#include <vector>

#include "fem/csr_matrix.h"

// The AVX kernels need an x86 CPU and GCC's or Clang's target attribute; elsewhere (ARM, MSVC)
// only the scalar kernels are built, and fastest_kernel() is Scalar.
#if (defined(__x86_64__) || defined(__i386__)) && defined(__GNUC__)
#define TOPOPT_AVX_KERNELS 1
#else
#define TOPOPT_AVX_KERNELS 0
#endif

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
  /// The product's kernels: one row at a time, or a node's three rows in the lanes of one AVX
  /// register (x86-64 CPUs from 2011 on). Both add each row's terms in the row walk's order and
  /// round alike: the same values to the bit.
  enum class Kernel { Scalar, Avx };
  /// The kernel this CPU runs fastest: Avx where it has AVX, else Scalar.
  static Kernel fastest_kernel();
  /// The number of block values: 9 per block and one more (read, never used, by the AVX kernel's
  /// last column; 0).
  size_t values() const { return 9 * col.size() + 1; }
  /// Values of M (M.val, same pattern as build's) in the blocks' layout: 9 per block, column-major
  /// within a block (a column's 3 rows side by side), padding 0; values() in all. `out` is resized.
  template <class Value>
  void fill(const CsrMatrix& M, std::vector<Value>& out) const;
  /// fill's double values and their single-precision copy in one walk over M. A refill of vectors
  /// of the right size (SIMP's next matrix, the same pattern) writes M's entries only: the padding
  /// is still the zeros the first fill wrote.
  void fill(const CsrMatrix& M, std::vector<double>& exact, std::vector<float>& single) const;
  /// y = M x with the block values `val` (fill's), on `threads` threads, by `kernel`. x, y: M.rows.
  /// `scratch`: a work vector (the padded x), resized here.
  template <class Value>
  void multiply(const std::vector<Value>& val, const double* x, double* y, std::vector<double>& scratch, int threads,
                Kernel kernel = fastest_kernel()) const;

 private:
  /// Both fills' one walk over M: put(index in the blocks' values, M's value) for every entry.
  template <class Put>
  void walk(const CsrMatrix& M, Put put) const;
};

/// The pattern of a rectangular CsrMatrix M in dense RB × CB blocks (block compressed rows), for
/// the multigrid's transfers: the prolongator P (rows: the fine level's node blocks of at most 3
/// rows; columns: the aggregates' coarse dofs, at most 6 each: RB = 3, CB = 6) and the
/// restriction R = Pᵀ (RB = 6, CB = 3). Block row b is M's row block b (M.blocks, its rows sharing
/// their columns) padded to RB rows; each block is one column block (`col_first`) of M padded to
/// CB columns. A row's entries in one column block must be consecutive with columns increasing
/// (the blocks may come in any order: P's aggregates come in the order its product first met
/// them), so a product adds each row's terms in the row walk's order (sparse_product), padding
/// adding zeros: the same values to the bit (a zero sum may differ in its sign). One column index
/// per RB × CB values, where the row walk reads one per value.
template <int RB, int CB>
struct BlockPattern {
  int row_blocks = 0;          ///< M's row blocks
  std::vector<int> row_first;  ///< row_blocks+1: the first row of each (M.blocks)
  std::vector<int> col_first;  ///< #column blocks+1: the first column of each
  std::vector<int> ptr;        ///< row_blocks+1 offsets into col
  std::vector<int> col;        ///< the column block of each RB × CB block
  bool padded = false;         ///< some column block has fewer than CB columns (x is copied padded)
  /// At most this many stored values per entry of M, else the blocks do not pay.
  static constexpr double kMaxFill = 1.3;

  /// Builds the pattern of M with column blocks `columns` (offsets, first 0, last M.cols). Returns
  /// false (and leaves the pattern empty) if M does not fit: no row blocks or rows of a block not
  /// sharing their columns, a row block of more than RB rows or a column block of more than CB
  /// columns, a row's entries of one column block not consecutive and increasing, or more than
  /// kMaxFill stored values per entry.
  bool build(const CsrMatrix& M, const std::vector<int>& columns);
  bool empty() const { return row_blocks == 0; }
  /// The product's kernels, as NodeBlockPattern's: a block's RB rows one at a time or in the
  /// lanes of AVX registers, the same values to the bit.
  using Kernel = NodeBlockPattern::Kernel;
  /// The number of block values: RB × CB per block and one more (read, never used, by the AVX
  /// kernel's last column when RB = 3; 0).
  size_t values() const { return static_cast<size_t>(RB * CB) * col.size() + 1; }
  /// Values of M (same pattern as build's) in the blocks' layout: RB × CB per block, column-major
  /// within a block (a column's RB rows side by side), padding 0; values() in all. `out` is resized.
  template <class Value>
  void fill(const CsrMatrix& M, std::vector<Value>& out) const;
  /// y = M x with the block values `val` (fill's), on `threads` threads, by `kernel`. x: M.cols,
  /// y: M.rows. `scratch`: a work vector (the padded x), resized here.
  template <class Value>
  void multiply(const std::vector<Value>& val, const double* x, double* y, std::vector<double>& scratch, int threads,
                Kernel kernel = NodeBlockPattern::fastest_kernel()) const;
};

/// The multigrid's transfers in blocks: P from fine node blocks to aggregates, R = Pᵀ back.
using ProlongatorBlocks = BlockPattern<3, 6>;
using RestrictionBlocks = BlockPattern<6, 3>;

}  // namespace topopt::fem
