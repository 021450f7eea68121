// The geometry controls as one map in the SIMP chain: variables x (#N) → design field z (#D)
// → density filter → projection → physics. Tying (symmetry planes, cyclic and linear
// repetition, extrusion: tying.h) makes z = x[class of each element], a linear map. Without
// controls it is the identity (#N = #D).
#pragma once
#include <string>
#include <vector>

#include "common/types.h"
#include "simp/controls/controls_params.h"

namespace topopt::simp {

/// #D by 3: the centroids of the tets design (#D indices into mesh.T).
Eigen::MatrixX3d design_centroids(const TetMesh& mesh, const std::vector<int>& design);

class DesignMap {
 public:
  /// mesh: the tagged mesh; design: #D indices of the design tets in mesh.T (the order of z);
  /// params: the controls; tolerance: mm, > 0 (ControlsParams::tolerance resolved, e.g. the
  /// mean edge length). Throws Error(InvalidParameter) as tie_design does.
  DesignMap(const TetMesh& mesh, const std::vector<int>& design, const ControlsParams& params, double tolerance);
  ~DesignMap();
  /// Number of variables #N.
  int num_variables() const { return num_variables_; }
  /// z (#D) of x (#N).
  VecXd apply(const VecXd& x) const;
  /// Chain rule: dF/dx (#N) given dF/dz (#D): each variable sums its elements' g.
  VecXd apply_transpose(const VecXd& g) const;
  /// One line for the log ("" without controls).
  const std::string& describe() const { return summary_; }

 private:
  std::vector<int> variable_of_;  // #D
  int num_variables_ = 0;
  std::string summary_;
};

}  // namespace topopt::simp
