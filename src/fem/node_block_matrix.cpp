// 3×3 node blocks of the elasticity matrix (see node_block_matrix.h).
#include "fem/node_block_matrix.h"

#include "common/parallel.h"

namespace topopt::fem {

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

template <class Value>
void NodeBlockPattern::fill(const CsrMatrix& M, std::vector<Value>& out) const {
  out.assign(9 * col.size(), Value(0));
  for (int b = 0; b < nodes; ++b) {
    const int r0 = first[b], nr = first[b + 1] - r0, len = M.ptr[r0 + 1] - M.ptr[r0];
    int blk = ptr[b];
    for (int k = 0; k < len; ++k) {
      const int c = M.col[M.ptr[r0] + k];
      while (c >= first[col[blk] + 1]) ++blk;  // columns increase: the block of c is this one or later
      Value* v = &out[9L * blk + (c - first[col[blk]])];
      for (int r = 0; r < nr; ++r) v[3 * r] = static_cast<Value>(M.val[M.ptr[r0 + r] + k]);
    }
  }
}

template <class Value>
void NodeBlockPattern::multiply(const std::vector<Value>& val, const double* x, double* y, std::vector<double>& scratch,
                                int threads) const {
  const double* xs = x;  // x with 3 entries per row block (as it is when no block is padded)
  if (padded) {
    scratch.resize(3L * nodes);
    parallel_for(
        nodes, threads,
        [&](long b, long e) {
          for (long n = b; n < e; ++n) {
            const int r0 = first[n], nr = first[n + 1] - r0;
            for (int j = 0; j < 3; ++j) scratch[3 * n + j] = j < nr ? x[r0 + j] : 0.0;
          }
        },
        4096);
    xs = scratch.data();
  }
  const int* bp = ptr.data();
  const int* bc = col.data();
  const Value* bv = val.data();
  parallel_for(
      nodes, threads,
      [&](long b, long e) {
        for (long n = b; n < e; ++n) {
          // each row's terms in column order, as the row walk adds them; three sums side by side
          double s0 = 0, s1 = 0, s2 = 0;
          for (int k = bp[n]; k < bp[n + 1]; ++k) {
            const double* xv = xs + 3L * bc[k];
            const Value* v = bv + 9L * k;
            s0 += v[0] * xv[0], s1 += v[3] * xv[0], s2 += v[6] * xv[0];
            s0 += v[1] * xv[1], s1 += v[4] * xv[1], s2 += v[7] * xv[1];
            s0 += v[2] * xv[2], s1 += v[5] * xv[2], s2 += v[8] * xv[2];
          }
          const int r0 = first[n], nr = first[n + 1] - r0;
          y[r0] = s0;
          if (nr > 1) y[r0 + 1] = s1;
          if (nr > 2) y[r0 + 2] = s2;
        }
      },
      1024);
}

template void NodeBlockPattern::fill(const CsrMatrix&, std::vector<float>&) const;
template void NodeBlockPattern::fill(const CsrMatrix&, std::vector<double>&) const;
template void NodeBlockPattern::multiply(const std::vector<float>&, const double*, double*, std::vector<double>&,
                                         int) const;
template void NodeBlockPattern::multiply(const std::vector<double>&, const double*, double*, std::vector<double>&,
                                         int) const;

}  // namespace topopt::fem
