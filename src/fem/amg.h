// Smoothed-aggregation algebraic multigrid (Vaněk, Mandel, Brezina 1996) for linear
// elasticity, used as the preconditioner of conjugate gradients (fem/pcg.h): the "strong
// preconditioner" of the iterative solver, and SIMP's solver of choice where a Cholesky factor
// is too slow or too big (see fem/linear_solver.h for how the default is chosen). The same
// hierarchy serves scalar problems (one row per node, the constant as near-null mode): the
// Helmholtz density filter on fine meshes (simp/helmholtz_filter.h).
//
// Per level: a strength graph on nodes (blocks of rows that belong together: a mesh node's
// free dofs on the finest level, an aggregate's coarse dofs below), greedy aggregation, a
// tentative prolongator that carries the six rigid-body modes exactly on every aggregate
// (orthonormalised per aggregate), one damped-Jacobi smoothing step of that prolongator, and
// the Galerkin product P^T A P; Chebyshev smoothing (Jacobi-scaled, fully parallel); CHOLMOD on
// the coarsest level. The V-cycle is symmetric positive definite, so it is a valid CG
// preconditioner.
#pragma once
#include <memory>
#include <vector>

#include "common/progress.h"
#include "common/types.h"
#include "fem/csr_matrix.h"
#include "fem/pcg.h"

namespace topopt::fem {

/// The most near-null modes a hierarchy carries (elasticity's six rigid-body motions).
constexpr int kMaxModes = 6;

struct AmgParams {
  /// Strength of connection θ between nodes i, j: ||A_ij||_F² > θ² ||A_ii||_F ||A_jj||_F.
  /// Small values aggregate over whole neighbourhoods (the usual choice for elasticity) while
  /// still separating SIMP's void from solid material (their coupling is ~1e-4 of either).
  double strength = 0.02;
  /// Solve directly (Cholesky) at or below this many unknowns. A large coarsest level pays:
  /// on the rocker (83 k unknowns) two levels with an 8.7 k direct coarse solve take 17 CG
  /// iterations where three levels take 25, for about the same setup time.
  int coarse_dofs = 20000;
  int max_levels = 12;
  int smoother_degree = 2;      ///< Chebyshev polynomial degree (matrix products per sweep)
  double smoother_lower = 0.1;  ///< Chebyshev interval [lower·λmax, 1.1·λmax] of D⁻¹A
  int threads = 0;              ///< 0 = hardware concurrency
};

/// The multigrid hierarchy of one matrix, a preconditioner for pcg(). setup() may be called
/// again for new values (SIMP's next stiffness); the matrix passed must stay alive while
/// apply() is used.
class SmoothedAggregationAmg final : public Preconditioner {
 public:
  SmoothedAggregationAmg();
  ~SmoothedAggregationAmg();
  SmoothedAggregationAmg(SmoothedAggregationAmg&&) noexcept;
  SmoothedAggregationAmg& operator=(SmoothedAggregationAmg&&) noexcept;

  /// Builds the hierarchy.
  /// A: n by n, symmetric positive definite, full storage.
  /// node_ptr: #nodes+1 offsets; the rows of node k are node_ptr[k] .. node_ptr[k+1]-1
  ///   (a mesh node's free dofs, so rows must be numbered node by node).
  /// near_null: n by k, row-major, 1 <= k <= kMaxModes: the motions A leaves (nearly)
  ///   unstrained, sampled at each row — for elasticity the six rigid-body motions (three
  ///   translations, three rotations about a central point, lengths scaled to about 1); for a
  ///   scalar diffusion-type problem (the Helmholtz filter) the constant, k = 1.
  /// Throws Error(NoSupport) if the coarsest matrix is not positive definite.
  void setup(const CsrMatrix& A, const std::vector<int>& node_ptr, const std::vector<double>& near_null,
             const AmgParams& params = {});

  /// The finest matrix (the one given to setup, same pattern) got new values: refreshes what
  /// the finest smoother reads from it (diagonal, eigenvalue bound) and keeps the coarse
  /// levels. The V-cycle stays symmetric positive definite, so it stays a valid (if weaker)
  /// preconditioner; SIMP uses this between full setups while the iteration count stays low.
  void refresh_finest();

  /// The finest matrix got new values (same pattern): recomputes every coarser matrix as the
  /// Galerkin product R A P with the kept prolongators, level by level, with each level's
  /// diagonal, eigenvalue bound and single-precision copy, and refactors the coarsest (numeric
  /// only: its pattern is the setup's). Skips the aggregation and the prolongator smoothing of
  /// a setup; the coarse correction stays exact for the new matrix on the old aggregates, so
  /// the V-cycle stays close to a fresh setup's while SIMP's stiffness moves (the finest-only
  /// refresh lets the coarse levels keep the old densities).
  void refresh_galerkin();

  /// z = M⁻¹ r: one V-cycle from zero. r, z: n.
  void apply(const double* r, double* z) const;
  /// The same on vectors (the Preconditioner interface).
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override { apply(r.data(), z.data()); }

  /// y = A x for the finest matrix (the one given to setup) with its values as of the last
  /// setup or refresh: from the hierarchy's 3×3 node-block copy of it where there is one
  /// (fem/node_block_matrix.h; the same values to the bit as A.multiply, in less time), else
  /// A.multiply. x, y: n.
  void multiply_finest(const double* x, double* y) const;

  int levels() const;
  /// Operator complexity: Σ nnz(A_l) / nnz(A_0).
  double complexity() const;
  /// Unknowns per level, finest first.
  std::vector<int> level_sizes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace topopt::fem
