// The result surface under an overhang control (issue 22): the last pass of the surface stage
// when the job prints along a build direction. The crossing margin and the smoothing tilt some
// facets of the lattice's staircase, which the filter built at or above the critical angle, below
// it; this pass moves points of the downward-facing facets that rise less than the angle from the
// plate so that they rise at least that much again where the surface around them, at the scale of
// its edges, rises that much (a ceiling stays a ceiling) — each move bounded, keeping every triangle's
// shape (no triangle below the angle floor that was above it), turning no triangle over, crossing
// nothing (exact, crossing_guard.h), non-design points fixed and Ω's face points in their planes.
#pragma once
#include "result/iso_surface.h"

namespace topopt::result {

/// The build the result surface is printed along (an overhang control of the job), or none.
struct BuildDirection {
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  ///< unit, from the plate up; zero: no control
  double angle = 45;                                    ///< degrees: the smallest self-supporting rise from the plate
  double plate = 0;                                     ///< mm: the plate's height along direction
  /// degrees: the control's margin: the non-design solids' undersides are carried by a funnel whose
  /// sides rise at angle + margin (simp/controls/overhang_carry.h)
  double margin = 20;
  /// mm: a triangle with every corner this close to the plate rests on it (simp::overhang_share's)
  double plate_tolerance = 1e-6;
  bool active() const { return direction.squaredNorm() > 0; }
};

struct OverhangLiftParams {
  /// degrees: a facet is lifted to angle + this, so that rounding does not leave it just below
  double lift_margin = 0.5;
  /// a point moves at most this share of the mean length of its edges (at the pass's start) from
  /// where the pass found it — the crossing margin's own shift: the pass restores slopes, it does
  /// not reshape the design (on the test beam 0.1 / 0.2 / 0.5 leave 0.50 / 0.19 / 0 % of the
  /// controlled design's surface too flat, and take the free design's 34.6 % to 30.4 / 25.4 / 16.0 %)
  double reach = 0.2;
  double min_angle = 10;        ///< degrees: no triangle ends below this unless it already was (then no worse)
  double max_normal_turn = 60;  ///< degrees: a move may turn no triangle's normal by more than this
  int sweeps = 12;              ///< sweeps over the points of the facets still too flat
};

/// What lift_overhangs did.
struct OverhangLiftReport {
  double before = 0, after = 0;  ///< mm²: downward-facing area off the plate rising less than the angle
  long moves = 0;                ///< point moves kept
  /// mm: the length of the hanging edges (keels: the surface rising on both sides of an edge that
  /// faces down and rises less than the angle), and the lowest points off the plate (every
  /// neighbour above): before and after. The pass makes neither; they are not in the facets' share
  double keels_before = 0, keels_after = 0;
  long lowest_before = 0, lowest_after = 0;
};

/// Moves points of s (V only; the triangles stay) so that less of its downward-facing area (facing
/// against build.direction, off the plate) rises less than build.angle from the plate: point by
/// point, the area-weighted excess of the facets around it (their normal's component along
/// −direction above cos(angle + lift_margin)) falls, by steepest descent with a backtracking step
/// and a few fixed directions when that fails. Free points (lock 0) move in space, points of a
/// planar Ω face's cut line within the face's plane; other points stay, and so does every point
/// whose 2-ring (off the plate) is, as one patch, flatter than build.angle: a ceiling, whose facets
/// the pass would only corrugate into steep ones that print on nothing. A move is kept only when
/// it lowers the excess, stays within `reach`, leaves no triangle around the point below
/// min_angle that was not (none worse that was), turns none by more than max_normal_turn, and
/// crosses no triangle of the surface. Does nothing without a build direction.
OverhangLiftReport lift_overhangs(TriSurface& s, const BuildDirection& build, const OverhangLiftParams& params = {});

/// The area (mm²) of s's triangles that face against build.direction, do not rest on the plate,
/// and rise less than `angle` degrees from it (the facets simp::overhang_share counts).
double too_flat_area(const TriSurface& s, const BuildDirection& build, double angle);

}  // namespace topopt::result
