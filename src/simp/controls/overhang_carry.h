// The overhang control's hard requirement on the non-design solids (issue 22): a non-design
// solid's face inside Ω that faces down, flatter than the printable angle, cannot print on the
// design unless design material covers it whole. The filter only removes material, so it cannot
// ask for that; the design tets under such a face are held solid instead (the pipeline hands
// them to SIMP as non-design and counts them in the volume fraction): a funnel whose sides rise at
// the filter's slope (angle + margin), printable from its bottom up, which the optimised design
// carries.
#pragma once
#include <vector>

#include "common/types.h"
#include "simp/controls/controls_params.h"

namespace topopt::simp {

/// #T flags: the design tets the control holds solid under the faces between a non-design and a
/// design tet whose outward normal (out of the solid) points against the build direction by more
/// than cos(control.angle) — every design tet with
/// a face on one, and every design tet whose centroid c lies under one (the line from c along the
/// build direction meets a carried face at height h above c) at least h / tan(angle + margin) inside
/// the carried faces' outline across the build direction: a funnel under each face whose sides rise
/// at the filter's slope. Nothing without domain tags or without such a face.
std::vector<char> carried_tets(const TetMesh& mesh, const OverhangControl& control);

/// #V: the same funnel as a level for the result's extraction, 1 inside it and falling to 0 over
/// `ramp` mm outside it across the build direction (0 where no carried face lies above): the
/// result stage cuts max(node density, level) so that the carried faces stay covered to their
/// edges and the funnel's sides come out as planes at the filter's slope, not as the staircase
/// of the tets carried_tets holds (whose treads are flat).
VecXd carried_level(const TetMesh& mesh, const OverhangControl& control, double ramp);

}  // namespace topopt::simp
