// The solver policy of the FE analysis behind one interface: Elasticity assembles the
// stiffness on the free dofs and hands it to a LinearSolver, which decides what to build
// (a Cholesky factor, a multigrid hierarchy), what to reuse from SIMP's previous iteration and
// how to solve. Two implementations: direct (CHOLMOD, direct_solver.cpp) and multigrid CG
// (multigrid_solver.cpp). A distributed one (PETSc over MPI, issue 21) sits behind the same
// calls: the pattern is fixed at construction, values change between update()s (a Mat whose
// values are reset), the dofs come in blocks of a node's components (MatSetBlockSize) and
// near_null_space gives the rigid-body modes (MatSetNearNullSpace for GAMG).
//
// Choice (measured in bench/fem and bench/simp, see BENCHMARKS.md): Auto takes the direct
// solver up to kDirectDofLimit unknowns (exact, and cheap to factorise) and multigrid CG above:
// on the rocker (83 k unknowns) the multigrid solve takes 1.6 s against 2.4-2.9 s for analysis
// + factorisation, and its memory grows linearly where the factor's grows much faster (5.2 GB
// at 560 k unknowns).
#pragma once
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "common/progress.h"
#include "common/types.h"
#include "fem/amg.h"

namespace topopt::fem {

enum class SolverKind { Auto, Direct, Iterative };

struct SolverParams {
  SolverKind kind = SolverKind::Auto;  ///< Auto: by problem size (choose_solver)
  double tolerance = 1e-8;             ///< iterative: relative residual
  int max_iterations = 5000;           ///< iterative
  int threads = 0;                     ///< assembly threads; 0 = hardware concurrency
  /// Reuse between SIMP iterations. Direct: first try conjugate gradients preconditioned by the
  /// previous Cholesky factor (SIMP's stiffness changes little between iterations) and
  /// refactorise only when that would take more than `recycle_iterations` iterations; the
  /// result then meets `recycle_tolerance` (relative residual) instead of machine precision.
  /// Iterative: keep the multigrid hierarchy (refresh its finest level, its coarse matrices
  /// when the iterations say so: HierarchyReuse in solver_policy.h).
  bool recycle_factor = true;
  int recycle_iterations = 20;
  double recycle_tolerance = 1e-9;
  /// Iterative: the multigrid's options (its `threads` is replaced by `threads` above).
  AmgParams multigrid;
};

/// Above this many free dofs, Auto takes multigrid CG instead of the direct solver: the
/// multigrid's own coarse-level size (AmgParams::coarse_dofs). At or below it the "multigrid"
/// is a single level, a Cholesky factorisation every SIMP iteration without the direct
/// solver's recycling, so the direct solver wins; above it the two-level hierarchy wins.
/// Measured inside SIMP (bench/simp/solvers.py, cantilever, 20 iterations, single core),
/// CPU direct / multigrid: 0.60 at 16.5 k unknowns, 1.40 at 20.9 k, 1.45 at 28.9 k, 1.72 at
/// 59 k, 1.84 at 102 k (the limit was 40 000 before: the 63 k-tet cantilever took the slower).
constexpr int kDirectDofLimit = AmgParams{}.coarse_dofs;

/// The solver Auto stands for with `free_dofs` unknowns (Direct or Iterative; other kinds are
/// returned as they are).
SolverKind choose_solver(SolverKind kind, int free_dofs);

/// Lower triangle of a symmetric sparse matrix, compressed columns (what CHOLMOD factorises).
using SparseLower = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

/// What a solver sees of the elasticity problem: the stiffness restricted to the free dofs and
/// where those dofs sit. The pointees are owned by the caller and must outlive the solver.
struct FreeSystem {
  /// nf by nf, symmetric, in full compressed rows with columns increasing in each row and the
  /// node blocks (CsrMatrix::blocks = node_blocks(free_dofs): a node's rows share their
  /// columns). The one copy of the stiffness: Elasticity assembles into it and the multigrid
  /// reads it as it is (the direct solver keeps the lower triangle CHOLMOD needs). Its pattern
  /// is fixed for the solver's life; its values change before each LinearSolver::update.
  const CsrMatrix* K = nullptr;
  /// nf: the mesh dof (3 * node + component) of each unknown, increasing (so a node's free
  /// components are consecutive unknowns).
  const std::vector<int>* free_dofs = nullptr;
  const MatX3d* nodes = nullptr;  ///< #V by 3: node coordinates (for the rigid-body modes)
  int threads = 1;                ///< threads for the solver's own loops
};

/// What a solver did so far: for tests, logs and benchmarks.
struct SolverStats {
  int preparations = 0;  ///< Cholesky factorisations, or multigrid setups
  int reuses = 0;        ///< solves through a factor or hierarchy built for an earlier matrix
  int refreshes = 0;     ///< multigrid: Galerkin refreshes of a kept hierarchy's coarse matrices
  int iterations = 0;    ///< CG iterations of the last solve (worst load case); 0 if direct
};

/// Solves K X = B on the free dofs, over the life of one pattern (SIMP's iterations).
class LinearSolver {
 public:
  virtual ~LinearSolver() = default;
  /// K has new values: build now what must be built (a factor, a hierarchy) and mark for reuse
  /// what may be reused. Throws Error(NoSupport) if K is found not positive definite.
  virtual void update(const Progress& progress) = 0;
  /// Solves K X = B. B: nf by #cases. X: on entry the previous solution (the warm start; any
  /// shape, ignored where it does not fit), on exit the solution, nf by #cases. Throws
  /// Error(NoSupport) if K is not positive definite, Error(Internal) if CG does not converge
  /// (its message names the other solver), Error(Cancelled) when `progress` asks to stop.
  virtual void solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X, const Progress& progress) = 0;
  virtual SolverStats stats() const = 0;
  /// CG's relative residual (SolverParams::tolerance) from the next solve on. The direct solver
  /// ignores it (its solves are exact, its recycled ones meet recycle_tolerance).
  virtual void set_tolerance(double tolerance) { (void)tolerance; }
};

/// The solver for `params.kind` (Auto resolved by choose_solver on K's size), for `system`.
std::unique_ptr<LinearSolver> make_linear_solver(const FreeSystem& system, const SolverParams& params);
/// CHOLMOD supernodal Cholesky (METIS ordering, symbolic analysis once), with factor reuse.
std::unique_ptr<LinearSolver> make_direct_solver(const FreeSystem& system, const SolverParams& params);
/// CG preconditioned by smoothed-aggregation multigrid (fem/amg.h), with hierarchy reuse.
std::unique_ptr<LinearSolver> make_multigrid_solver(const FreeSystem& system, const SolverParams& params);

/// The first unknown of each node with free dofs, then nf (#nodes with free dofs + 1
/// offsets): the dof blocks of `free_dofs` (increasing mesh dofs 3 * node + component).
std::vector<int> node_blocks(const std::vector<int>& free_dofs);

/// The near-null space of the stiffness: the six rigid-body motions (rigid_modes_at, rotations
/// about the centre of the nodes' bounding box, lengths divided by its diagonal) sampled at the
/// free dofs. nodes: #V by 3. Returns nf by 6, row-major.
std::vector<double> near_null_space(const MatX3d& nodes, const std::vector<int>& free_dofs);

/// The six rigid-body motions' components along axis c (0, 1, 2) at point x (relative to the
/// centre of rotation): row[0..2] translations, row[3..5] rotations about x, y, z (e_a × x).
void rigid_modes_at(const Eigen::Vector3d& x, int c, double row[6]);

}  // namespace topopt::fem
