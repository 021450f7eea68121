// The member sizes of a crisp design on its tet mesh, measured (issue 22's test of the minimum
// and maximum member size): a distance transform of the solid tets to the design's boundary and
// the local thickness built from it (Hildebrand & Rüegsegger 1997: the diameter of the largest
// inscribed ball that contains the point). The same measure of the void design tets gives the
// gaps.
#pragma once
#include "common/types.h"

namespace topopt::simp {

/// How the part's own boundary (the faces of the mesh) bounds the balls.
enum class PartFaces {
  /// The part's boundary bounds the balls like a solid/void face (the maximum size: a ball must
  /// fit in the part). The part's own convex corners and edges read thin then.
  Wall,
  /// The minimum size: the balls are bounded by the faces between solid and void tets only, and
  /// a ball that crosses the part's boundary counts for the width it keeps inside the part along
  /// the line from its nearest boundary point through its centre: r + min(r, s), s the distance
  /// from the centre along that line to the part's boundary. A member along the part's face
  /// measures its own thickness (a ball centred in it reaches the face), a member that meets a
  /// face across its thickness is not thinned there, and a solid corner of the part is as thick
  /// as the solid behind it. A member that fills the part's own thickness (the part thinner than
  /// the member) is not bounded there: it is the part's, not the design's.
  Clipped,
};

/// What to measure against.
struct MemberMeasureParams {
  double threshold = 0.5;  ///< a tet is solid when its density is at least this
  PartFaces part_faces = PartFaces::Clipped;
  /// False: the solid tets' members. True: the gaps, the void design tets' (non-design tets are
  /// solid), bounded by the faces between void and solid tets.
  bool gaps = false;
  /// mm: a tet belongs to a ball when its centroid lies within the ball's radius plus this (half
  /// the mesh size: a crisp design is a staircase of tets, and a tet in a staircase corner would
  /// otherwise lie in no ball wider than its own centroid's distance to the corner).
  double reach = 0;
};

/// Per tet and overall sizes (mm) of the measured phase (the solid tets, or the void design tets
/// for gaps).
struct MemberMeasure {
  /// #T: the distance from the tet's centroid to the nearest boundary triangle of its phase
  /// (0 outside the phase; the part's diagonal when the phase has no boundary of the kind asked).
  VecXd inscribed;
  /// #T: the local thickness, the largest width w_f of the balls f (centre c_f, radius r_f =
  /// inscribed) with |c_t − c_f| <= r_f + reach; w_f = 2 r_f, clipped by the part as
  /// PartFaces says (0 outside the phase).
  VecXd thickness;
  double smallest_member = 0;  ///< min thickness over the phase's design tets (domain 0)
  double largest_ball = 0;     ///< 2 max inscribed over the phase's design tets: the widest ball that fits
  long solid_design = 0;       ///< number of the phase's design tets
};

/// Measures the crisp design `density` (#T, non-design tets 1) on `mesh`. Distances go to the
/// boundary triangles (exact point–triangle distances), so sizes are known to about a tet's
/// centroid offset, a fraction of the mesh size. Cost: #phase × #boundary triangles at worst.
MemberMeasure measure_members(const TetMesh& mesh, const VecXd& density, const MemberMeasureParams& params = {});

}  // namespace topopt::simp
