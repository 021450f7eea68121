// The draw-direction control (issue 22): filtered densities ρ̃ (#D) → intermediate grid of
// columns along the draw direction (column_grid.h) → a smooth cumulative maximum along each
// column, outwards from the parting plane (or from the grid's lower end, one-sided) → back to
// the elements → the same cast once more on the tets themselves (tet_cast.h). The grid sets
// the design's resolution (`cell`); the tet pass makes the element field castable along every
// ray, also where the grid's columns do not line up with the mesh (a turned direction, a cell
// other than the mesh's): an element takes its cell's value by its centroid, so a wall of the
// grid is jagged on the tets and a ray along it would enter and leave it. The result never
// rises along the draw direction above the parting plane and never falls below it, so the
// projection that follows leaves one solid stretch per ray. Sits between the density filter
// and the projection; the chain rule runs through all four maps.
#pragma once
#include <string>
#include <vector>

#include "common/types.h"
#include "simp/controls/column_grid.h"
#include "simp/controls/controls_params.h"
#include "simp/controls/tet_cast.h"

namespace topopt::simp {

class DrawFilter {
 public:
  /// mesh: the tet mesh; design: #D indices of the design tets in mesh.T (the field's order);
  /// volumes: #D their volumes; params: the draw direction (enabled); cell: the grid's cell
  /// side (mm, > 0). Throws Error(InvalidParameter) naming the key for a zero direction or a
  /// smoothness outside (0, 0.01].
  DrawFilter(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volumes, const DrawDirection& params,
             double cell);
  /// #D: the cast field of r (#D, values in [0, 1]).
  VecXd apply(const VecXd& r) const;
  /// Chain rule: dF/dr (#D) at r (#D) given dF/d apply(r) (#D).
  VecXd apply_transpose(const VecXd& r, const VecXd& g) const;
  /// One line for the log: grid size, parting layer, the tet pass's pairs.
  const std::string& describe() const { return summary_; }

 private:
  DrawDirection params_;
  ColumnGrid grid_;
  TetCast tets_;
  int parting_layer_ = 0;  // layers below it rise along d, layers from it on fall
  std::string summary_;
  /// The cumulative smooth maximum of grid values g (#cells) along every column; with
  /// adjoint != nullptr, also replaces *adjoint (d/d output, #cells) by d/d g.
  VecXd cumulate(const VecXd& g, VecXd* adjoint) const;
};

/// The smooth maximum (a + b + √((a−b)² + eps) − √eps)/2: at most max(a, b), equal to a when
/// a = b, within √eps/2 of max(a, b); its partial derivatives in *da and *db.
double smooth_max(double a, double b, double eps, double* da, double* db);

}  // namespace topopt::simp
