// 3×3 node blocks of the elasticity matrix (see node_block_matrix.h).
#include "fem/node_block_matrix.h"

#if TOPOPT_AVX_KERNELS
#include <immintrin.h>
#endif

#include "common/parallel.h"

namespace topopt::fem {

namespace {

/// x with `width` entries per block (blocks [first[j], first[j+1]) of x, at most `width` long, the
/// rest zeros) in scratch; x itself when no block is padded.
const double* padded_x(const std::vector<int>& first, int width, bool padded, const double* x,
                       std::vector<double>& scratch, int threads) {
  if (!padded) return x;
  const long blocks = static_cast<long>(first.size()) - 1;
  scratch.resize(static_cast<size_t>(width) * blocks);
  parallel_for(
      blocks, threads,
      [&](long b, long e) {
        for (long j = b; j < e; ++j) {
          const int c0 = first[j], nc = first[j + 1] - c0;
          for (int c = 0; c < width; ++c) scratch[width * j + c] = c < nc ? x[c0 + c] : 0.0;
        }
      },
      4096);
  return scratch.data();
}

}  // namespace

bool NodeBlockPattern::build(const CsrMatrix& M) {
  *this = NodeBlockPattern();
  if (M.rows != M.cols || M.blocks.size() < 2 || !M.blocks_consistent()) return false;
  NodeBlockPattern P;
  P.nodes = static_cast<int>(M.blocks.size()) - 1;
  P.first = M.blocks;
  std::vector<int> block_of(M.rows);
  for (int b = 0; b < P.nodes; ++b) {
    const int nr = M.blocks[b + 1] - M.blocks[b];
    if (nr < 1 || nr > 3) return false;
    P.padded |= nr < 3;
    for (int r = M.blocks[b]; r < M.blocks[b + 1]; ++r) block_of[r] = b;
  }
  P.ptr.reserve(P.nodes + 1);
  P.ptr.push_back(0);
  for (int b = 0; b < P.nodes; ++b) {
    const int r0 = M.blocks[b];  // the block's other rows have the same columns (blocks_consistent)
    int previous = -1;
    for (int k = M.ptr[r0]; k < M.ptr[r0 + 1]; ++k) {
      const int c = M.col[k];
      if (c <= previous) return false;  // the row walk's order is the blocks' only if columns increase
      if (previous < 0 || block_of[c] != block_of[previous]) P.col.push_back(block_of[c]);
      previous = c;
    }
    P.ptr.push_back(static_cast<int>(P.col.size()));
  }
  if (9.0 * static_cast<double>(P.col.size()) > kMaxFill * static_cast<double>(M.nonzeros())) return false;
  *this = std::move(P);
  return true;
}

template <class Put>
void NodeBlockPattern::walk(const CsrMatrix& M, Put put) const {
  for (int b = 0; b < nodes; ++b) {
    const int r0 = first[b], nr = first[b + 1] - r0, len = M.ptr[r0 + 1] - M.ptr[r0];
    int blk = ptr[b];
    for (int k = 0; k < len; ++k) {
      const int c = M.col[M.ptr[r0] + k];
      while (c >= first[col[blk] + 1]) ++blk;                // columns increase: the block of c is this one or later
      const long at = 9L * blk + 3 * (c - first[col[blk]]);  // a block's column c at 3 c
      for (int r = 0; r < nr; ++r) put(at + r, M.val[M.ptr[r0 + r] + k]);
    }
  }
}

template <class Value>
void NodeBlockPattern::fill(const CsrMatrix& M, std::vector<Value>& out) const {
  out.assign(values(), Value(0));
  walk(M, [&](long at, double v) { out[at] = static_cast<Value>(v); });
}

void NodeBlockPattern::fill(const CsrMatrix& M, std::vector<double>& exact, std::vector<float>& single) const {
  const size_t size = values();
  if (exact.size() != size || single.size() != size) exact.assign(size, 0.0), single.assign(size, 0.0f);
  walk(M, [&](long at, double v) {
    exact[at] = v;
    single[at] = static_cast<float>(v);
  });
}

NodeBlockPattern::Kernel NodeBlockPattern::fastest_kernel() {
#if TOPOPT_AVX_KERNELS
  return __builtin_cpu_supports("avx") ? Kernel::Avx : Kernel::Scalar;
#else
  return Kernel::Scalar;
#endif
}

namespace {

/// y's rows of node blocks b .. e − 1 from the block values `bv` (9 a block, column-major) and
/// the padded x `xs` (3 a node), one row at a time within a block's column: each row's terms in
/// column order, as the row walk adds them; three sums side by side.
template <class Value>
void scalar_block_rows(const NodeBlockPattern& p, const Value* bv, const double* xs, double* y, long b, long e) {
  const int* bp = p.ptr.data();
  const int* bc = p.col.data();
  for (long n = b; n < e; ++n) {
    double s0 = 0, s1 = 0, s2 = 0;
    for (int k = bp[n]; k < bp[n + 1]; ++k) {
      const double* xv = xs + 3L * bc[k];
      const Value* v = bv + 9L * k;
      s0 += v[0] * xv[0], s1 += v[1] * xv[0], s2 += v[2] * xv[0];
      s0 += v[3] * xv[1], s1 += v[4] * xv[1], s2 += v[5] * xv[1];
      s0 += v[6] * xv[2], s1 += v[7] * xv[2], s2 += v[8] * xv[2];
    }
    const int r0 = p.first[n], nr = p.first[n + 1] - r0;
    y[r0] = s0;
    if (nr > 1) y[r0 + 1] = s1;
    if (nr > 2) y[r0 + 2] = s2;
  }
}

#if TOPOPT_AVX_KERNELS
/// A block's column as four doubles (its three rows and the next value, which no row uses).
__attribute__((target("avx"))) inline __m256d column_of(const float* v) { return _mm256_cvtps_pd(_mm_loadu_ps(v)); }
__attribute__((target("avx"))) inline __m256d column_of(const double* v) { return _mm256_loadu_pd(v); }

/// scalar_block_rows with a node's three rows in the lanes of one AVX register: lane r adds
/// v[3 c + r] x_c for c = 0, 1, 2, block after block — each row's products and sums in the
/// scalar kernel's order, rounded alike (no fused multiply-add: the target is AVX alone), so the
/// same values to the bit, in about two thirds of its time (BENCHMARKS.md, branch speed17).
/// The fourth lane reads the next value (the fill's one past the last block at the end).
template <class Value>
__attribute__((target("avx"))) void avx_block_rows(const NodeBlockPattern& p, const Value* bv, const double* xs,
                                                   double* y, long b, long e) {
  const int* bp = p.ptr.data();
  const int* bc = p.col.data();
  for (long n = b; n < e; ++n) {
    __m256d s = _mm256_setzero_pd();
    for (int k = bp[n]; k < bp[n + 1]; ++k) {
      const double* xv = xs + 3L * bc[k];
      const Value* v = bv + 9L * k;
      s = _mm256_add_pd(s, _mm256_mul_pd(column_of(v), _mm256_broadcast_sd(xv)));
      s = _mm256_add_pd(s, _mm256_mul_pd(column_of(v + 3), _mm256_broadcast_sd(xv + 1)));
      s = _mm256_add_pd(s, _mm256_mul_pd(column_of(v + 6), _mm256_broadcast_sd(xv + 2)));
    }
    alignas(32) double sum[4];
    _mm256_store_pd(sum, s);
    const int r0 = p.first[n], nr = p.first[n + 1] - r0;
    for (int r = 0; r < nr; ++r) y[r0 + r] = sum[r];
  }
}

#endif

}  // namespace

template <class Value>
void NodeBlockPattern::multiply(const std::vector<Value>& val, const double* x, double* y, std::vector<double>& scratch,
                                int threads, [[maybe_unused]] Kernel kernel) const {
  const double* xs = padded_x(first, 3, padded, x, scratch, threads);  // 3 entries per row block
  parallel_for(
      nodes, threads,
      [&](long b, long e) {
#if TOPOPT_AVX_KERNELS
        if (kernel == Kernel::Avx) return avx_block_rows(*this, val.data(), xs, y, b, e);
#endif
        scalar_block_rows(*this, val.data(), xs, y, b, e);
      },
      1024);
}

template <int RB, int CB>
bool BlockPattern<RB, CB>::build(const CsrMatrix& M, const std::vector<int>& columns) {
  *this = BlockPattern();
  if (M.blocks.size() < 2 || !M.blocks_consistent() || columns.size() < 2 || columns.front() != 0 ||
      columns.back() != M.cols)
    return false;
  BlockPattern P;
  P.row_blocks = static_cast<int>(M.blocks.size()) - 1;
  P.row_first = M.blocks;
  P.col_first = columns;
  const int column_blocks = static_cast<int>(columns.size()) - 1;
  std::vector<int> block_of(M.cols);
  for (int j = 0; j < column_blocks; ++j) {
    const int nc = columns[j + 1] - columns[j];
    if (nc < 1 || nc > CB) return false;
    P.padded |= nc < CB;
    for (int c = columns[j]; c < columns[j + 1]; ++c) block_of[c] = j;
  }
  std::vector<int> met(column_blocks, -1);  // the last row block whose row met each column block
  P.ptr.reserve(P.row_blocks + 1);
  P.ptr.push_back(0);
  for (int b = 0; b < P.row_blocks; ++b) {
    const int r0 = M.blocks[b];  // the block's other rows have the same columns (blocks_consistent)
    if (M.blocks[b + 1] - r0 > RB) return false;
    int previous = -1;
    for (int k = M.ptr[r0]; k < M.ptr[r0 + 1]; ++k) {
      const int c = M.col[k], j = block_of[c];
      if (previous >= 0 && j == block_of[previous]) {
        if (c <= previous) return false;  // within a block the row walk's order is the columns'
      } else {
        if (met[j] == b) return false;  // the block's entries are not consecutive in the row
        met[j] = b;
        P.col.push_back(j);
      }
      previous = c;
    }
    P.ptr.push_back(static_cast<int>(P.col.size()));
  }
  if (static_cast<double>(RB * CB) * static_cast<double>(P.col.size()) > kMaxFill * static_cast<double>(M.nonzeros()))
    return false;
  *this = std::move(P);
  return true;
}

template <int RB, int CB>
template <class Value>
void BlockPattern<RB, CB>::fill(const CsrMatrix& M, std::vector<Value>& out) const {
  constexpr long kValues = RB * CB;
  out.assign(values(), Value(0));
  for (int b = 0; b < row_blocks; ++b) {
    const int r0 = row_first[b], nr = row_first[b + 1] - r0, len = M.ptr[r0 + 1] - M.ptr[r0];
    int blk = ptr[b];
    for (int k = 0; k < len; ++k) {
      const int c = M.col[M.ptr[r0] + k];
      // a block's entries are consecutive and the blocks in the row's order: past this one, the next
      if (c < col_first[col[blk]] || c >= col_first[col[blk] + 1]) ++blk;
      Value* v = &out[kValues * blk + RB * (c - col_first[col[blk]])];  // a block's column c at RB c
      for (int r = 0; r < nr; ++r) v[r] = static_cast<Value>(M.val[M.ptr[r0 + r] + k]);
    }
  }
}

namespace {

/// y's rows of row blocks b .. e − 1 of a BlockPattern p (RB × CB blocks, column-major values
/// `bv`; the padded x `xs`, CB a column block), one row at a time: each row's terms in the row
/// walk's order, block by block, columns increasing.
template <int RB, int CB, class Value>
void scalar_transfer_rows(const BlockPattern<RB, CB>& p, const Value* bv, const double* xs, double* y, long b, long e) {
  for (long n = b; n < e; ++n) {
    double s[RB] = {};
    for (int k = p.ptr[n]; k < p.ptr[n + 1]; ++k) {
      const double* xv = xs + static_cast<long>(CB) * p.col[k];
      const Value* v = bv + static_cast<long>(RB * CB) * k;
      for (int c = 0; c < CB; ++c)
        for (int r = 0; r < RB; ++r) s[r] += v[RB * c + r] * xv[c];
    }
    const int r0 = p.row_first[n], nr = p.row_first[n + 1] - r0;
    for (int r = 0; r < nr; ++r) y[r0 + r] = s[r];
  }
}

#if TOPOPT_AVX_KERNELS
/// Two of a column's values as doubles (rows 4 and 5 of the restriction's 6).
__attribute__((target("avx"))) inline __m128d pair_of(const float* v) {
  return _mm_cvtps_pd(_mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(v))));
}
__attribute__((target("avx"))) inline __m128d pair_of(const double* v) { return _mm_loadu_pd(v); }

