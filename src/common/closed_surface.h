// Whether a triangle surface is closed: every edge used by exactly two triangles in opposite
// directions (closed, manifold, consistently oriented), and the volume it encloses. The one
// such check of the code: the surface mesher's solids (mesh/surface), the result shape
// (result/) and the CLI use it.
#pragma once
#include "common/types.h"

namespace topopt {

/// How the triangles' directed edges pair up, each distinct directed edge (a, b) counted once.
struct SurfaceCheck {
  long open_edges = 0;         ///< directed edges whose opposite (b, a) no triangle uses
  long overshared_edges = 0;   ///< directed edges used by more than one triangle
  long misoriented_edges = 0;  ///< directed edges used a different number of times than their (used) opposite
  long unpaired_edges = 0;     ///< directed edges in any of the three above: not used once each way
  double volume = 0;           ///< enclosed volume (divergence theorem), > 0 when oriented outwards; 0 without V
  bool closed_manifold() const { return unpaired_edges == 0; }
};

/// The edge pairing of the triangles F (#F by 3 node indices); volume 0.
SurfaceCheck check_surface(const MatX3i& F);

/// The edge pairing of the triangles F (#F by 3 rows of V) and the volume they enclose
/// (V: #V by 3 points).
SurfaceCheck check_surface(const MatX3d& V, const MatX3i& F);

}  // namespace topopt
