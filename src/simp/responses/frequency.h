// The first eigenfrequency of SIMP's design as a response: the stiffness of the SIMP law and a
// mass that follows the density, with Pedersen's low-density correction against spurious
// local modes of near-void regions, and the eigenvalue's gradient.
#pragma once
#include <cmath>

#include "fem/modal.h"
#include "simp/optimizer.h"

namespace topopt::simp {

/// Mass interpolation of a design tet: m(ρ) = ρ above 0.1 and 1e5 ρ⁶ below (continuous at
/// 0.1; Pedersen 2000): near-void tets then weigh much less than their stiffness ρ^p carries,
/// so they have no local modes below the structure's.
struct MassLaw {
  double value(double rho) const { return rho > 0.1 ? rho : 1e5 * std::pow(rho, 6); }
  double derivative(double rho) const { return rho > 0.1 ? 1.0 : 6e5 * std::pow(rho, 5); }
};

/// The first eigenvalue λ1 = ω1² of the design of the last problem.compliance() call (the
/// non-design tets with their full mass), with the lowest two modes found by subspace iteration
/// through the problem's solver. density: the material's mass density (t/mm³);
/// params: eigen_tolerance; warm: the previous call's subspace, replaced by this call's.
/// grad (optional): #D, dλ1/dx = φᵀ(∂K/∂ρ̄ − λ1 ∂M/∂ρ̄)φ chained to x (φ M-normalised).
/// Returns the modal result (eigenvalues and frequencies of two modes, first_repeated).
fem::ModalResult first_eigenvalue(ComplianceProblem& problem, double density, const ResponseParams& params,
                                  Eigen::MatrixXd& warm, VecXd* grad = nullptr);

}  // namespace topopt::simp