/// scalar_transfer_rows with a block's rows in the lanes of AVX registers (RB = 3: one register,
/// its fourth lane reading the next value — the next column's, block's, or the fill's one past the
/// end — and never stored; RB = 6: four lanes and two): each row's products and sums in the scalar
/// order, rounded alike (no fused multiply-add), the same values to the bit.
template <int RB, int CB, class Value>
__attribute__((target("avx"))) void avx_transfer_rows(const BlockPattern<RB, CB>& p, const Value* bv, const double* xs,
                                                      double* y, long b, long e) {
  static_assert(RB == 3 || RB == 6, "the transfers' blocks: 3 or 6 rows");
  for (long n = b; n < e; ++n) {
    __m256d lo = _mm256_setzero_pd();  // rows 0-3 (0-2 and a lane not used when RB = 3)
    __m128d hi = _mm_setzero_pd();     // rows 4-5 when RB = 6
    for (int k = p.ptr[n]; k < p.ptr[n + 1]; ++k) {
      const double* xv = xs + static_cast<long>(CB) * p.col[k];
      const Value* v = bv + static_cast<long>(RB * CB) * k;
      for (int c = 0; c < CB; ++c, v += RB) {
        const __m256d x = _mm256_broadcast_sd(xv + c);
        lo = _mm256_add_pd(lo, _mm256_mul_pd(column_of(v), x));
        if (RB == 6) hi = _mm_add_pd(hi, _mm_mul_pd(pair_of(v + 4), _mm256_castpd256_pd128(x)));
      }
    }
    alignas(32) double sum[8];
    _mm256_store_pd(sum, lo);
    _mm_store_pd(sum + 4, hi);
    const int r0 = p.row_first[n], nr = p.row_first[n + 1] - r0;
    for (int r = 0; r < nr; ++r) y[r0 + r] = sum[r];
  }
}

