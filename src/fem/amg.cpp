// Smoothed-aggregation AMG and AMG-preconditioned conjugate gradients (see amg.h).
#include "fem/amg.h"

#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <deque>
#include <numeric>
#include <sstream>

#include "common/error.h"
#include "common/parallel.h"

namespace topopt::fem {

namespace {

/// y = M x with M's pattern and the values `val` (double, or float copies for the V-cycle:
/// the products are memory-bound, and 4-byte values cut the bytes read by a third).
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

}  // namespace

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

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// C = A B (Gustavson's row-by-row product with a dense accumulator per thread). With row
/// blocks in A, the rows of a block are formed together (one index walk for all of them) and
/// C inherits A's blocks.
CsrMatrix multiply(const CsrMatrix& A, const CsrMatrix& B, int threads) {
  assert(A.cols == B.rows);
  constexpr int kB = CsrMatrix::kMaxBlock;
  CsrMatrix C;
  C.rows = A.rows;
  C.cols = B.cols;
  std::vector<int> blocks = A.blocks;
  if (blocks.empty()) {  // one row a block
    blocks.resize(A.rows + 1);
    std::iota(blocks.begin(), blocks.end(), 0);
  }
  const long nblocks = static_cast<long>(blocks.size()) - 1;
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
          const long b0 = nblocks * c / chunks, b1 = nblocks * (c + 1) / chunks;
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
  C.ptr.assign(A.rows + 1, 0);
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
  assert(row == A.rows);
  C.blocks = A.blocks;
  return C;
}

/// A^T in compressed rows.
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

struct Level {
  CsrMatrix own;                 // this level's matrix (unused on level 0)
  const CsrMatrix* A = nullptr;  // the matrix of this level
  std::vector<double> inv_diag;
  double lambda = 1;           // estimate of λmax(D⁻¹A)
  std::vector<double> eigvec;  // its eigenvector estimate (restarts the power iteration)
  CsrMatrix P, R;              // to/from the next coarser level
  // single-precision copies of A, P, R's values: what the V-cycle reads (see sparse_product)
  std::vector<float> Af, Pf, Rf;
  // work vectors of the V-cycle (apply() is logically const): right-hand side, solution,
  // residual, Chebyshev correction, scratch product
  mutable std::vector<double> b, x, r, d, q;
};

}  // namespace

struct SmoothedAggregationAmg::Impl {
  AmgParams params;
  int threads = 1;
  std::deque<Level> levels;  // a deque: levels point at their own matrices
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> coarse;
  mutable Eigen::VectorXd coarse_b, coarse_x;

  /// Power iteration for λmax(D⁻¹A): `steps` steps from L.eigvec if it is set (a refresh:
  /// the matrix changed a little), else 15 from a fixed start.
  void estimate_lambda(Level& L, int steps = 15) const;
  void inverse_diagonal(Level& L) const;
  void factor_coarsest();
  /// Builds the next level's tentative prolongator from this one; returns false if the
  /// level does not coarsen any more.
  bool coarsen(Level& L, const std::vector<int>& node_ptr, const std::vector<double>& modes,
               std::vector<int>& coarse_ptr, std::vector<double>& coarse_modes, CsrMatrix& Pt) const;
  static void to_float(const CsrMatrix& M, std::vector<float>& out) { out.assign(M.val.begin(), M.val.end()); }
  void smooth(const Level& L, const double* b, double* x, bool zero_start) const;
  void cycle(size_t l) const;
};

