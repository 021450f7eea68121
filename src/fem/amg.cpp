// Smoothed-aggregation AMG (see amg.h).
#include "fem/amg.h"

#include <Eigen/CholmodSupport>
#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <deque>

#include "common/adjacency.h"
#include "common/error.h"
#include "common/parallel.h"
#include "fem/node_block_matrix.h"

namespace topopt::fem {

namespace {

using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

struct Level {
  CsrMatrix own;                 // this level's matrix (unused on level 0)
  const CsrMatrix* A = nullptr;  // the matrix of this level
  std::vector<double> inv_diag;
  std::vector<long> diag_at;   // position of each row's diagonal entry in A (found at the first use)
  double lambda = 1;           // estimate of λmax(D⁻¹A)
  std::vector<double> eigvec;  // its eigenvector estimate (restarts the power iteration)
  CsrMatrix P, R;              // to/from the next coarser level
  // single-precision copies of A, P, R's values: what the V-cycle reads (see sparse_product)
  std::vector<float> Af, Pf, Rf;
  // P and R in blocks of a node's rows by an aggregate's coarse dofs where they fit (the finest
  // level of an elasticity hierarchy), then the V-cycle's transfers read Pbf and Rbf (single
  // precision, the same sums as the row walks on Pf and Rf) and Pf, Rf stay empty
  ProlongatorBlocks pb;
  RestrictionBlocks rb;
  std::vector<float> Pbf, Rbf;
  // A in 3×3 node blocks where it fits (the finest level of an elasticity hierarchy: K), then
  // the products with A read these instead of A and Af: Abf in the V-cycle, Abd (A's values to
  // the bit) in the power iteration and multiply_finest
  NodeBlockPattern nb;
  std::vector<float> Abf;
  std::vector<double> Abd;
  bool p_by_blocks = false;  // P's row blocks are nb's, their rows sharing columns: A P from the blocks
  // work vectors of the V-cycle (apply() is logically const): right-hand side, solution,
  // residual, Chebyshev correction, scratch product
  mutable std::vector<double> b, x, r, d, q, xpad, tpad;  // tpad: the transfers' padded x
};

/// The node of each row: rows node_ptr[k] .. node_ptr[k+1]-1 belong to node k.
std::vector<int> row_nodes(const std::vector<int>& node_ptr, int rows) {
  std::vector<int> node_of(rows);
  const int nnode = static_cast<int>(node_ptr.size()) - 1;
  for (int k = 0; k < nnode; ++k)
    for (int i = node_ptr[k]; i < node_ptr[k + 1]; ++i) node_of[i] = k;
  return node_of;
}

/// The strong neighbours of every node (rows of A grouped by node_ptr, node_of: the node of
/// each row): m is one of k's if ||A_km||_F² > θ² ||A_kk||_F ||A_mm||_F, θ = `strength`.
/// Neighbours are listed in the order the rows of k first reach them.
Adjacency strength_graph(const CsrMatrix& A, const std::vector<int>& node_ptr, const std::vector<int>& node_of,
                         double strength) {
  const int nnode = static_cast<int>(node_ptr.size()) - 1;
  std::vector<double> dnorm(nnode, 0.0);  // ||A_kk||_F
  for (int i = 0; i < A.rows; ++i)
    for (int k = A.ptr[i]; k < A.ptr[i + 1]; ++k)
      if (node_of[A.col[k]] == node_of[i]) dnorm[node_of[i]] += A.val[k] * A.val[k];
  for (double& d : dnorm) d = std::sqrt(d);
  const double theta2 = strength * strength;
  Adjacency strong;
  std::vector<double> acc(nnode, 0.0);  // ||A_km||_F² of the neighbours m touched
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
      if (acc[m] > theta2 * dnorm[k] * dnorm[m]) strong.index.push_back(m);
    strong.close_row();
  }
  return strong;
}

/// Greedy aggregation of the nodes over their strong neighbours, in three phases: a node whose
/// whole neighbourhood is free seeds an aggregate of it; a node left over joins a neighbouring
/// aggregate of phase 1; what is still left forms aggregates with its free neighbours.
/// Returns the aggregate of each node (-2 for a node without rows); `count` gets their number.
std::vector<int> aggregate_nodes(const Adjacency& strong, const std::vector<int>& node_ptr, int& count) {
  const int nnode = strong.rows();
  std::vector<int> agg(nnode, -1);
  int naggs = 0;
  for (int k = 0; k < nnode; ++k)
    if (node_ptr[k] == node_ptr[k + 1]) agg[k] = -2;  // no rows
  for (int k = 0; k < nnode; ++k) {                   // 1: seeds with their whole neighbourhood
    if (agg[k] != -1 || strong.size(k) == 0) continue;
    bool free = true;
    for (const int* e = strong.begin(k); e != strong.end(k) && free; ++e) free = agg[*e] == -1;
    if (!free) continue;
    agg[k] = naggs;
    for (int m : strong.row(k)) agg[m] = naggs;
    ++naggs;
  }
  const std::vector<int> first = agg;
  for (int k = 0; k < nnode; ++k) {  // 2: join a neighbouring aggregate of phase 1
    if (agg[k] != -1) continue;
    for (int m : strong.row(k))
      if (first[m] >= 0) {
        agg[k] = first[m];
        break;
      }
  }
  for (int k = 0; k < nnode; ++k) {  // 3: the rest with its free neighbours
    if (agg[k] != -1) continue;
    agg[k] = naggs;
    for (int m : strong.row(k))
      if (agg[m] == -1) agg[m] = naggs;
    ++naggs;
  }
  count = naggs;
  return agg;
}

/// Orthonormalises the k near-null modes (k <= kMaxModes) restricted to the m rows `rows` of
/// one aggregate (modified Gram-Schmidt, twice for stability): B = Q R with Q's columns
/// appended to `Q` (m values each) and R (kept by k, row-major) appended to `R`. Modes that
/// depend on the others on this aggregate (a lone node cannot tell rotations from
/// translations) drop out. Returns kept, the number of columns of Q.
int orthonormal_modes(const int* rows, int m, int k, const std::vector<double>& modes, std::vector<double>& Q,
                      std::vector<double>& R) {
  Q.clear();
  double Rm[kMaxModes][kMaxModes] = {};
  std::vector<double> v(m);
  int kept = 0;
  for (int j = 0; j < k; ++j) {
    double norm0 = 0;
    for (int i = 0; i < m; ++i) v[i] = modes[k * rows[i] + j], norm0 += v[i] * v[i];
    norm0 = std::sqrt(norm0);
    double coef[kMaxModes] = {};
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
  for (int q = 0; q < kept; ++q) R.insert(R.end(), Rm[q], Rm[q] + k);
  return kept;
}

/// The tentative prolongator Pt (rows by #coarse dofs): on each aggregate, the orthonormalised
/// near-null modes (k of them, orthonormal_modes), one coarse dof per kept mode. `agg_rows`: the
/// rows of each aggregate. Sets coarse_ptr (the coarse dofs of each aggregate, offsets) and
/// coarse_modes (#coarse dofs by k: the modes on the coarse level, R of each aggregate).
CsrMatrix tentative_prolongator(const Adjacency& agg_rows, int rows, int k, const std::vector<double>& modes,
                                std::vector<int>& coarse_ptr, std::vector<double>& coarse_modes) {
  coarse_ptr.assign(1, 0);
  coarse_modes.clear();
  std::vector<int> pt_col(static_cast<size_t>(rows) * k, -1);  // up to k entries a row, row-major
  std::vector<double> pt_val(static_cast<size_t>(rows) * k, 0.0);
  std::vector<int> pt_count(rows, 0);
  std::vector<double> Q;
  for (int a = 0; a < agg_rows.rows(); ++a) {
    const int m = agg_rows.size(a);
    const int* arows = agg_rows.begin(a);
    const int kept = orthonormal_modes(arows, m, k, modes, Q, coarse_modes);
    const int c0 = coarse_ptr.back();
    for (int q = 0; q < kept; ++q)
      for (int i = 0; i < m; ++i) {
        const int r = arows[i];
        pt_col[static_cast<size_t>(k) * r + pt_count[r]] = c0 + q;
        pt_val[static_cast<size_t>(k) * r + pt_count[r]] = Q[q * m + i];
        ++pt_count[r];
      }
    coarse_ptr.push_back(c0 + kept);
  }
  CsrMatrix Pt;
  Pt.rows = rows;
  Pt.cols = coarse_ptr.back();
  Pt.ptr.assign(rows + 1, 0);
  for (int i = 0; i < rows; ++i) {
    for (int e = 0; e < pt_count[i]; ++e)
      Pt.col.push_back(pt_col[static_cast<size_t>(k) * i + e]),
          Pt.val.push_back(pt_val[static_cast<size_t>(k) * i + e]);
    Pt.ptr[i + 1] = static_cast<int>(Pt.col.size());
  }
  return Pt;
}

/// The smoothed prolongator P = (I − ω D⁻¹ A) Pt with ω = 4 / (3 λmax), λmax ≈ 1.1 `lambda`
/// (an estimate of λmax(D⁻¹A)): damps the high-energy part of the tentative prolongator.
/// inv_diag: D⁻¹ (A.rows).
CsrMatrix smoothed_prolongator(const CsrMatrix& A, const CsrMatrix& Pt, const std::vector<double>& inv_diag,
                               double lambda, int threads) {
  CsrMatrix AP = multiply(A, Pt, threads);
  const double omega = 4.0 / (3.0 * 1.1 * lambda);
  for (int i = 0; i < A.rows; ++i) {
    for (int k = AP.ptr[i]; k < AP.ptr[i + 1]; ++k) AP.val[k] *= -omega * inv_diag[i];
    for (int kt = Pt.ptr[i]; kt < Pt.ptr[i + 1]; ++kt)
      for (int k = AP.ptr[i]; k < AP.ptr[i + 1]; ++k)
        if (AP.col[k] == Pt.col[kt]) {
          AP.val[k] += Pt.val[kt];
          break;
        }
  }
  return AP;
}

/// The rows of A P from A's row blocks b0 .. b1 − 1: from A's 3×3 node blocks where the level
/// has them and P's row blocks are A's (the same values as from A's rows, in less time).
CsrMatrix product_slice(const Level& L, long b0, long b1, int threads) {
  if (L.p_by_blocks)
    return multiply_rows(L.nb, L.Abd, *L.A, L.P, b0, b1, threads);
  return multiply_rows(*L.A, L.P, b0, b1, threads);
}

/// The values of C = R (A P) recomputed for new values of A on C's pattern (the product the setup
/// made: multiply(R, multiply(A, P))): A P formed a slice of A's row blocks at a time and its
/// terms added to C as they come (add_product_rows), so that about 1/kSlices of A P is held —
/// A P is the hierarchy's largest matrix (1.5 times A's entries on the rocker), and keeping it
/// whole between refreshes was 0.5 GB per million tets. The same additions in the same order as
/// the product of the whole A P: the same values to the bit.
void galerkin_values(const Level& L, CsrMatrix& C, int threads) {
  constexpr long kSlices = 8;
  const CsrMatrix &A = *L.A, &R = L.R;
  std::fill(C.val.begin(), C.val.end(), 0.0);
  std::vector<int> cursor(row_blocks(R));
  for (size_t b = 0; b < cursor.size(); ++b) cursor[b] = R.ptr[R.blocks.empty() ? b : R.blocks[b]];
  const long blocks = row_blocks(A);
  for (long s = 0; s < kSlices; ++s) {
    const long b0 = blocks * s / kSlices, b1 = blocks * (s + 1) / kSlices;
    if (b0 == b1) continue;
    const CsrMatrix slice = product_slice(L, b0, b1, threads);
    add_product_rows(R, slice, A.blocks.empty() ? static_cast<int>(b0) : A.blocks[b0], cursor, C, threads);
  }
}

}  // namespace

struct SmoothedAggregationAmg::Impl {
  AmgParams params;
  int threads = 1;
  int modes_count = 6;       // near-null modes per row: 6 rigid-body modes, 1 for a scalar problem
  std::deque<Level> levels;  // a deque: levels point at their own matrices
  Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> coarse;
  SpMat coarse_lower;             // the lower triangle of the coarsest matrix, as factorised
  std::vector<long> coarse_from;  // the entry of the coarsest CsrMatrix behind each value of coarse_lower
  mutable Eigen::VectorXd coarse_b, coarse_x;

