// Sparse matrix kernels (see csr_matrix.h).
#include "fem/csr_matrix.h"

#include <algorithm>
#include <cassert>
#include <numeric>

#include "common/parallel.h"
#include "fem/node_block_matrix.h"

#if TOPOPT_AVX_KERNELS
#include <immintrin.h>
#endif

namespace topopt::fem {

void CsrMatrix::multiply(const double* x, double* y, int threads) const {
  sparse_product(*this, val.data(), x, y, threads);
}

bool CsrMatrix::blocks_consistent() const {
  if (blocks.empty()) return true;
  if (blocks.front() != 0 || blocks.back() != rows) return false;
  for (size_t b = 0; b + 1 < blocks.size(); ++b) {
    const int r0 = blocks[b], nr = blocks[b + 1] - r0;
    if (nr < 1 || nr > kMaxBlock) return false;
    const int len = ptr[r0 + 1] - ptr[r0];
    for (int r = 1; r < nr; ++r)
      if (ptr[r0 + r + 1] - ptr[r0 + r] != len || !std::equal(&col[ptr[r0]], &col[ptr[r0]] + len, &col[ptr[r0 + r]]))
        return false;
  }
  return true;
}

long row_blocks(const CsrMatrix& A) { return A.blocks.empty() ? A.rows : static_cast<long>(A.blocks.size()) - 1; }

CsrMatrix multiply(const CsrMatrix& A, const CsrMatrix& B, int threads) {
  return multiply_rows(A, B, 0, row_blocks(A), threads);
}

namespace {

/// A thread's dense accumulator for multiply_rows: per column of B the block that last touched
/// it (mark) and its place (slot) among the columns the block touched, in order (touched);
/// CsrMatrix::kMaxBlock sums per place (acc).
struct RowAccumulator {
  std::vector<int> mark, slot, touched;
  std::vector<double> acc;
};

/// The rows r0 .. r0 + nr − 1 of A B (a row block of A: the same columns) summed into `w`, one
/// walk over the block's column indices. NR: the row count at compile time (0: nr, any count
/// up to kMaxBlock); the same additions in the same order whatever NR — a fixed count lets the
/// compiler keep a column's values in registers (a mesh node's 3 rows, an aggregate's 6).
template <int NR>
void block_rows_times(const CsrMatrix& A, const CsrMatrix& B, int r0, int nr, int blk, RowAccumulator& w) {
  constexpr int kB = CsrMatrix::kMaxBlock;
  const int n = NR ? NR : nr, len = A.ptr[r0 + 1] - A.ptr[r0];
  w.touched.clear();
  int* mark = w.mark.data();  // raw pointers: the stores into acc need not reload them
  int* slot = w.slot.data();
  double* acc = w.acc.data();
  const int* a_col = A.col.data() + A.ptr[r0];
  const double* a_val[kB];
  for (int r = 0; r < n; ++r) a_val[r] = A.val.data() + A.ptr[r0 + r];
  for (int k = 0; k < len; ++k) {
    const int cc = a_col[k];
    double a[kB];
    for (int r = 0; r < n; ++r) a[r] = a_val[r][k];
    for (int kb = B.ptr[cc]; kb < B.ptr[cc + 1]; ++kb) {
      const int j = B.col[kb];
      const double v = B.val[kb];
      if (mark[j] != blk) {
        mark[j] = blk;
        slot[j] = static_cast<int>(w.touched.size());
        w.touched.push_back(j);
        if (w.acc.size() < w.touched.size() * kB) w.acc.resize(2 * w.touched.size() * kB), acc = w.acc.data();
        double* q = acc + kB * slot[j];
        for (int r = 0; r < n; ++r) q[r] = a[r] * v;
      } else {
        double* q = acc + kB * slot[j];
        for (int r = 0; r < n; ++r) q[r] += a[r] * v;
      }
    }
  }
}

/// One column j of B's row block p0 .. p0 + pn − 1 (entry t of its rows, bv[c][t]) times M's
/// 3×3 block `a` (column-major: a[r + 3 c]), into j's sums q of M's n rows: q[r] (+)= a[r + 3 c]
/// bv[c][t] for c = 0 .. pn − 1, the first term set, not added, when `set` (as block_rows_times).
struct ScalarColumns {
  static void add(const double* a, const double* const* bv, int t, int n, int pn, double* q, bool set) {
    const int c0 = set ? 1 : 0;
    if (set)
      for (int r = 0; r < n; ++r) q[r] = a[r] * bv[0][t];
    for (int r = 0; r < n; ++r) {
      double s = q[r];
      for (int c = c0; c < pn; ++c) s += a[r + 3 * c] * bv[c][t];
      q[r] = s;
    }
  }
};

#if TOPOPT_AVX_KERNELS
/// ScalarColumns with M's three rows in one AVX register's lanes where the block and B's row
/// block are full (n = pn = 3): each row's products and sums in the scalar order, rounded alike (no
/// fused multiply-add), the same values to the bit. The fourth lane reads a[3 + 3 c] (the next
/// column's, or the next block's, or the values' one past the end: NodeBlockPattern::values) and
/// writes q[3], which no row reads (RowAccumulator keeps CsrMatrix::kMaxBlock = 8 sums a column).
struct AvxColumns {
  __attribute__((target("avx"))) static inline void add(const double* a, const double* const* bv, int t, int n, int pn,
                                                        double* q, bool set) {
    if (n != 3 || pn != 3) return ScalarColumns::add(a, bv, t, n, pn, q, set);
    __m256d s = _mm256_mul_pd(_mm256_loadu_pd(a), _mm256_set1_pd(bv[0][t]));
    if (!set) s = _mm256_add_pd(_mm256_loadu_pd(q), s);
    s = _mm256_add_pd(s, _mm256_mul_pd(_mm256_loadu_pd(a + 3), _mm256_set1_pd(bv[1][t])));
    s = _mm256_add_pd(s, _mm256_mul_pd(_mm256_loadu_pd(a + 6), _mm256_set1_pd(bv[2][t])));
    _mm256_storeu_pd(q, s);
  }
};
static_assert(CsrMatrix::kMaxBlock >= 4, "AvxColumns writes four sums a column");
#endif

/// The rows of row block `blk` of M B summed into `w` as block_rows_times sums them from M's
/// compressed rows (the same terms in the same order: M's columns increase, and B's rows of a
/// node block share their columns), with M's values read from its 3×3 blocks `val`: one column
/// check per block of B's columns instead of one per entry of M. NR: M's rows in the block (3 or
/// 0: any); Columns: how a block meets one column of B (ScalarColumns, AvxColumns).
template <int NR, class Columns>
inline void node_block_rows_times(const NodeBlockPattern& nb, const double* val, const CsrMatrix& B, int blk,
                                  RowAccumulator& w) {
  constexpr int kB = CsrMatrix::kMaxBlock;
  const int n = NR ? NR : nb.first[blk + 1] - nb.first[blk];
  w.touched.clear();
  int* mark = w.mark.data();
  int* slot = w.slot.data();
  double* acc = w.acc.data();
  for (int k = nb.ptr[blk]; k < nb.ptr[blk + 1]; ++k) {
    const int m = nb.col[k], p0 = nb.first[m], pn = nb.first[m + 1] - p0;
    const double* a = val + 9L * k;  // a[r + 3 c]: M's row r, column p0 + c (column-major blocks)
    const int* bc = B.col.data() + B.ptr[p0];
    const int blen = B.ptr[p0 + 1] - B.ptr[p0];
    const double* bv[3];
    for (int c = 0; c < pn; ++c) bv[c] = B.val.data() + B.ptr[p0 + c];
    for (int t = 0; t < blen; ++t) {
      const int j = bc[t];
      const bool set = mark[j] != blk;
      if (set) {  // the first term is set, not added (as in block_rows_times)
        mark[j] = blk;
        slot[j] = static_cast<int>(w.touched.size());
        w.touched.push_back(j);
        if (w.acc.size() < w.touched.size() * kB) w.acc.resize(2 * w.touched.size() * kB), acc = w.acc.data();
      }
      Columns::add(a, bv, t, n, pn, acc + kB * slot[j], set);
    }
  }
}

/// node_block_rows_times for a block of 3 rows or any, by the scalar or the AVX columns.
template <int NR>
void scalar_node_block_rows(const NodeBlockPattern& nb, const double* val, const CsrMatrix& B, int blk,
                            RowAccumulator& w) {
  node_block_rows_times<NR, ScalarColumns>(nb, val, B, blk, w);
}
#if TOPOPT_AVX_KERNELS
template <int NR>
__attribute__((target("avx"), flatten)) void avx_node_block_rows(const NodeBlockPattern& nb, const double* val,
                                                                 const CsrMatrix& B, int blk, RowAccumulator& w) {
  node_block_rows_times<NR, AvxColumns>(nb, val, B, blk, w);
}
#endif

/// The terms of X's rows i .. i + m − 1 (m = 1, or 3: a node block of X, its rows sharing their
/// columns) into C's rows c[0 .. n − 1] at the places `slot` gives their columns, with A's values
/// a[0 .. m − 1][r]: each entry of C takes row i's term, then row i + 1's, then row i + 2's, in
/// that order whatever m (one pass over the block's columns for three), the same additions.
template <int NR, int M>
void add_row_terms(const CsrMatrix& X, int i, const double (*a)[CsrMatrix::kMaxBlock], int n, const int* slot,
                   double* const* c) {
  const int p0 = X.ptr[i], len = X.ptr[i + 1] - p0;
  const int* xc = X.col.data() + p0;
  const double* xv[3];
  for (int m = 0; m < M; ++m) xv[m] = X.val.data() + X.ptr[i + m];
  for (int kx = 0; kx < len; ++kx) {
    const int t = slot[xc[kx]];
    for (int r = 0; r < (NR ? NR : n); ++r) {
      double s = c[r][t];
      for (int m = 0; m < M; ++m) s += a[m][r] * xv[m][kx];
      c[r][t] = s;
    }
  }
}

/// add_product_rows for one row block of A (rows r0 .. r0 + nr − 1, from its entry k on, while
/// the column is below `last`): the terms of X's rows, added into the block's rows of C at the
/// places `slot` gives their columns; three of X's rows at a time where A's next three entries
/// are a node block of X (`triple`: X's rows that start one). Returns the first entry not added.
/// NR as in block_rows_times.
template <int NR>
int add_block_terms(const CsrMatrix& A, const CsrMatrix& X, int first, int last, int r0, int nr, int k, const int* slot,
                    const char* triple, CsrMatrix& C) {
  constexpr int kB = CsrMatrix::kMaxBlock;
  const int n = NR ? NR : nr, end = A.ptr[r0 + 1];
  double* c[kB];
  for (int r = 0; r < n; ++r) c[r] = &C.val[C.ptr[r0 + r]];
  while (k < end && A.col[k] < last) {
    const int i = A.col[k] - first, offset = k - A.ptr[r0];
    const int m = triple[i] && k + 2 < end && A.col[k + 2] == A.col[k] + 2 ? 3 : 1;  // columns increase
    double a[3][kB];
    for (int q = 0; q < m; ++q)
      for (int r = 0; r < n; ++r) a[q][r] = A.val[A.ptr[r0 + r] + offset + q];
    if (m == 3)
      add_row_terms<NR, 3>(X, i, a, n, slot, c);
    else
      add_row_terms<NR, 1>(X, i, a, n, slot, c);
    k += m;
  }
  return k;
}

/// The driver of multiply_rows: the rows of A B from A's row blocks first .. last − 1, each block
/// summed by form(r0, nr, blk, w) (its nr rows from row r0 into w's touched columns and sums),
/// on `threads` threads, gathered into one matrix.
template <class Form>
CsrMatrix product_rows(const CsrMatrix& A, const CsrMatrix& B, long first, long last, int threads, const Form& form) {
  assert(A.cols == B.rows && 0 <= first && first <= last && last <= row_blocks(A));
  constexpr int kB = CsrMatrix::kMaxBlock;
  std::vector<int> blocks = A.blocks;
  if (blocks.empty()) {  // one row a block
    blocks.resize(A.rows + 1);
    std::iota(blocks.begin(), blocks.end(), 0);
  }
  const int row0 = blocks[first];
  CsrMatrix C;
  C.rows = blocks[last] - row0;
  C.cols = B.cols;
  const long nblocks = last - first;
  const int chunks = static_cast<int>(std::max(1L, std::min<long>(threads, nblocks / 512 + 1)));
  struct Part {
    std::vector<int> count, col;
    std::vector<double> val;
  };
  std::vector<Part> parts(chunks);
  parallel_for(
      chunks, chunks,
      [&](long cb, long ce) {
        RowAccumulator w;
        w.mark.assign(B.cols, -1);
        w.slot.resize(B.cols);
        for (long c = cb; c < ce; ++c) {
          Part& part = parts[c];
          const long b0 = first + nblocks * c / chunks, b1 = first + nblocks * (c + 1) / chunks;
          part.count.reserve(blocks[b1] - blocks[b0]);
          part.col.reserve(static_cast<size_t>(A.ptr[blocks[b1]] - A.ptr[blocks[b0]]) * 4);
          part.val.reserve(part.col.capacity());
          for (long blk = b0; blk < b1; ++blk) {
            const int r0 = blocks[blk], nr = blocks[blk + 1] - r0;
            form(r0, nr, static_cast<int>(blk), w);
            for (int r = 0; r < nr; ++r) {
              part.count.push_back(static_cast<int>(w.touched.size()));
              for (size_t t = 0; t < w.touched.size(); ++t) {
                part.col.push_back(w.touched[t]);
                part.val.push_back(w.acc[kB * t + r]);
              }
            }
          }
        }
      },
      1);
  C.ptr.assign(C.rows + 1, 0);
  long nnz = 0, row = 0;
  for (const Part& p : parts) nnz += static_cast<long>(p.col.size());
  C.col = std::move(parts[0].col);  // the first part in place, the others appended
  C.val = std::move(parts[0].val);
  C.col.reserve(nnz);
  C.val.reserve(nnz);
  for (size_t k = 0; k < parts.size(); ++k) {
    const Part& p = parts[k];
    for (int n : p.count) C.ptr[row + 1] = C.ptr[row] + n, ++row;
    if (k == 0) continue;
    C.col.insert(C.col.end(), p.col.begin(), p.col.end());
    C.val.insert(C.val.end(), p.val.begin(), p.val.end());
  }
  assert(row == C.rows);
  if (!A.blocks.empty())
    for (long b = first; b <= last; ++b) C.blocks.push_back(A.blocks[b] - row0);
  return C;
}

}  // namespace

// Gustavson's row-by-row product with a dense accumulator per thread; a block's rows share one
// walk over their column indices.
CsrMatrix multiply_rows(const CsrMatrix& A, const CsrMatrix& B, long first, long last, int threads) {
  return product_rows(A, B, first, last, threads, [&](int r0, int nr, int blk, RowAccumulator& w) {
    if (nr == 3)
      block_rows_times<3>(A, B, r0, nr, blk, w);
    else
      block_rows_times<0>(A, B, r0, nr, blk, w);
  });
}

CsrMatrix multiply_rows(const NodeBlockPattern& nb, const std::vector<double>& val, const CsrMatrix& A,
                        const CsrMatrix& B, long first, long last, int threads) {
  assert(B.blocks == nb.first && A.blocks == nb.first);
  [[maybe_unused]] const bool avx = NodeBlockPattern::fastest_kernel() == NodeBlockPattern::Kernel::Avx;
  return product_rows(A, B, first, last, threads, [&](int, int nr, int blk, RowAccumulator& w) {
#if TOPOPT_AVX_KERNELS
    if (avx)
      return nr == 3 ? avx_node_block_rows<3>(nb, val.data(), B, blk, w)
                     : avx_node_block_rows<0>(nb, val.data(), B, blk, w);
#endif
    if (nr == 3)
      scalar_node_block_rows<3>(nb, val.data(), B, blk, w);
    else
      scalar_node_block_rows<0>(nb, val.data(), B, blk, w);
  });
}

void add_product_rows(const CsrMatrix& A, const CsrMatrix& X, int first, std::vector<int>& cursor, CsrMatrix& C,
                      int threads) {
  assert(C.rows == A.rows && C.cols == X.cols);
  const bool one_row = A.blocks.empty();
  const long nblocks = row_blocks(A);
  const int last = first + X.rows;
  assert(static_cast<long>(cursor.size()) == nblocks);
  std::vector<char> triple(X.rows, 0);  // X's rows that start a node block of 3 (sharing columns)
  for (size_t b = 0; b + 1 < X.blocks.size(); ++b) triple[X.blocks[b]] = X.blocks[b + 1] - X.blocks[b] == 3;
  parallel_for(
      nblocks, threads,
      [&](long bb, long be) {
        std::vector<int> slot(C.cols);  // a column's position in the block's rows of C
        for (long blk = bb; blk < be; ++blk) {
          const int r0 = one_row ? static_cast<int>(blk) : A.blocks[blk];
          const int nr = one_row ? 1 : A.blocks[blk + 1] - r0, end = A.ptr[r0 + 1];
          const int k = cursor[blk];
          if (k == end || A.col[k] >= last) continue;
          const int c0 = C.ptr[r0], clen = C.ptr[r0 + 1] - c0;
          for (int t = 0; t < clen; ++t) slot[C.col[c0 + t]] = t;
          // an aggregate's six coarse dofs (elasticity), or any count
          cursor[blk] = nr == 6 ? add_block_terms<6>(A, X, first, last, r0, nr, k, slot.data(), triple.data(), C)
                                : add_block_terms<0>(A, X, first, last, r0, nr, k, slot.data(), triple.data(), C);
        }
      },
      512);
}

CsrMatrix transpose(const CsrMatrix& A) {
  CsrMatrix T;
  T.rows = A.cols;
  T.cols = A.rows;
  T.ptr.assign(T.rows + 1, 0);
  for (int c : A.col) ++T.ptr[c + 1];
  for (int i = 0; i < T.rows; ++i) T.ptr[i + 1] += T.ptr[i];
  T.col.resize(A.col.size());
  T.val.resize(A.val.size());
  std::vector<int> fill(T.ptr.begin(), T.ptr.end() - 1);
  for (int i = 0; i < A.rows; ++i)
    for (int k = A.ptr[i]; k < A.ptr[i + 1]; ++k) {
      int p = fill[A.col[k]]++;
      T.col[p] = i;
      T.val[p] = A.val[k];
    }
  return T;
}

void CsrOperator::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  A_.multiply(x.data(), y.data(), threads_);
}

void CsrOperator::residual(const Eigen::VectorXd& b, const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
  Eigen::VectorXd q(A_.rows);
  A_.multiply(x.data(), q.data(), threads_);
  r = b - q;
}

}  // namespace topopt::fem
