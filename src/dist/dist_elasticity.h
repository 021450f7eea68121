// Linear elasticity on the distributed mesh, on PETSc: a MatMPIAIJ (block size 3) whose
// pattern is preallocated once from the ranks' tets (MatPreallocator) and whose values are
// refilled for every new set of element factors, solved by CG with algebraic multigrid (GAMG
// with the six rigid-body modes as near-null space, or hypre's BoomerAMG with nodal coarsening:
// DistSolverParams::amg; PETSC_OPTIONS may override either). Held dofs (supports, unused nodes) are left out of the
// element matrices and get a diagonal entry alone, so the matrix stays symmetric positive definite.
#pragma once
#include <memory>
#include <string>

#include "dist/dist_mesh.h"
#include "fem/elasticity.h"

namespace topopt::dist {

/// The algebraic multigrid preconditioning CG (bench/scale/amg.py measured them, BENCHMARKS.md).
enum class Amg : int {
  GAMG,       ///< PETSc's smoothed aggregation, the six rigid-body modes as near-null space
  BoomerAMG,  ///< hypre's classical AMG, nodal coarsening on the 3 dofs of a node
};

struct DistSolverParams {
  double tolerance = 1e-8;    ///< relative residual ‖b − K u‖ / ‖b‖
  int max_iterations = 5000;  ///< CG iterations per solve
  Amg amg = Amg::GAMG;        ///< the preconditioner (PETSC_OPTIONS may still override it)
  /// Keep the multigrid built for an earlier matrix while it still pays, by the serial
  /// multigrid's rule (fem::HierarchyReuse: a new set-up where the serial solver would refresh
  /// its coarse matrices — once the iterations beyond the first solve's would soon outweigh it —
  /// and a solve that runs a refresh's cost past that count finished on a new set-up). SIMP's
  /// SolverParams::recycle_factor; false: a new set-up for every new matrix.
  bool reuse = true;
};

/// The Amg named `name` ("gamg" or "boomeramg"); throws Error(InvalidParameter) naming the
/// choices for anything else.
Amg amg_named(const std::string& name);

class DistElasticity {
 public:
  /// mesh: this rank's part (distribute_mesh); it must outlive the object. Collective.
  DistElasticity(const MpiSession& session, const DistMesh& mesh, const fem::Material& material,
                 const DistSolverParams& params = {});
  ~DistElasticity();
  DistElasticity(const DistElasticity&) = delete;
  DistElasticity& operator=(const DistElasticity&) = delete;

  /// Element stiffness factors of this rank's tets (#local tets, > 0); default all 1.
  void set_scale(const VecXd& scale);

  /// Solves K U = F for each column of `loads` (3 × owned nodes by #cases, as DistMesh::loads;
  /// values on held dofs are ignored). Returns the displacements of every local node, owned and
  /// ghost (3 × #local nodes by #cases), held dofs 0. Warm-starts from the previous solution.
  /// Collective. Throws Error(NoSupport) when CG fails (the supports do not hold the part).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& loads);

  /// #local tets: u_eᵀ K0_e u_e for the local displacements u (3 × #local nodes), the unscaled
  /// element energy that SIMP's sensitivities use.
  VecXd element_energy(const VecXd& u) const;

  /// #local tets: the von Mises stress (MPa) of each tet under u, with its stiffness factor
  /// applied (as fem::Elasticity::von_mises).
  VecXd von_mises(const VecXd& u) const;

  /// CG iterations of the last solve (the largest over the load cases).
  int last_iterations() const;

  /// CG's relative residual from the next solve on (SIMP's early loose tolerance,
  /// simp::solver_tolerance). Collective (every rank must pass the same value).
  void set_tolerance(double tolerance);

  /// Preconditioner set-ups so far (the rest of the solves ran on a kept one).
  int setups() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace topopt::dist
