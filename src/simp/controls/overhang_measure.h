// The overhang property of a result surface (issue 22): how much of its downward-facing area
// is too flat to print without supports. The measure the overhang control is tested and
// benchmarked with.
#pragma once
#include "common/types.h"

namespace topopt::simp {

struct OverhangShare {
  double downward_area = 0;  ///< mm²: triangles facing against the build direction, off the plate
  double overhang_area = 0;  ///< mm²: those of them flatter than the critical angle
  /// overhang_area / downward_area (0 when nothing faces down)
  double share() const { return downward_area > 0 ? overhang_area / downward_area : 0.0; }
};

/// V: #P by 3 points, F: #Q by 3 triangles oriented outwards (a closed surface); d: the build
/// direction (non-zero); angle: degrees, the smallest self-supporting angle to the plate;
/// plate: the base plate's height along d/|d| (mm). A triangle faces down when its normal n
/// has n·d < 0; it is an overhang when the angle between n and −d is below `angle` (a plane
/// rising less than `angle` from the plate). Triangles lying on the plate (every corner within
/// plate_tolerance mm of it) rest on it and count neither way.
OverhangShare overhang_share(const MatX3d& V, const MatX3i& F, const Eigen::Vector3d& d, double angle, double plate,
                             double plate_tolerance = 1e-6);

}  // namespace topopt::simp
