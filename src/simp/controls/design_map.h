// The geometry controls as maps in the SIMP chain: variables x (#N) → design field z (#D)
// → density filter → orbit mean → projection → physics. Tying (symmetry planes, cyclic and
// linear repetition: tying.h) makes z = P x = x[class of each element], a linear map. The
// density filter does not keep that: on an unstructured mesh each element's kernel covers a
// different neighbourhood than its image's, so F z differs across a class, and the projection
// sharpens the difference into a design that does not repeat (issue 22; on the jittered test
// beam at β = 32, 4.4 / 0.8 % of the tets' projected densities lay more than 0.1 off their
// class's mean with a pattern / a mirror; the cantilever's pattern left 11.5 % of the result
// surface's area more than a mesh size off its image, 3.6 % with A). The orbit mean
// A = P (Pᵀ V P)⁻¹ Pᵀ V (V the element volumes) gives every element of a class its class's
// volume-weighted mean of the filtered field, so the filtered and projected designs repeat
// exactly class by class; it keeps the filtered field's volume (Σ v A y = Σ v y) and its
// transpose Aᵀ = V P (Pᵀ V P)⁻¹ Pᵀ carries the chain rule. Without ties both maps are the identity.
//
// An extrusion puts the variables on the nodes of a section grid (section_grid.h) half a
// `tolerance` apart, tied by the other controls at the section's nodes: z = S x with S (#D by #N)
// each element's bilinear weights at its centroid's projection, so z is a smooth field of the
// section, equal along the direction. Its orbit mean is the lumped fit on the same nodes,
// A = S W⁻¹ Sᵀ V with W = diag(Sᵀ V 1): the filtered field becomes a section field again (equal
// along the direction), its volume kept (S 1 = 1), Aᵀ = V S W⁻¹ Sᵀ. (Columns one tolerance
// wide, each one variable and the exact class mean, drew the cantilever's section in squares
// that coarse: compliance 489 -> 1000 N·mm, the load pad left alone — branch repeat23.)
#pragma once
#include <Eigen/Sparse>
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
  /// Chain rule: dF/dx (#N) given dF/dz (#D): each variable sums its elements' g (weighted by
  /// their interpolation weights under an extrusion).
  VecXd apply_transpose(const VecXd& g) const;
  /// The orbit mean A y (#D) of a filtered field y (#D); y itself without ties.
  VecXd orbit_mean(const VecXd& y) const;
  /// Chain rule of orbit_mean: Aᵀ g (#D); g itself where orbit_mean is the identity.
  VecXd orbit_mean_transpose(const VecXd& g) const;
  /// One line for the log ("" without controls).
  const std::string& describe() const { return summary_; }

 private:
  /// The extrusion's map S and its class volumes (see the file's head).
  void build_section(const TetMesh& mesh, const std::vector<int>& design, const ControlsParams& params,
                     double tolerance);

  std::vector<int> variable_of_;         // #D (ties without an extrusion)
  Eigen::SparseMatrix<double> section_;  // #D by #N: S under an extrusion, else empty
  bool extruded_ = false;
  int num_variables_ = 0;
  bool averaged_ = false;  // the orbit mean acts: ties
  VecXd volume_;           // #D element volumes (when averaged_)
  VecXd class_volume_;     // #N the volume of each class (when averaged_; W's diagonal under an extrusion)
  std::string summary_;
};

}  // namespace topopt::simp
