// The draw direction's cast on the tets themselves (issue 22): whatever grid the draw filter
// casts on, a ray along the draw direction runs through the tets, not through the grid's
// cells, and a grid turned against the mesh leaves the tets of a wall with values of two
// columns (a ray along the wall enters and leaves it). This pass makes the element field
// itself castable: a ray going up (along d) leaves a tet A through a face into the tet B above
// it, so with ρ̂_A ≥ ρ̂_B for every such pair of design tets (one-sided, and above the parting
// plane when split; ρ̂_A ≤ ρ̂_B below it) the field never rises along any ray, on any mesh and
// for any direction. ρ̂_A is the smooth maximum of ρ_A and the cast values of the tets above
// it, taken in an order where those come first (the pairs form no cycle on Delaunay-like
// meshes; a cycle, if any, is broken at its highest tet). Linear-time; the chain rule is the
// adjoint of the same sweep.
#pragma once
#include <vector>

#include "common/adjacency.h"
#include "common/types.h"

namespace topopt::simp {

/// What TetCast casts along.
struct TetCastParams {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();     ///< the draw direction (non-zero)
  bool split = false;                                       ///< two dies meeting at the parting plane
  Eigen::Vector3d parting_point = Eigen::Vector3d::Zero();  ///< a point of the parting plane (split)
  double smoothness = 1e-4;                                 ///< ε of the smooth maximum (draw_filter.h's smooth_max)
};

class TetCast {
 public:
  /// mesh: the tet mesh; design: #D indices of the design tets in mesh.T (the field's order);
  /// params: the direction and parting plane. Tets below the parting plane (by centroid) take
  /// from the design tets below them, the others from those above them; a non-design tet
  /// between two design tets breaks the chain (it is solid anyway).
  TetCast(const TetMesh& mesh, const std::vector<int>& design, const TetCastParams& params);
  /// #D: the cast field of z (#D).
  VecXd apply(const VecXd& z) const;
  /// Chain rule: dF/dz (#D) at z (#D) given dF/d apply(z) (#D).
  VecXd apply_transpose(const VecXd& z, const VecXd& g) const;
  /// Number of ordered pairs (tet, tet it takes from), and of pairs dropped to break cycles.
  long num_pairs() const { return static_cast<long>(takes_from_.index.size()); }
  long num_dropped() const { return dropped_; }

 private:
  double eps_;
  std::vector<int> order_;  // #D: each tet after the tets it takes from
  Adjacency takes_from_;    // row i: the tets tet i takes from
  long dropped_ = 0;
  /// The cast values; with da, db (#pairs) the smooth maximum's partial derivatives per pair.
  VecXd sweep(const VecXd& z, std::vector<double>* da, std::vector<double>* db) const;
};

}  // namespace topopt::simp
