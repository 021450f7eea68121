// Free vibration: the consistent mass of linear tets and the lowest eigenpairs of K φ = λ M φ
// by subspace iteration, each step a solve with the elasticity problem's own LinearSolver
// (CHOLMOD's factor or the multigrid CG, whichever the SolverParams choose), so the
// eigensolver reuses what the static analysis builds.
#pragma once
#include <string>

#include "common/progress.h"
#include "common/types.h"
#include "fem/elasticity.h"

namespace topopt::fem {

/// y = M x for the consistent mass of linear tets: M_e = m_e ρ vol_e / 20 (1 + δ_ab) I3 between
/// nodes a, b of tet e. mesh: #V nodes, #T tets; density: mass density ρ (t/mm³); factor: #T
/// mass factors m_e (SIMP's mass interpolation; empty: all 1); x: 3*#V. Returns 3*#V.
VecXd apply_mass(const TetMesh& mesh, double density, const VecXd& factor, const VecXd& x);

struct ModalParams {
  int modes = 1;             ///< eigenpairs wanted, >= 1
  int block = 0;             ///< subspace size; <= modes: max(2 modes, modes + 6)
  int max_iterations = 200;  ///< subspace iterations
  double tolerance = 1e-10;  ///< relative change of every wanted eigenvalue between iterations
  /// Two eigenvalues closer than this (relative) are reported as repeated.
  double repeated = 1e-3;
};

struct ModalResult {
  VecXd eigenvalues;       ///< #modes, ascending, λ = ω² (1/s² with N, mm, t)
  VecXd frequencies;       ///< #modes, Hz: √λ / 2π
  Eigen::MatrixXd shapes;  ///< (3*#V) by #modes, M-orthonormal (φᵀ M φ = I), zero at the supports
  Eigen::MatrixXd block;   ///< (3*#V) by the subspace size: the whole last subspace (a warm start)
  int iterations = 0;
  bool converged = false;
  /// True when the first eigenvalue is repeated (λ2 within `repeated` of λ1): its derivative
  /// then does not exist and an optimiser sees a kink.
  bool first_repeated = false;
};

/// The lowest eigenpairs of K φ = λ M φ for the stiffness `fe` holds (after its set_scale) and
/// the mass of `mesh` with factors `mass_factor` (#T, empty: all 1). The supports of `fe` must
/// prescribe zero displacements. Throws Error(NoSupport) as Elasticity::solve does for a
/// structure its supports do not hold, and Error(InvalidParameter) for modes < 1. start:
/// (3*#V) by the subspace size, the subspace to start from (a previous result's block, e.g. the
/// last SIMP iteration's); empty or of another shape: a random one.
ModalResult lowest_modes(Elasticity& fe, double density, const VecXd& mass_factor, const ModalParams& params = {},
                         const Progress& progress = {}, const Eigen::MatrixXd& start = {});

}  // namespace topopt::fem
