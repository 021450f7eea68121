// The PDE density filter (Lazarov & Sigmund, "Filters in topology optimization based on
// Helmholtz-type differential equations", IJNME 2011): ρ̃ solves
//     −ℓ² ∇²ρ̃ + ρ̃ = x   on the design domain, ∂ρ̃/∂n = 0 on its boundary (or, padded, the
//     Robin condition ℓ ∂ρ̃/∂n + ρ̃ = 0 on the part's free faces: see the constructor),
// with linear tets on the nodes of the design elements and x piecewise constant. In matrices:
//     (ℓ² K + M) u = T x,   ρ̃_e = mean of u at e's four nodes,
// K the stiffness (Laplacian) and M the consistent mass of the design tets, T x the load of
// the element densities (each element gives V_e/4 to its nodes). Since M 1 = T 1 and K 1 = 0,
// constants pass unchanged. The boundary condition keeps the non-design solids out (they
// neither give nor take, as with the explicit filter). ℓ from the user's radius r by
// helmholtz_length (filter.h).
//
// Memory is linear in the mesh (about 15 matrix entries per node) whatever the radius: the
// explicit filter holds every pair of elements within r, which at a 2 mm radius on a fine
// mesh is hundreds of pairs per element. Each application is a conjugate-gradient solve,
// warm-started from the previous solution. ℓ²K + M is a mass matrix with a Laplacian of
// relative weight (ℓ/h)²: for the radii of a few mesh sizes it is well conditioned and Jacobi
// suffices; a fixed radius on a refined mesh makes (ℓ/h)² grow and Jacobi-CG's iterations with
// ℓ/h, so there a V-cycle of our smoothed-aggregation multigrid (fem/amg.h, one row per node,
// the constant as near-null mode) preconditions instead (helmholtz_uses_multigrid).
#pragma once
#include <Eigen/Dense>
#include <memory>
#include <vector>

#include "fem/amg.h"
#include "fem/csr_matrix.h"
#include "simp/filter.h"

namespace topopt::simp {

/// Above this (ℓ/h)², h the mean edge length of the design tets, HelmholtzSolver::Auto
/// preconditions with multigrid instead of Jacobi (see the definition for the measurement).
double helmholtz_multigrid_above();

/// Whether the Helmholtz filter of length `length` (mm) on design tets of mean edge `edge` (mm)
/// preconditions with multigrid: as `solver` says, or for Auto when (ℓ/h)² exceeds
/// helmholtz_multigrid_above().
bool helmholtz_uses_multigrid(HelmholtzSolver solver, double length, double edge);

/// The element matrix ℓ² K_e + M_e of a linear tet with corners p (4 rows, mm) and length ℓ
/// (mm): K_e = V Gᵀ G with G the 3 × 4 gradients of the shape functions, M_e = V/20 (1 + δ_ab).
/// The serial filter and dist's parallel one assemble it.
Eigen::Matrix4d helmholtz_element_matrix(const Eigen::Matrix<double, 4, 3>& p, double length);

class HelmholtzFilter final : public Filter {
 public:
  /// mesh, design (#D), volume (#T), held (#V or empty): as make_filter; params.radius > 0 (mm).
  /// With params.pad_free_faces the part's free faces get the Robin condition ℓ ∂ρ̃/∂n + κ ρ̃ = 0
  /// (κ = params.pad_weight) instead of ∂ρ̃/∂n = 0: with κ = 1 the slope at the face of the
  /// equation's solution in a void half-space beyond it (which decays as e^(−s/ℓ)), so the filter
  /// sees void beyond a free face as the explicit filter's ghost layers do (a full design reads ½
  /// there; 1/(1 + κ) in general). Free: as the explicit
  /// filter's (filter.h) — not a face of a non-design tet, not all of its nodes held.
  HelmholtzFilter(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volume, const FilterParams& params,
                  const Progress& progress = {}, const std::vector<char>& held = {});

  VecXd apply(const VecXd& x) const override;
  VecXd apply_transpose(const VecXd& g) const override;
  VecXd filter_sensitivity(const VecXd& x, const VecXd& g) const override;
  std::string describe() const override;

  /// The length ℓ of the equation (mm).
  double length() const { return length_; }
  /// Unknowns (design nodes) and CG iterations of the last solve.
  int unknowns() const { return A_.rows; }
  int last_iterations() const { return last_iterations_; }
  /// True when CG is preconditioned by multigrid (else Jacobi).
  bool multigrid() const { return amg_ != nullptr; }

 private:
  void assemble(const TetMesh& mesh, const std::vector<int>& design);
  void set_up_multigrid();
  /// Adds κ ℓ × the free faces' triangle mass matrices to A_ (the Robin condition above, κ = weight:
  /// FilterParams::pad_weight).
  void pad_free_faces(const TetMesh& mesh, const std::vector<int>& design, const std::vector<char>& held,
                      double weight);
  VecXd nodal_load(const VecXd& per_element) const;  // Σ over each node's elements of value/4
  VecXd element_mean(const VecXd& nodal) const;      // each element's mean of its four nodes
  VecXd solve(const VecXd& b, VecXd& warm) const;

  double length_ = 0;
  int threads_ = 1;
  Progress progress_;
  std::vector<int> element_nodes_;  // #D × 4 local node numbers
  VecXd volume_;                    // #D element volumes
  fem::CsrMatrix A_;                // ℓ² K + M on the design nodes
  VecXd inverse_diagonal_;
  std::unique_ptr<fem::SmoothedAggregationAmg> amg_;  // null: Jacobi
  double mean_edge_ = 0;                              // of the design tets (mm)
  mutable VecXd forward_, backward_;                  // the last solutions: warm starts for the next solve
  mutable int last_iterations_ = 0;
  long padded_faces_ = 0;  // free-face triangles with the Robin condition
  double pad_weight_ = 1;  // κ of that condition
};

}  // namespace topopt::simp