void SmoothedAggregationAmg::Impl::estimate_lambda(Level& L, int steps) const {
  // Power iteration on D⁻¹A from a fixed, non-smooth start (deterministic).
  const int n = L.A->rows;
  std::vector<double> v(n), w(n);
  if (static_cast<int>(L.eigvec.size()) == n) {
    v = L.eigvec;
  } else {
    steps = 15;
    for (int i = 0; i < n; ++i) v[i] = 1.0 + 0.5 * std::sin(12.9898 * i);
  }
  double lambda = 0;
  for (int it = 0; it < steps; ++it) {
    double nv = 0;
    for (double a : v) nv += a * a;
    nv = std::sqrt(nv);
    if (nv == 0) break;
    for (double& a : v) a /= nv;
    L.A->multiply(v.data(), w.data(), threads);
    double num = 0;
    for (int i = 0; i < n; ++i) {
      w[i] *= L.inv_diag[i];
      num += v[i] * w[i];
    }
    lambda = num;
    std::swap(v, w);
  }
  L.eigvec = v;
  // The Rayleigh quotient underestimates λmax; Chebyshev and the prolongator smoothing
  // both need an upper bound, so pad it (the power method is within a few % after 15 steps).
  L.lambda = std::max(lambda, 1e-300);
}

void SmoothedAggregationAmg::Impl::factor_coarsest() {
  // Sparse Cholesky of the coarsest matrix (its lower triangle).
  const CsrMatrix& Ac = *levels.back().A;
  std::vector<Eigen::Triplet<double, int>> trip;
  trip.reserve(Ac.nonzeros() / 2 + Ac.rows);
  for (int i = 0; i < Ac.rows; ++i)
    for (int k = Ac.ptr[i]; k < Ac.ptr[i + 1]; ++k)
      if (Ac.col[k] >= i) trip.emplace_back(Ac.col[k], i, Ac.val[k]);  // lower triangle
  SpMat S(Ac.rows, Ac.rows);
  S.setFromTriplets(trip.begin(), trip.end());
  // AMD only: the coarse matrix is small and dense-ish; CHOLMOD's default of trying several
  // orderings costs more than the fill it saves (measured on the rocker's 8.7 k coarse level).
  coarse.cholmod().nmethods = 1;
  coarse.cholmod().method[0].ordering = CHOLMOD_AMD;
  coarse.compute(S);
  if (coarse.info() != Eigen::Success)
    throw Error(ErrorCode::NoSupport,
                "the coarse multigrid matrix is not positive definite: the supports "
                "do not hold the structure, or the mesh has degenerate elements");
}

void SmoothedAggregationAmg::Impl::inverse_diagonal(Level& L) const {
  const CsrMatrix& A = *L.A;
  L.inv_diag.assign(A.rows, 0.0);
  for (int i = 0; i < A.rows; ++i)
    for (int k = A.ptr[i]; k < A.ptr[i + 1]; ++k)
      if (A.col[k] == i) L.inv_diag[i] += A.val[k];
  for (int i = 0; i < A.rows; ++i) {
    if (!(L.inv_diag[i] > 0))
      throw Error(ErrorCode::NoSupport,
                  "the stiffness matrix has a zero or negative diagonal entry: "
                  "an unknown is not held by any element; check the mesh and supports");
    L.inv_diag[i] = 1 / L.inv_diag[i];
  }
}

