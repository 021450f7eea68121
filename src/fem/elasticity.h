// Linear elasticity on 4-node tetrahedra, built for SIMP: the sparse pattern is made once,
// the values are refilled cheaply for every new set of element factors, and several load
// cases are solved against one factorisation / preconditioner.
//
// INTERFACE CONTRACT (SIMP, CLI and bindings rely on it; implementation in elasticity.cpp).
#pragma once
#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "common/progress.h"
#include "common/types.h"
#include "fem/linear_solver.h"

namespace topopt::fem {

/// Isotropic linear elastic material. Units: N, mm, MPa (N/mm²), tonne/mm³.
struct Material {
  double young = 210000.0;   ///< Young's modulus E, MPa (steel)
  double poisson = 0.3;      ///< Poisson's ratio ν, in (-1, 0.5)
  double density = 7.85e-9;  ///< mass density, t/mm³ (for gravity loads)
};

/// Dirichlet data: fixed degrees of freedom (3*node + component) with prescribed values.
struct Supports {
  std::vector<int> dofs;       ///< sorted, unique
  std::vector<double> values;  ///< same length (0 for a fixed support)
};

/// The elasticity problem on one mesh. Element stiffness K_e = scale_e * K0_e.
class Elasticity {
 public:
  /// mesh: #V nodes, #T tets (positive orientation). Throws Error(NoSupport) later, at solve,
  /// if the supports leave rigid-body motion free.
  Elasticity(const TetMesh& mesh, const Material& material, const Supports& supports, const SolverParams& params = {});
  ~Elasticity();
  Elasticity(Elasticity&&) noexcept;
  Elasticity& operator=(Elasticity&&) noexcept;

  /// Per-element stiffness factors (#T, > 0), e.g. SIMP's E(ρ)/E0. Default all 1.
  void set_scale(const VecXd& scale);

  /// Solves K U = F for each column of `loads` ((3*#V) by #cases, node-major: 3*i+c) through
  /// the LinearSolver that `params.kind` names (fem/linear_solver.h), assembling K first if
  /// set_scale changed it. Returns U of the same shape (supports imposed). Warm-starts from
  /// the previous solution. Throws Error(NoSupport) for a singular system.
  Eigen::MatrixXd solve(const Eigen::MatrixXd& loads, const Progress& progress = {});

  /// The iterative solver's relative residual from the next solve on (LinearSolver::set_tolerance;
  /// the direct solver ignores it).
  void set_solver_tolerance(double tolerance);

  /// #T: u_e^T K0_e u_e for a displacement field u (3*#V), the unscaled element energy
  /// (twice the strain energy); SIMP's sensitivity is -dscale/dρ * this.
  VecXd element_energy(const VecXd& u) const;

  /// #T: von Mises stress (MPa) of each element for displacement u, with scale applied
  /// to the stress as SIMP does (σ_e = scale_e · D ε_e).
  VecXd von_mises(const VecXd& u) const;

  /// #T: von Mises stress (MPa) of each element's solid material for displacement u (3*#V),
  /// σ0_e = D ε_e without the scale: the stress SIMP's relaxed stress scales.
  VecXd solid_von_mises(const VecXd& u) const;

  /// 3*#V: the gradient w.r.t. u of Σ_e w_e vm0_e(u), vm0 as solid_von_mises; w: #T weights.
  /// An element with zero stress contributes nothing (vm0 is not differentiable there).
  /// The adjoint load of an aggregated stress.
  VecXd solid_von_mises_gradient(const VecXd& u, const VecXd& w) const;

  int num_dofs() const;
  const TetMesh& mesh() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace topopt::fem
