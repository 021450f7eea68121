// The overhang property of a result surface (issue 22): how much of its downward-facing area
// is too flat to print without supports. The measure the overhang control is tested and
// benchmarked with.
#pragma once
#include "common/types.h"

namespace topopt::simp {

struct OverhangShare {
  double downward_area = 0;  ///< mm²: triangles facing against the build direction, off the plate
  double overhang_area = 0;  ///< mm²: those of them flatter than the critical angle
  /// mm², with tags only: the overhang area split by whose face it lies on (the three sum to
  /// overhang_area): the design's own surface (tag 0), the non-design solids' faces inside Ω that
  /// the design leaves bare (tag < 0), Ω's faces where the design reaches them (tag > 0)
  double design_overhang = 0, nondesign_overhang = 0, omega_overhang = 0;
  /// mm², with tags and locks only: the part's given shape, not in the areas above — the
  /// non-design solids' faces on Ω's boundary (a bore's roof in a boss): downward-facing, and of
  /// them flatter than the critical angle. No design changes them; they need supports whatever
  /// the optimiser does, so they are reported apart, not in the share.
  double given_downward_area = 0, given_overhang_area = 0;
  /// overhang_area / downward_area (0 when nothing faces down)
  double share() const { return downward_area > 0 ? overhang_area / downward_area : 0.0; }
};

/// How overhang_share judges a surface.
struct OverhangMeasureParams {
  double angle = 45;              ///< degrees: the smallest self-supporting angle to the plate
  double plate = 0;               ///< mm: the base plate's height along the build direction
  double plate_tolerance = 1e-6;  ///< mm: a triangle with every corner this close to the plate rests on it
  /// degrees >= 0: a triangle counts as an overhang only when it rises less than angle − tolerance
  /// from the plate (facets of a wall at the limit scatter by a few degrees around its slope)
  double tolerance = 0;
};

/// V: #P by 3 points, F: #Q by 3 triangles oriented outwards (a closed surface); d: the build
/// direction (non-zero); params: the angle, plate and tolerances; tag: nullptr or #Q tags of
/// result::TriSurface (0 the design's own surface, f > 0 Ω's face f, −k a face of non-design
/// solid k); lock: nullptr or #P locks of result::TriSurface (2: a point of a non-design solid).
/// What counts is what a design could change: the design's own surface, a non-design face inside
/// Ω (on the surface only where the design leaves it bare, and the design could have covered
/// it: a bared load pad's face needs supports because of the design), and Ω's faces where the
/// design reaches them. Not counted, reported apart as given_*: a non-design solid's face on Ω's
/// boundary (tag > 0, every corner locked 2), the user's shape whatever the design. Without tags
/// every triangle counts. A triangle faces down when its normal n has n·d < 0; it is an overhang
/// when the angle between n and −d is below angle − tolerance (a plane rising less than that
/// from the plate). Triangles lying on the plate (every corner within plate_tolerance of it)
/// count neither way: they rest on it (docs/optimization.md, "Overhang", what counts).
OverhangShare overhang_share(const MatX3d& V, const MatX3i& F, const Eigen::Vector3d& d,
                             const OverhangMeasureParams& params, const VecXi* tag = nullptr,
                             const VecXi* lock = nullptr);

}  // namespace topopt::simp