bool SmoothedAggregationAmg::Impl::coarsen(Level& L, const std::vector<int>& node_ptr, const std::vector<double>& modes,
                                           std::vector<int>& coarse_ptr, std::vector<double>& coarse_modes,
                                           CsrMatrix& Pt) const {
  const CsrMatrix& A = *L.A;
  const int nnode = static_cast<int>(node_ptr.size()) - 1;
  std::vector<int> node_of(A.rows);
  for (int k = 0; k < nnode; ++k)
    for (int i = node_ptr[k]; i < node_ptr[k + 1]; ++i) node_of[i] = k;
  // Block norms: ||A_kk||_F, then the strong neighbours of every node.
  std::vector<double> dnorm(nnode, 0.0);
  for (int i = 0; i < A.rows; ++i)
    for (int k = A.ptr[i]; k < A.ptr[i + 1]; ++k)
      if (node_of[A.col[k]] == node_of[i]) dnorm[node_of[i]] += A.val[k] * A.val[k];
  for (double& d : dnorm) d = std::sqrt(d);
  const double theta2 = params.strength * params.strength;
  std::vector<int> sptr(nnode + 1, 0), sadj;
  {
    std::vector<double> acc(nnode, 0.0);
    std::vector<int> mark(nnode, -1), touched;
    for (int k = 0; k < nnode; ++k) {
      touched.clear();
      for (int i = node_ptr[k]; i < node_ptr[k + 1]; ++i)
        for (int e = A.ptr[i]; e < A.ptr[i + 1]; ++e) {
          int m = node_of[A.col[e]];
          if (m == k) continue;
          if (mark[m] != k) mark[m] = k, acc[m] = 0, touched.push_back(m);
          acc[m] += A.val[e] * A.val[e];
        }
      for (int m : touched)
        if (acc[m] > theta2 * dnorm[k] * dnorm[m]) sadj.push_back(m);
      sptr[k + 1] = static_cast<int>(sadj.size());
    }
  }
  // Greedy aggregation in three phases.
  std::vector<int> agg(nnode, -1);
  int naggs = 0;
  for (int k = 0; k < nnode; ++k) {
    if (node_ptr[k] == node_ptr[k + 1]) agg[k] = -2;  // no rows
  }
  for (int k = 0; k < nnode; ++k) {  // 1: a node whose whole neighbourhood is free seeds one
    if (agg[k] != -1 || sptr[k] == sptr[k + 1]) continue;
    bool free = true;
    for (int e = sptr[k]; e < sptr[k + 1] && free; ++e) free = agg[sadj[e]] == -1;
    if (!free) continue;
    agg[k] = naggs;
    for (int e = sptr[k]; e < sptr[k + 1]; ++e) agg[sadj[e]] = naggs;
    ++naggs;
  }
  std::vector<int> first = agg;
  for (int k = 0; k < nnode; ++k) {  // 2: join a neighbouring aggregate of phase 1
    if (agg[k] != -1) continue;
    for (int e = sptr[k]; e < sptr[k + 1]; ++e)
      if (first[sadj[e]] >= 0) {
        agg[k] = first[sadj[e]];
        break;
      }
  }
  for (int k = 0; k < nnode; ++k) {  // 3: what is left forms aggregates with its free neighbours
    if (agg[k] != -1) continue;
    agg[k] = naggs;
    for (int e = sptr[k]; e < sptr[k + 1]; ++e)
      if (agg[sadj[e]] == -1) agg[sadj[e]] = naggs;
    ++naggs;
  }
  // Rows of each aggregate.
  std::vector<int> aptr(naggs + 1, 0), arows(A.rows);
  for (int k = 0; k < nnode; ++k)
    if (agg[k] >= 0) aptr[agg[k] + 1] += node_ptr[k + 1] - node_ptr[k];
  for (int a = 0; a < naggs; ++a) aptr[a + 1] += aptr[a];
  {
    std::vector<int> fill(aptr.begin(), aptr.end() - 1);
    for (int k = 0; k < nnode; ++k)
      if (agg[k] >= 0)
        for (int i = node_ptr[k]; i < node_ptr[k + 1]; ++i) arows[fill[agg[k]]++] = i;
  }
  // Tentative prolongator: per aggregate, the rigid modes restricted to its rows,
  // orthonormalised by modified Gram-Schmidt (twice, for stability); modes that are
  // dependent on the aggregate (a lone node cannot tell rotations from translations) drop out.
  // B_a = Q_a R_a, with Q_a the prolongator's block and R_a the coarse modes.
  coarse_ptr.assign(1, 0);
  coarse_modes.clear();
  std::vector<int> pt_col(A.rows * 6, -1);  // up to 6 entries a row, row-major
  std::vector<double> pt_val(A.rows * 6, 0.0);
  std::vector<int> pt_count(A.rows, 0);
  std::vector<double> Q, v;
  for (int a = 0; a < naggs; ++a) {
    const int m = aptr[a + 1] - aptr[a];
    const int* rows = &arows[aptr[a]];
    Q.clear();
    double Rm[6][6] = {};
    int kept = 0;
    for (int j = 0; j < 6; ++j) {
      v.resize(m);
      double norm0 = 0;
      for (int i = 0; i < m; ++i) v[i] = modes[6 * rows[i] + j], norm0 += v[i] * v[i];
      norm0 = std::sqrt(norm0);
      double coef[6] = {};
      for (int pass = 0; pass < 2; ++pass)
        for (int q = 0; q < kept; ++q) {
          double s = 0;
          for (int i = 0; i < m; ++i) s += Q[q * m + i] * v[i];
          for (int i = 0; i < m; ++i) v[i] -= s * Q[q * m + i];
          coef[q] += s;
        }
      double nv = 0;
      for (double x : v) nv += x * x;
      nv = std::sqrt(nv);
      for (int q = 0; q < kept; ++q) Rm[q][j] = coef[q];
      if (norm0 > 0 && nv > 1e-8 * norm0 && kept < m) {
        Rm[kept][j] = nv;
        for (double x : v) Q.push_back(x / nv);
        ++kept;
      }
    }
    const int c0 = coarse_ptr.back();
    for (int q = 0; q < kept; ++q) {
      for (int i = 0; i < m; ++i) {
        const int r = rows[i];
        pt_col[6 * r + pt_count[r]] = c0 + q;
        pt_val[6 * r + pt_count[r]] = Q[q * m + i];
        ++pt_count[r];
      }
      for (int j = 0; j < 6; ++j) coarse_modes.push_back(Rm[q][j]);
    }
    coarse_ptr.push_back(c0 + kept);
  }
  const int nc = coarse_ptr.back();
  if (nc == 0 || nc >= A.rows * 0.8) return false;
  Pt.rows = A.rows;
  Pt.cols = nc;
  Pt.ptr.assign(A.rows + 1, 0);
  Pt.col.clear();
  Pt.val.clear();
  for (int i = 0; i < A.rows; ++i) {
    for (int k = 0; k < pt_count[i]; ++k) Pt.col.push_back(pt_col[6 * i + k]), Pt.val.push_back(pt_val[6 * i + k]);
    Pt.ptr[i + 1] = static_cast<int>(Pt.col.size());
  }
  return true;
}

