// Staircase removal on the result surface: Taubin's λ|μ smoothing (a low-pass filter that
// does not shrink), on free vertices only.
#pragma once
#include "result/iso_surface.h"

namespace topopt::result {

struct SmoothParams {
  int iterations = 20;  ///< λ|μ pairs
  double lambda = 0.5;  ///< shrinking step
  double mu = -0.53;    ///< inflating step (|μ| > λ)
  /// Vertices on Ω's boundary faces: slide within their face's plane when it is planar
  /// (true), or stay fixed (false). Non-design vertices never move.
  bool slide_on_planar_faces = true;
  /// The finishing of the result surface around the smoothing (design_surface.h): edge flips
  /// and collapses of badly shaped triangles before and after it (remesh, job key
  /// "surface_remesh"), and the smoothing undone where triangles cross (repair,
  /// "surface_repair"). Off only to compare with the surface as it was before issue 19.
  bool remesh = true;
  bool repair = true;
  /// With remesh: crossings kept this share of an edge away from its nodes when the surface is
  /// cut (extract_iso_surface's margin; slivers from crossings next to nodes never appear).
  double crossing_margin = 0.2;
  /// The resolution the surface is cut at (job key "result.resolution"): 1 on the FE mesh, 2 on
  /// the FE mesh with the design tets near the level split once (iso_surface_refine.h).
  int resolution = 1;
};

/// Smooths s.V in place. Vertices with lock 2 do not move; with lock 1 they move only
/// within the plane of their (planar) Ω face and only along the boundary curve of the cut.
void smooth_surface(TriSurface& s, const SmoothParams& params = {});

}  // namespace topopt::result
