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
};

/// Smooths s.V in place. Vertices with lock 2 do not move; with lock 1 they move only
/// within the plane of their (planar) Ω face and only along the boundary curve of the cut.
void smooth_surface(TriSurface& s, const SmoothParams& params = {});

}  // namespace topopt::result
