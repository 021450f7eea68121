// Fewer facets for the result's CAD solid: the free-form region of the result surface (the
// iso-surface, tag 0) coarsened by edge collapses within a chordal tolerance before it becomes
// B-Rep faces (step_export.h), so that result.step holds fewer faces. Ω's kept faces and the
// non-design solids' faces are never touched: a point is removed only when every triangle
// around it is free-form and it is free to move (lock 0, not on a cut line), and no point is
// ever moved, so every kept point is a point of the surface it came from.
#pragma once
#include "result/iso_surface.h"

namespace topopt::result {

struct CoarsenParams {
  /// Chordal tolerance as a fraction of the median edge length of the free-form triangles:
  /// no removed point lies farther than this from the coarsened surface (<= 0: nothing is
  /// removed). The median edge is about the FE size, so 0.05 is well below it.
  double tolerance = 0.05;
  /// Largest turn (radians) of a triangle's normal that a collapse may cause.
  double max_normal_turn = 0.5;
  /// Smallest angle (degrees) of a triangle a collapse makes, unless the triangles it replaces
  /// already had a smaller one (then that one is the floor).
  double min_angle = 5.0;
  int passes = 8;  ///< sweeps over the edges, shortest first; stops early when one removes nothing
};

/// What coarsen_free_form did.
struct CoarsenReport {
  long triangles_before = 0;  ///< triangles of the surface given
  long triangles_after = 0;   ///< triangles of the surface returned
  double tolerance = 0;       ///< the chordal tolerance used, mm
  bool reverted = false;      ///< the coarsened surface crossed itself: the one given was returned
  /// Set by result_solid: bodies whose merged faces OCCT's check refused, written as facets.
  int unmerged_bodies = 0;
  /// Set by result_solid: of those, bodies written without the input's curved faces.
  int facet_bodies = 0;
  int attempts = 1;          ///< coarsenings run by coarsen_to_budget (1: the tolerance given sufficed)
  double volume_change = 0;  ///< |volume returned - volume given| / volume given
  bool fits = true;          ///< coarsen_to_budget: triangles_after is within the budget
};

/// How far coarsen_to_budget may go to bring a surface within a triangle budget.
struct CoarsenBudget {
  long max_triangles = 0;          ///< the budget (<= 0: none; the tolerance given is used)
  double max_tolerance = 1.6;      ///< the largest relative tolerance tried (CoarsenParams::tolerance)
  double max_volume_change = 0.005;  ///< the largest relative change of the enclosed volume allowed
};

/// Distance (mm) from point p to the triangle (a, b, c) (all 3-vectors), by the region of
/// the closest point (a corner, an edge or the inside).
double point_triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                               const Eigen::Vector3d& c);

/// `s` (a closed, outward, self-intersection-free result surface) with points of its free-form
/// region removed by edge collapses (the removed point joins a neighbour) while every removed
/// point stays within the tolerance of the new surface, no normal turns past
/// params.max_normal_turn, no new triangle is sharper than params.min_angle and the surface
/// stays manifold (link condition). The result is checked by the product's exact result check
/// (check_result); if it is not valid, the surface given is returned unchanged (report->reverted).
/// s.V and the per-point arrays are kept as they are (removed points are simply unused);
/// s.F and s.tag shrink.
TriSurface coarsen_free_form(const TriSurface& s, const CoarsenParams& params = {}, CoarsenReport* report = nullptr);

/// `s` coarsened by coarsen_free_form with params.tolerance (0 or less: 0.05) and, while more
/// than budget.max_triangles triangles remain, coarsened again from `s` with the tolerance
/// doubled, up to budget.max_tolerance, as long as the enclosed volume stays within
/// budget.max_volume_change of s's (a coarsening that crossed itself and was reverted is
/// passed over). Returns the surface with the fewest triangles within those bounds (the one
/// given when even the first is not); report->fits says whether it is within the budget,
/// report->attempts how many coarsenings ran. Each coarsening starts from `s`, so the chordal
/// tolerance reported holds against the surface given.
TriSurface coarsen_to_budget(const TriSurface& s, const CoarsenParams& params, const CoarsenBudget& budget,
                             CoarsenReport* report = nullptr);

}  // namespace topopt::result