void SmoothedAggregationAmg::Impl::smooth(const Level& L, const double* b, double* x, bool zero_start) const {
  // Chebyshev iteration on D⁻¹A over [lower·λ, 1.1·λ] (three-term recurrence, Saad,
  // Iterative Methods for Sparse Linear Systems, §12.3). Uses L.r, L.d, L.q.
  const int n = L.A->rows;
  const double hi = 1.1 * L.lambda, lo = params.smoother_lower * L.lambda;
  const double theta = 0.5 * (hi + lo), delta = 0.5 * (hi - lo), sigma = theta / delta;
  double rho = 1 / sigma;
  double* r = L.r.data();
  double* d = L.d.data();
  double* q = L.q.data();
  const double* dinv = L.inv_diag.data();
  if (zero_start) {
    for (int i = 0; i < n; ++i) r[i] = b[i], x[i] = 0;
  } else {
    sparse_product(*L.A, L.Af.data(), x, q, threads);
    for (int i = 0; i < n; ++i) r[i] = b[i] - q[i];
  }
  for (int i = 0; i < n; ++i) d[i] = dinv[i] * r[i] / theta, x[i] += d[i];
  for (int k = 1; k < params.smoother_degree; ++k) {
    sparse_product(*L.A, L.Af.data(), d, q, threads);  // r -= A d keeps r = b - A x
    const double rho_new = 1 / (2 * sigma - rho);
    const double c1 = rho_new * rho, c2 = 2 * rho_new / delta;
    for (int i = 0; i < n; ++i) {
      r[i] -= q[i];
      d[i] = c1 * d[i] + c2 * dinv[i] * r[i];
      x[i] += d[i];
    }
    rho = rho_new;
  }
}

