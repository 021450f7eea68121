// The design surface: remesh, smooth, remesh, repair, check (see design_surface.h).
#include "result/design_surface.h"

#include "mesh/surface/surface_check.h"

namespace topopt::result {

namespace {

/// The smallest free-form angle the design surface aims at (issue 19: no triangle below 10°).
constexpr double kMinDesignAngle = 10.0;

/// Remeshes s, and keeps the remeshed surface only when it crosses nothing (the remesher refuses
/// each edit that would cross, so this is the net behind it); counts into report.
void remesh_unless_crossing(TriSurface& s, const RemeshParams& params, const FaceProjector& onto,
                            DesignSurfaceReport& report) {
  TriSurface kept = s;
  const RemeshReport r = remesh_surface(s, params, onto);
  if (!mesh::self_intersections(s.V, s.F, 1).empty()) {
    s = std::move(kept);
    ++report.remesh_undone;
    return;
  }
  report.collapses += r.collapses, report.flips += r.flips, report.moves += r.moves, report.splits += r.splits;
}

}  // namespace

DesignSurfaceReport finish_design_surface(TriSurface& s, const SmoothParams& smooth, const RemeshParams& remesh,
                                          const FaceProjector& onto) {
  DesignSurfaceReport report;
  if (smooth.remesh) remesh_unless_crossing(s, remesh, onto, report);
  MatX3d before = s.V;
  if (smooth.iterations > 0) {
    smooth_surface(s, smooth);
    report.crossings_smoothed = static_cast<long>(mesh::self_intersections(s.V, s.F, 1L << 40).size());
    // where smoothing made needles or caps (a small cut loop shrinking to a point), undo it
    // locally; then the crossings (pulling points back can itself cross a smoothed neighbour)
    if (smooth.repair) unsharpen(s, before, kMinDesignAngle);
    if (smooth.repair && !mesh::self_intersections(s.V, s.F, 1).empty()) untangle(s, before);
    // smoothing bent some triangles: flip, collapse and move again
    if (smooth.remesh) remesh_unless_crossing(s, remesh, onto, report);
  }
  if (smooth.build.active()) report.lift = lift_overhangs(s, smooth.build);
  report.check = check_result(s);
  return report;
}

}  // namespace topopt::result
