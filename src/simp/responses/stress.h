// The von Mises stress of SIMP's design as a response: qp-relaxed element stresses aggregated
// by a p-norm, its adjoint gradient, and the largest stress of the crisp design.
#pragma once
#include "simp/optimizer.h"

namespace topopt::simp {

/// Per load case k, the p-norm (Σ_e s_e^P)^(1/P) of the relaxed element stresses over all
/// tets, s_e = η(ρ̄_e) vm0_e / stress_limit with η(ρ) = ρ^q on design tets (1 on non-design
/// ones) and vm0 the solid material's von Mises stress, for the design of the last
/// problem.compliance() call. Returns #cases values (relative to the limit).
/// grad (optional): #D by #cases, d/dx, one adjoint solve per case. largest (optional):
/// #cases, max_e s_e.
VecXd pnorm_stress(ComplianceProblem& problem, const ResponseParams& params, Eigen::MatrixXd* grad = nullptr,
                   VecXd* largest = nullptr);

/// The largest von Mises stress (MPa) of the crisp design over the load cases: the tets with
/// density >= threshold (non-design tets always) solid, the others void (stiffness e_min),
/// analysed anew on the same mesh; the maximum is taken over the solid tets. The loads are
/// `cases` made on the solid tets and their boundary triangles only (fem::kept_part): a face
/// load spreads over the part of its face the design keeps, a body load weighs the solid tets,
/// and no force lands on nodes that only removed tets hold. density: #T
/// (SimpResult::density); supports: on the whole mesh.
double crisp_max_von_mises(const TetMesh& mesh, const fem::Material& material, const fem::Supports& supports,
                           const std::vector<fem::LoadCase>& cases, const VecXd& density, double threshold = 0.5,
                           double e_min = 1e-9);

}  // namespace topopt::simp
