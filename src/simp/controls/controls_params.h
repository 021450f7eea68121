// The geometry controls of SIMP (issue 22): symmetry planes, cyclic and linear-pattern
// repetition and extrusion, as options for DesignMap (design_map.h).
#pragma once
#include <Eigen/Core>
#include <vector>

namespace topopt::simp {

/// A mirror plane of the design: any plane through the part, given by a point on it and its
/// normal (need not be unit length, must not be zero).
struct MirrorPlane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
};

/// Cyclic repetition: the design repeats `sectors` times about the axis through `point`
/// along `axis` (rotation by 360°/sectors maps the design onto itself).
struct CyclicRepetition {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  int sectors = 0;  ///< >= 2
};

/// Linear pattern: `count` copies of the design, `pitch` mm apart along `direction`, the first
/// starting where the design domain starts along the direction. Beyond count × pitch the
/// design is free.
struct LinearPattern {
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  double pitch = 0;  ///< mm, > 0
  int count = 0;     ///< >= 2
};

/// Geometry controls, combinable. Defaults: none.
struct ControlsParams {
  std::vector<MirrorPlane> mirrors;      ///< several planes allowed
  std::vector<CyclicRepetition> cyclic;  ///< usually one
  std::vector<LinearPattern> patterns;
  bool extrude = false;                                  ///< constant cross-section along extrusion
  Eigen::Vector3d extrusion = Eigen::Vector3d::UnitZ();  ///< the extrusion direction
  /// mm: how far a mirrored/rotated/shifted centroid may lie from the design element that
  /// takes it, and the width of the extrusion's columns; <= 0: the mesh's mean edge length.
  double tolerance = 0;

  /// True when any control is set.
  bool any() const { return !mirrors.empty() || !cyclic.empty() || !patterns.empty() || extrude; }
};

}  // namespace topopt::simp