#endif

}  // namespace

template <int RB, int CB>
template <class Value>
void BlockPattern<RB, CB>::multiply(const std::vector<Value>& val, const double* x, double* y,
                                    std::vector<double>& scratch, int threads, [[maybe_unused]] Kernel kernel) const {
  const double* xs = padded_x(col_first, CB, padded, x, scratch, threads);  // CB entries per column block
  parallel_for(
      row_blocks, threads,
      [&](long b, long e) {
#if TOPOPT_AVX_KERNELS
        if (kernel == Kernel::Avx) return avx_transfer_rows(*this, val.data(), xs, y, b, e);
#endif
        scalar_transfer_rows(*this, val.data(), xs, y, b, e);
      },
      512);
}

template struct BlockPattern<3, 6>;
template struct BlockPattern<6, 3>;
template void BlockPattern<3, 6>::fill(const CsrMatrix&, std::vector<float>&) const;
template void BlockPattern<3, 6>::fill(const CsrMatrix&, std::vector<double>&) const;
template void BlockPattern<6, 3>::fill(const CsrMatrix&, std::vector<float>&) const;
template void BlockPattern<6, 3>::fill(const CsrMatrix&, std::vector<double>&) const;
template void BlockPattern<3, 6>::multiply(const std::vector<float>&, const double*, double*, std::vector<double>&, int,
                                           Kernel) const;
template void BlockPattern<3, 6>::multiply(const std::vector<double>&, const double*, double*, std::vector<double>&,
                                           int, Kernel) const;
template void BlockPattern<6, 3>::multiply(const std::vector<float>&, const double*, double*, std::vector<double>&, int,
                                           Kernel) const;
template void BlockPattern<6, 3>::multiply(const std::vector<double>&, const double*, double*, std::vector<double>&,
                                           int, Kernel) const;

template void NodeBlockPattern::fill(const CsrMatrix&, std::vector<float>&) const;
template void NodeBlockPattern::fill(const CsrMatrix&, std::vector<double>&) const;
template void NodeBlockPattern::multiply(const std::vector<float>&, const double*, double*, std::vector<double>&, int,
                                         Kernel) const;
template void NodeBlockPattern::multiply(const std::vector<double>&, const double*, double*, std::vector<double>&, int,
                                         Kernel) const;

}  // namespace topopt::fem
