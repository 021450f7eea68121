// The member sizes of a crisp design on its tet mesh, measured (issue 22's test of the minimum
// and maximum member size): a distance transform of the solid tets to the design's boundary and
// the local thickness built from it (Hildebrand & Rüegsegger 1997: the diameter of the largest
// inscribed ball that contains the point).
#pragma once
#include "common/types.h"

namespace topopt::simp {

/// What to measure against.
struct MemberMeasureParams {
  double threshold = 0.5;  ///< a tet is solid when its density is at least this
  /// True: the part's own boundary bounds the solid too (the maximum size: a ball must fit in
  /// the part). False: only faces between a solid and a void tet do (the minimum size: the
  /// density filter is normalised over the part, so a member along the part's boundary is
  /// measured as if mirrored there, and the part's own corners are not the design's).
  bool part_boundary = false;
  /// mm: a tet belongs to a ball when its centroid lies within the ball's radius plus this (half
  /// the mesh size: a crisp design is a staircase of tets, and a tet in a staircase corner would
  /// otherwise lie in no ball wider than its own centroid's distance to the corner).
  double reach = 0;
};

/// Per tet and overall sizes (mm).
struct MemberMeasure {
  /// #T: the distance from the tet's centroid to the nearest boundary triangle of the solid
  /// (0 for void tets; the part's diagonal when the solid has no boundary of the kind asked).
  VecXd inscribed;
  /// #T: the local thickness, 2 max { inscribed_f : |c_t − c_f| <= inscribed_f + reach } over solid f
  /// (0 for void tets).
  VecXd thickness;
  double smallest_member = 0;  ///< min thickness over the solid design tets (domain 0)
  double largest_ball = 0;     ///< 2 max inscribed over the solid design tets: the widest ball that fits
  long solid_design = 0;       ///< number of solid design tets
};

/// Measures the crisp design `density` (#T, non-design tets 1) on `mesh`. Distances go to the
/// boundary triangles (exact point–triangle distances), so sizes are known to about a tet's
/// centroid offset, a fraction of the mesh size. Cost: #solid × #boundary triangles at worst.
MemberMeasure measure_members(const TetMesh& mesh, const VecXd& density, const MemberMeasureParams& params = {});

}  // namespace topopt::simp