void SmoothedAggregationAmg::Impl::cycle(size_t l) const {
  // V-cycle for A_l x = b on level l: reads levels[l].b, writes levels[l].x.
  const Level& L = levels[l];
  const int n = L.A->rows;
  if (l + 1 == levels.size()) {
    coarse_b = Eigen::Map<const Eigen::VectorXd>(L.b.data(), n);
    coarse_x = coarse.solve(coarse_b);
    std::copy(coarse_x.data(), coarse_x.data() + n, L.x.begin());
    return;
  }
  smooth(L, L.b.data(), L.x.data(), true);
  sparse_product(*L.A, L.Af.data(), L.x.data(), L.q.data(), threads);
  for (int i = 0; i < n; ++i) L.r[i] = L.b[i] - L.q[i];
  const Level& C = levels[l + 1];
  sparse_product(L.R, L.Rf.data(), L.r.data(), C.b.data(), threads);
  cycle(l + 1);
  sparse_product(L.P, L.Pf.data(), C.x.data(), L.q.data(), threads);
  for (int i = 0; i < n; ++i) L.x[i] += L.q[i];
  smooth(L, L.b.data(), L.x.data(), false);
}

SmoothedAggregationAmg::SmoothedAggregationAmg() : impl_(std::make_unique<Impl>()) {}
SmoothedAggregationAmg::~SmoothedAggregationAmg() = default;
SmoothedAggregationAmg::SmoothedAggregationAmg(SmoothedAggregationAmg&&) noexcept = default;
SmoothedAggregationAmg& SmoothedAggregationAmg::operator=(SmoothedAggregationAmg&&) noexcept = default;

void SmoothedAggregationAmg::setup(const CsrMatrix& A, const std::vector<int>& node_ptr,
                                   const std::vector<double>& rigid_modes, const AmgParams& params) {
  Impl& m = *impl_;
  m.params = params;
  m.threads = thread_count(params.threads);
  if (node_ptr.empty() || node_ptr.back() != A.rows || rigid_modes.size() != 6 * static_cast<size_t>(A.rows))
    throw Error(ErrorCode::Internal, "AMG setup: node offsets or rigid modes do not match the matrix");
  if (!A.blocks_consistent())
    throw Error(ErrorCode::Internal, "AMG setup: the matrix's row blocks do not share their columns");
  m.levels.clear();
  std::vector<int> nodes = node_ptr, coarse_nodes;
  std::vector<double> modes = rigid_modes, coarse_modes;
  m.levels.emplace_back();
  m.levels[0].A = &A;
  for (;;) {
    Level& L = m.levels.back();
    const CsrMatrix& Al = *L.A;
    const int n = Al.rows;
    m.inverse_diagonal(L);
    for (auto* v : {&L.b, &L.x, &L.r, &L.d, &L.q}) v->assign(n, 0.0);
    if (n <= params.coarse_dofs || static_cast<int>(m.levels.size()) >= params.max_levels) break;
    CsrMatrix Pt;
    if (!m.coarsen(L, nodes, modes, coarse_nodes, coarse_modes, Pt)) break;
    m.estimate_lambda(L);
    // P = (I - ω D⁻¹ A) P_t with ω = 4 / (3 λmax): damps the prolongator's high-energy part.
    CsrMatrix AP = multiply(Al, Pt, m.threads);
    const double omega = 4.0 / (3.0 * 1.1 * L.lambda);
    for (int i = 0; i < n; ++i) {
      for (int k = AP.ptr[i]; k < AP.ptr[i + 1]; ++k) AP.val[k] *= -omega * L.inv_diag[i];
      for (int kt = Pt.ptr[i]; kt < Pt.ptr[i + 1]; ++kt)
        for (int k = AP.ptr[i]; k < AP.ptr[i + 1]; ++k)
          if (AP.col[k] == Pt.col[kt]) {
            AP.val[k] += Pt.val[kt];
            break;
          }
    }
    L.P = std::move(AP);
    L.R = transpose(L.P);
    L.R.blocks = coarse_nodes;  // an aggregate's coarse dofs share their fine rows
    CsrMatrix APs = multiply(Al, L.P, m.threads);
    CsrMatrix coarse = multiply(L.R, APs, m.threads);
    Impl::to_float(L.P, L.Pf);
    Impl::to_float(L.R, L.Rf);
    Impl::to_float(Al, L.Af);
    nodes.swap(coarse_nodes);
    modes.swap(coarse_modes);
    m.levels.emplace_back();
    m.levels.back().own = std::move(coarse);
    m.levels.back().A = &m.levels.back().own;
  }
  m.factor_coarsest();
}

