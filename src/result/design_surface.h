// The result surface handed to the user, from the marching-tetrahedra surface: badly shaped
// triangles removed (remesh.h), the staircase smoothed (smoothing.h), triangles improved again
// where smoothing bent them, crossings that smoothing made undone (result_check.h), and the
// whole checked: closed, oriented, no self-intersection (exact).
#pragma once
#include "result/remesh.h"
#include "result/result_check.h"
#include "result/smoothing.h"

namespace topopt::result {

/// What finish_design_surface did and found.
struct DesignSurfaceReport {
  long collapses = 0, flips = 0, moves = 0, splits = 0;  ///< remeshing, before and after smoothing
  long remesh_undone = 0;       ///< remeshing passes dropped because their surface crossed itself
  long crossings_smoothed = 0;  ///< crossing pairs right after smoothing (before the repair)
  OverhangLiftReport lift;      ///< with a build direction (smooth.build): the last pass's
  ResultCheck check;            ///< the final surface's check
};

/// Turns the marching-tetrahedra surface s (extract_iso_surface) into the design surface:
/// remesh, smooth (when smooth.iterations > 0), undo the smoothing where triangles cross,
/// remesh (each edit that would make a crossing is refused by the remesher; a remeshing pass whose
/// surface still crosses itself is dropped whole) (smooth.remesh and smooth.repair switch the
/// remeshing and the repair off); with a build direction (smooth.build) the too-flat downward facets
/// are lifted back to the angle last (lift_overhangs). Non-design points never move; Ω's face points stay in their
/// planes. `onto` (may be empty) puts the points the remeshing adds inside Ω's curved faces onto their surfaces
/// (remesh_surface). Returns the counts and the final check; the caller decides what an invalid check means (see
/// pipeline::result_surface, which refuses it with a named error).
DesignSurfaceReport finish_design_surface(TriSurface& s, const SmoothParams& smooth, const RemeshParams& remesh = {},
                                          const FaceProjector& onto = {});

}  // namespace topopt::result
