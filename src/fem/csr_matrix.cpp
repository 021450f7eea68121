// Sparse matrix kernels (see csr_matrix.h).
#include "fem/csr_matrix.h"

#include <algorithm>
#include <cassert>
#include <numeric>

#include "common/parallel.h"

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

// Gustavson's row-by-row product with a dense accumulator per thread; a block's rows share one
// walk over their column indices.
CsrMatrix multiply_rows(const CsrMatrix& A, const CsrMatrix& B, long first, long last, int threads) {
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
        std::vector<int> mark(B.cols, -1), slot(B.cols), touched;
        std::vector<double> acc;
        for (long c = cb; c < ce; ++c) {
          Part& part = parts[c];
          const long b0 = first + nblocks * c / chunks, b1 = first + nblocks * (c + 1) / chunks;
          part.count.reserve(blocks[b1] - blocks[b0]);
          part.col.reserve(static_cast<size_t>(A.ptr[blocks[b1]] - A.ptr[blocks[b0]]) * 4);
          part.val.reserve(part.col.capacity());
          for (long blk = b0; blk < b1; ++blk) {
            const int r0 = blocks[blk], nr = blocks[blk + 1] - r0, len = A.ptr[r0 + 1] - A.ptr[r0];
            touched.clear();
            for (int k = 0; k < len; ++k) {
              const int cc = A.col[A.ptr[r0] + k];
              double a[kB];
              for (int r = 0; r < nr; ++r) a[r] = A.val[A.ptr[r0 + r] + k];
              for (int kb = B.ptr[cc]; kb < B.ptr[cc + 1]; ++kb) {
                const int j = B.col[kb];
                const double v = B.val[kb];
                if (mark[j] != blk) {
                  mark[j] = static_cast<int>(blk);
                  slot[j] = static_cast<int>(touched.size());
                  touched.push_back(j);
                  if (acc.size() < touched.size() * kB) acc.resize(2 * touched.size() * kB);
                  double* q = &acc[kB * slot[j]];
                  for (int r = 0; r < nr; ++r) q[r] = a[r] * v;
                } else {
                  double* q = &acc[kB * slot[j]];
                  for (int r = 0; r < nr; ++r) q[r] += a[r] * v;
                }
              }
            }
            for (int r = 0; r < nr; ++r) {
              part.count.push_back(static_cast<int>(touched.size()));
              for (size_t t = 0; t < touched.size(); ++t) {
                part.col.push_back(touched[t]);
                part.val.push_back(acc[kB * t + r]);
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

void add_product_rows(const CsrMatrix& A, const CsrMatrix& X, int first, std::vector<int>& cursor, CsrMatrix& C,
                      int threads) {
  assert(C.rows == A.rows && C.cols == X.cols);
  constexpr int kB = CsrMatrix::kMaxBlock;
  const bool one_row = A.blocks.empty();
  const long nblocks = row_blocks(A);
  const int last = first + X.rows;
  assert(static_cast<long>(cursor.size()) == nblocks);
  parallel_for(
      nblocks, threads,
      [&](long bb, long be) {
        std::vector<int> slot(C.cols);  // a column's position in the block's rows of C
        for (long blk = bb; blk < be; ++blk) {
          const int r0 = one_row ? static_cast<int>(blk) : A.blocks[blk];
          const int nr = one_row ? 1 : A.blocks[blk + 1] - r0, end = A.ptr[r0 + 1];
          int k = cursor[blk];
          if (k == end || A.col[k] >= last) continue;
          const int c0 = C.ptr[r0], clen = C.ptr[r0 + 1] - c0;
          for (int t = 0; t < clen; ++t) slot[C.col[c0 + t]] = t;
          for (; k < end && A.col[k] < last; ++k) {
            const int i = A.col[k] - first, offset = k - A.ptr[r0];
            double a[kB];
            for (int r = 0; r < nr; ++r) a[r] = A.val[A.ptr[r0 + r] + offset];
            for (int kx = X.ptr[i]; kx < X.ptr[i + 1]; ++kx) {
              const int t = slot[X.col[kx]];
              const double v = X.val[kx];
              for (int r = 0; r < nr; ++r) C.val[C.ptr[r0 + r] + t] += a[r] * v;
            }
          }
          cursor[blk] = k;
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
