// Design variables tied over orbits: symmetry planes, cyclic and linear-pattern repetition
// and extrusion all say "these design elements carry the same density". Each is a map of
// element centroids (a mirror, a rotation by one sector, a shift by one pitch) or a column
// along a direction; the element that takes an image is the design element whose centroid
// lies nearest to it (within a tolerance, so the mesh need not be symmetric), and the tied
// elements are the connected classes of all those pairs (union-find). One variable per class.
// The optimiser's DesignMap no longer ties an extrusion's columns here: it puts the extrusion's
// variables on a section grid (section_grid.h) and ties that grid's nodes by the other controls.
#pragma once
#include <string>
#include <vector>

#include "common/types.h"
#include "simp/controls/controls_params.h"

namespace topopt::simp {

/// The classes of tied design elements.
struct Tying {
  std::vector<int> variable_of;  ///< #D: the variable of each design element
  int num_variables = 0;
  /// per control, in the order mirrors, cyclic, patterns (extrusion last): the share of design
  /// elements whose image fell on a design element
  std::vector<double> matched;
  std::string summary;  ///< one line for the log
};

/// Ties the design elements. centroids: #D by 3 centroids of the design elements (in the
/// order of the design variables); params: the controls (mirrors, cyclic, patterns,
/// extrusion); tolerance: mm (> 0), the largest distance
/// between an image and the centroid that takes it, and the column width of the extrusion.
/// Throws Error(InvalidParameter) naming the control when a direction or normal is zero, a
/// mirror plane or cyclic axis has the image of fewer than half the design elements in the
/// design domain (it is not a symmetry of the part), or a pattern ties nothing.
Tying tie_design(const Eigen::MatrixX3d& centroids, const ControlsParams& params, double tolerance);

/// Two unit vectors u, v completing the unit vector d to an orthonormal basis (the
/// cross-section plane of a direction).
void cross_section_basis(const Eigen::Vector3d& d, Eigen::Vector3d& u, Eigen::Vector3d& v);

/// The design elements grouped in columns along the unit direction d: elements whose
/// centroids (#D by 3) project on the cross-section plane into the same square of side
/// `width` share a column. Each column lists its elements in any order.
std::vector<std::vector<int>> columns_along(const Eigen::MatrixX3d& centroids, const Eigen::Vector3d& d, double width);

}  // namespace topopt::simp