  /// Power iteration for λmax(D⁻¹A): `steps` steps from L.eigvec if it is set (a refresh:
  /// the matrix changed a little), else 15 from a fixed start.
  void estimate_lambda(Level& L, int steps = 15) const;
  void inverse_diagonal(Level& L) const;
  /// Cholesky of the coarsest matrix; `numeric_only`: its pattern is the one factorised last.
  void factor_coarsest(bool numeric_only = false);
  /// The tentative prolongator Pt from level matrix A (rows grouped into nodes by node_ptr,
  /// near-null modes `modes`, #rows by `modes_count`) to the next level, whose node offsets and
  /// modes it sets: strength graph, aggregation, modes orthonormalised per aggregate. Returns false if
  /// A does not coarsen any more (the next level would keep 80 % of the unknowns or more).
  bool coarsen(const CsrMatrix& A, const std::vector<int>& node_ptr, const std::vector<double>& modes,
               std::vector<int>& coarse_ptr, std::vector<double>& coarse_modes, CsrMatrix& Pt) const;
  static void to_single(const CsrMatrix& M, std::vector<float>& out) { out.assign(M.val.begin(), M.val.end()); }
  /// The copies of L.A's values the products read (Af, or Abf and Abd): after A got new values.
  static void copy_values(Level& L);
  /// y = A x on level L in single precision (the V-cycle's products).
  void single_product(const Level& L, const double* x, double* y) const;
  /// y = A x on level L with A's values (the same to the bit as L.A->multiply).
  void exact_product(const Level& L, const double* x, double* y) const;
  /// The single-precision copies of L.P and L.R the V-cycle reads: in blocks where they fit
  /// (fine_nodes: the offsets of L's node blocks, coarse_nodes: the aggregates' coarse dofs), else
  /// row-wise. P and R are kept for the hierarchy's life, so once per setup.
  static void copy_transfers(Level& L, const std::vector<int>& fine_nodes, const std::vector<int>& coarse_nodes);
  /// y = R r (restriction to the next level) and y = P x (prolongation from it), single precision.
  void restrict_to(const Level& L, const double* r, double* y) const;
  void prolong_from(const Level& L, const double* x, double* y) const;
  void smooth(const Level& L, const double* b, double* x, bool zero_start) const;
  void cycle(size_t l) const;
};

void SmoothedAggregationAmg::Impl::copy_values(Level& L) {
  if (L.nb.empty()) {
    to_single(*L.A, L.Af);
    return;
  }
  L.nb.fill(*L.A, L.Abd, L.Abf);
}

void SmoothedAggregationAmg::Impl::single_product(const Level& L, const double* x, double* y) const {
  if (L.nb.empty())
    sparse_product(*L.A, L.Af.data(), x, y, threads);
  else
    L.nb.multiply(L.Abf, x, y, L.xpad, threads);
}

void SmoothedAggregationAmg::Impl::exact_product(const Level& L, const double* x, double* y) const {
  if (L.nb.empty())
    L.A->multiply(x, y, threads);
  else
    L.nb.multiply(L.Abd, x, y, L.xpad, threads);
}

void SmoothedAggregationAmg::Impl::copy_transfers(Level& L, const std::vector<int>& fine_nodes,
                                                  const std::vector<int>& coarse_nodes) {
  L.Pf.clear(), L.Rf.clear(), L.Pbf.clear(), L.Rbf.clear();
  if (L.pb.build(L.P, coarse_nodes))
    L.pb.fill(L.P, L.Pbf);
  else
    to_single(L.P, L.Pf);
  if (L.rb.build(L.R, fine_nodes))
    L.rb.fill(L.R, L.Rbf);
  else
    to_single(L.R, L.Rf);
}

void SmoothedAggregationAmg::Impl::restrict_to(const Level& L, const double* r, double* y) const {
  if (L.rb.empty())
    sparse_product(L.R, L.Rf.data(), r, y, threads);
  else
    L.rb.multiply(L.Rbf, r, y, L.tpad, threads);
}

void SmoothedAggregationAmg::Impl::prolong_from(const Level& L, const double* x, double* y) const {
  if (L.pb.empty())
    sparse_product(L.P, L.Pf.data(), x, y, threads);
  else
    L.pb.multiply(L.Pbf, x, y, L.tpad, threads);
}

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
    exact_product(L, v.data(), w.data());
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

void SmoothedAggregationAmg::Impl::factor_coarsest(bool numeric_only) {
  // Sparse Cholesky of the coarsest matrix (its lower triangle). Its pattern and where each of
  // its values comes from are made once per setup; a refresh only copies the values over.
  const CsrMatrix& Ac = *levels.back().A;
  SpMat& S = coarse_lower;
  if (!numeric_only || static_cast<long>(coarse_from.size()) != S.nonZeros() || S.rows() != Ac.rows) {
    std::vector<Eigen::Triplet<double, int>> trip;
    trip.reserve(Ac.nonzeros() / 2 + Ac.rows);
    for (int i = 0; i < Ac.rows; ++i)
      for (int k = Ac.ptr[i]; k < Ac.ptr[i + 1]; ++k)
        if (Ac.col[k] >= i) trip.emplace_back(Ac.col[k], i, Ac.val[k]);  // lower triangle
    S.resize(Ac.rows, Ac.rows);
    S.setFromTriplets(trip.begin(), trip.end());
    // column i of S is row i of Ac from its diagonal on (Ac holds each entry once)
    coarse_from.assign(S.nonZeros(), 0);
    std::vector<long> at(Ac.rows, -1);
    for (int i = 0; i < Ac.rows; ++i) {
      for (int k = Ac.ptr[i]; k < Ac.ptr[i + 1]; ++k) at[Ac.col[k]] = k;
      for (int p = S.outerIndexPtr()[i]; p < S.outerIndexPtr()[i + 1]; ++p) coarse_from[p] = at[S.innerIndexPtr()[p]];
    }
  } else {
    double* v = S.valuePtr();
    for (size_t p = 0; p < coarse_from.size(); ++p) v[p] = Ac.val[coarse_from[p]];
  }
  // AMD only: the coarse matrix is small and dense-ish; CHOLMOD's default of trying several
  // orderings costs more than the fill it saves (measured on the rocker's 8.7 k coarse level).
  coarse.cholmod().nmethods = 1;
  coarse.cholmod().method[0].ordering = CHOLMOD_AMD;
  if (numeric_only)
    coarse.factorize(S);
  else
    coarse.compute(S);
  if (coarse.info() != Eigen::Success)
    throw Error(ErrorCode::NoSupport,
                "the coarse multigrid matrix is not positive definite: the supports "
                "do not hold the structure, or the mesh has degenerate elements");
}

void SmoothedAggregationAmg::Impl::inverse_diagonal(Level& L) const {
  // The diagonal's positions are found once per pattern: a refresh (SIMP's every iteration)
  // then reads n values instead of scanning every entry of A. A row holding its diagonal more
  // than once (kDiagonalScan) has it summed by a scan of the row, as a row without one reads 0.
  constexpr long kNoDiagonal = -1, kDiagonalScan = -2;
  const CsrMatrix& A = *L.A;
  if (static_cast<int>(L.diag_at.size()) != A.rows) {
    L.diag_at.assign(A.rows, kNoDiagonal);
    for (int i = 0; i < A.rows; ++i)
      for (int k = A.ptr[i]; k < A.ptr[i + 1]; ++k)
        if (A.col[k] == i) L.diag_at[i] = L.diag_at[i] == kNoDiagonal ? k : kDiagonalScan;
  }
  L.inv_diag.assign(A.rows, 0.0);
  for (int i = 0; i < A.rows; ++i) {
    double d = 0;
    if (L.diag_at[i] >= 0)
      d = A.val[L.diag_at[i]];
    else if (L.diag_at[i] == kDiagonalScan)
      for (int k = A.ptr[i]; k < A.ptr[i + 1]; ++k)
        if (A.col[k] == i) d += A.val[k];
    if (!(d > 0))
      throw Error(ErrorCode::NoSupport,
                  "the stiffness matrix has a zero or negative diagonal entry: "
                  "an unknown is not held by any element; check the mesh and supports");
    L.inv_diag[i] = 1 / d;
  }
}

bool SmoothedAggregationAmg::Impl::coarsen(const CsrMatrix& A, const std::vector<int>& node_ptr,
                                           const std::vector<double>& modes, std::vector<int>& coarse_ptr,
                                           std::vector<double>& coarse_modes, CsrMatrix& Pt) const {
  const std::vector<int> node_of = row_nodes(node_ptr, A.rows);
  const Adjacency strong = strength_graph(A, node_ptr, node_of, params.strength);
  int naggs = 0;
  const std::vector<int> agg = aggregate_nodes(strong, node_ptr, naggs);
  const Adjacency agg_rows = group_pairs(naggs, [&](auto emit) {
    for (int k = 0; k + 1 < static_cast<int>(node_ptr.size()); ++k)
      if (agg[k] >= 0)
        for (int i = node_ptr[k]; i < node_ptr[k + 1]; ++i) emit(agg[k], i);
  });
  Pt = tentative_prolongator(agg_rows, A.rows, modes_count, modes, coarse_ptr, coarse_modes);
  return Pt.cols > 0 && Pt.cols < A.rows * 0.8;
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
    single_product(L, x, q);
    for (int i = 0; i < n; ++i) r[i] = b[i] - q[i];
  }
  for (int i = 0; i < n; ++i) d[i] = dinv[i] * r[i] / theta, x[i] += d[i];
  for (int k = 1; k < params.smoother_degree; ++k) {
    single_product(L, d, q);  // r -= A d keeps r = b - A x
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
  single_product(L, L.x.data(), L.q.data());
  for (int i = 0; i < n; ++i) L.r[i] = L.b[i] - L.q[i];
  const Level& C = levels[l + 1];
  restrict_to(L, L.r.data(), C.b.data());
  cycle(l + 1);
  prolong_from(L, C.x.data(), L.q.data());
  for (int i = 0; i < n; ++i) L.x[i] += L.q[i];
  smooth(L, L.b.data(), L.x.data(), false);
}

SmoothedAggregationAmg::SmoothedAggregationAmg() : impl_(std::make_unique<Impl>()) {}
SmoothedAggregationAmg::~SmoothedAggregationAmg() = default;
SmoothedAggregationAmg::SmoothedAggregationAmg(SmoothedAggregationAmg&&) noexcept = default;
SmoothedAggregationAmg& SmoothedAggregationAmg::operator=(SmoothedAggregationAmg&&) noexcept = default;

void SmoothedAggregationAmg::setup(const CsrMatrix& A, const std::vector<int>& node_ptr,
                                   const std::vector<double>& near_null, const AmgParams& params) {
  Impl& m = *impl_;
  m.params = params;
  m.threads = thread_count(params.threads);
  m.modes_count = A.rows > 0 ? static_cast<int>(near_null.size() / A.rows) : 0;
  if (node_ptr.empty() || node_ptr.back() != A.rows || m.modes_count < 1 || m.modes_count > kMaxModes ||
      near_null.size() != static_cast<size_t>(m.modes_count) * A.rows)
    throw Error(ErrorCode::Internal, "AMG setup: node offsets or near-null modes do not match the matrix");
  if (!A.blocks_consistent())
    throw Error(ErrorCode::Internal, "AMG setup: the matrix's row blocks do not share their columns");
  m.levels.clear();
  std::vector<int> nodes = node_ptr, coarse_nodes;
  std::vector<double> modes = near_null, coarse_modes;
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
    if (!m.coarsen(Al, nodes, modes, coarse_nodes, coarse_modes, Pt)) break;
    L.nb.build(Al);  // a level with a coarser one below: its products are the V-cycle's
    Impl::copy_values(L);
    m.estimate_lambda(L);
    L.P = smoothed_prolongator(Al, Pt, L.inv_diag, L.lambda, m.threads);
    L.p_by_blocks = !L.nb.empty() && L.P.blocks == L.nb.first && L.P.blocks_consistent();
    L.R = transpose(L.P);
    L.R.blocks = coarse_nodes;  // an aggregate's coarse dofs share their fine rows
    // A P only for as long as the product needs it (a refresh forms it again slice by slice),
    // from A's node blocks where the level has them, as a refresh does: the same values as
    // multiply(Al, L.P) to the bit, in less time (the one-off solve's setup)
    CsrMatrix coarse = multiply(L.R, product_slice(L, 0, row_blocks(Al), m.threads), m.threads);
    Impl::copy_transfers(L, nodes, coarse_nodes);
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
    Impl::copy_values(m.levels[0]);
    m.estimate_lambda(m.levels[0], 5);
  } else
    m.factor_coarsest();
}

