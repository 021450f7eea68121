// The Helmholtz (PDE) density filter on the distributed mesh: the serial filter's equation
// (simp/helmholtz_filter.h: (ℓ² K + M) u = T x on the design tets' nodes, ρ̃_e the mean of u at
// e's nodes) as a PETSc MatMPIAIJ on the nodes, assembled once from the same element matrix and
// solved by CG with Jacobi to the serial filter's tolerance. Nodes of no design tet get a
// diagonal alone and stay 0, so they neither give nor take.
// Not padded (simp::FilterParams::pad_free_faces and its pad_weight κ, the serial filter's Robin term on the part's
// free faces): the padding serves the minimum member size alone, and mpirun refuses it with the
// other geometry controls (check_distributable, dist_simp.h); it comes with the robust
// formulation if that is ever distributed.
#pragma once
#include <memory>
#include <vector>

#include "dist/dist_mesh.h"

namespace topopt::dist {

class DistHelmholtz {
 public:
  /// design: this rank's design tets (indices into mesh.local.T, the order of the local design
  /// variables); length: ℓ (mm, simp::helmholtz_length). Collective.
  DistHelmholtz(const MpiSession& session, const DistMesh& mesh, const std::vector<int>& design, double length);
  ~DistHelmholtz();
  DistHelmholtz(const DistHelmholtz&) = delete;
  DistHelmholtz& operator=(const DistHelmholtz&) = delete;

  /// ρ̃ = F x on this rank's design variables (#D local in, #D local out). Collective.
  VecXd apply(const VecXd& x) const;
  /// Fᵀ g, the chain rule of apply (#D local in and out). Collective.
  VecXd apply_transpose(const VecXd& g) const;
  /// CG iterations of the last solve.
  int last_iterations() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace topopt::dist
