// Design variables tied over orbits: symmetry planes, cyclic and linear-pattern repetition all
// say "these design elements carry the same density". Each is a map of element centroids (a
// mirror, a rotation by one sector, a shift by one pitch); the element that takes an image is the
// design element whose centroid lies nearest to it (within a tolerance, so the mesh need not be
// symmetric), and the tied elements are the connected classes of all those pairs (union-find).
// One variable per class. An extrusion is not tied here: DesignMap puts its variables on a
// section grid (section_grid.h) and ties that grid's nodes by these controls.
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
  /// per control, in the order mirrors, cyclic, patterns: the share of design
  /// elements whose image fell on a design element
  std::vector<double> matched;
  std::string summary;  ///< one line for the log
};

/// Ties the design elements. centroids: #D by 3 centroids of the design elements (in the
/// order of the design variables); params: the controls (mirrors, cyclic, patterns; an extrusion
/// is not a tie but DesignMap's section grid, so params.extrude is ignored here); tolerance: mm
/// (> 0), the largest distance between an image and the centroid that takes it.
/// Throws Error(InvalidParameter) naming the control when a direction or normal is zero, a
/// mirror plane or cyclic axis has the image of fewer than half the design elements in the
/// design domain (it is not a symmetry of the part), or a pattern ties nothing.
Tying tie_design(const Eigen::MatrixX3d& centroids, const ControlsParams& params, double tolerance);

/// Two unit vectors u, v completing the unit vector d to an orthonormal basis (the
/// cross-section plane of a direction).
void cross_section_basis(const Eigen::Vector3d& d, Eigen::Vector3d& u, Eigen::Vector3d& v);

}  // namespace topopt::simp