void SmoothedAggregationAmg::refresh_galerkin() {
  Impl& m = *impl_;
  if (m.levels.empty()) throw Error(ErrorCode::Internal, "AMG: refresh before setup");
  for (size_t l = 0; l + 1 < m.levels.size(); ++l) {
    Level& L = m.levels[l];
    m.inverse_diagonal(L);
    Impl::copy_values(L);
    m.estimate_lambda(L, 5);
    // the setup's pattern: the next level's values rewritten in place (its A points at its `own`)
    galerkin_values(L, m.levels[l + 1].own, m.threads);
  }
  m.inverse_diagonal(m.levels.back());
  m.factor_coarsest(true);
}

void SmoothedAggregationAmg::apply(const double* r, double* z) const {
  const Impl& m = *impl_;
  Level& L = const_cast<Level&>(m.levels[0]);
  std::copy(r, r + L.A->rows, L.b.begin());
  m.cycle(0);
  std::copy(L.x.begin(), L.x.end(), z);
}

void SmoothedAggregationAmg::multiply_finest(const double* x, double* y) const {
  const Impl& m = *impl_;
  if (m.levels.empty()) throw Error(ErrorCode::Internal, "AMG: product before setup");
  m.exact_product(m.levels[0], x, y);
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

}  // namespace topopt::fem