void SmoothedAggregationAmg::refresh_finest() {
  Impl& m = *impl_;
  if (m.levels.empty()) throw Error(ErrorCode::Internal, "AMG: refresh before setup");
  m.inverse_diagonal(m.levels[0]);
  if (m.levels.size() > 1) {
    m.estimate_lambda(m.levels[0], 5);
    Impl::to_float(*m.levels[0].A, m.levels[0].Af);
  } else
    m.factor_coarsest();
}

void SmoothedAggregationAmg::apply(const double* r, double* z) const {
  const Impl& m = *impl_;
  Level& L = const_cast<Level&>(m.levels[0]);
  std::copy(r, r + L.A->rows, L.b.begin());
  m.cycle(0);
  std::copy(L.x.begin(), L.x.end(), z);
}

int SmoothedAggregationAmg::levels() const { return static_cast<int>(impl_->levels.size()); }

double SmoothedAggregationAmg::complexity() const {
  if (impl_->levels.empty()) return 0;
  double s = 0;
  for (const Level& L : impl_->levels) s += static_cast<double>(L.A->nonzeros());
  return s / static_cast<double>(impl_->levels[0].A->nonzeros());
}

std::vector<int> SmoothedAggregationAmg::level_sizes() const {
  std::vector<int> n;
  for (const Level& L : impl_->levels) n.push_back(L.A->rows);
  return n;
}

PcgResult amg_pcg(const CsrMatrix& A, const SmoothedAggregationAmg& amg, const double* b, double* x, double tolerance,
                  int max_iterations, int threads, const Progress& progress) {
  const int n = A.rows;
  using Vec = Eigen::VectorXd;
  Eigen::Map<const Vec> bv(b, n);
  Eigen::Map<Vec> xv(x, n);
  Vec r(n), z(n), p(n), q(n);
  PcgResult res;
  const double bnorm = bv.norm();
  if (bnorm == 0) {
    xv.setZero();
    res.converged = true;
    return res;
  }
  A.multiply(x, q.data(), threads);
  r = bv - q;
  double rnorm = r.norm();
  amg.apply(r.data(), z.data());
  p = z;
  double rz = r.dot(z);
  const double goal = tolerance * bnorm;
  int it = 0;
  for (; rnorm > goal && it < max_iterations; ++it) {
    if (it % 16 == 15) progress.check_cancel("the FE solve");
    A.multiply(p.data(), q.data(), threads);
    const double pq = p.dot(q);
    if (!(pq > 0)) break;  // breakdown: A (or the preconditioner) is not positive definite
    const double alpha = rz / pq;
    xv += alpha * p;
    r -= alpha * q;
    rnorm = r.norm();
    if (rnorm <= goal) {
      ++it;
      break;
    }
    amg.apply(r.data(), z.data());
    const double rz_new = r.dot(z);
    p = z + (rz_new / rz) * p;
    rz = rz_new;
  }
  res.iterations = it;
  res.relative_residual = rnorm / bnorm;
  res.converged = rnorm <= goal;
  return res;
}

}  // namespace topopt::fem
