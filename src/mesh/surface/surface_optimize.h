// Local optimisation of a face's triangles judged in 3D (issue 3, "local optimisation on the
// surface"): the face front works in scaled parameters, which are only an approximation of
// lengths on a curved surface, so the triangles are improved afterwards by their angles on
// the surface itself:
// - edge flips that raise the smaller angle of the pair;
// - edge collapses (a node removed onto a neighbour, the survivor placed by a compass search)
//   for edges much shorter than their triangles' others (needles where fronts met) and around
//   triangles below 20° (a node squeezed against a boundary segment), kept when the region's
//   smallest angle rises by 1°;
// - smoothing that moves a node towards the centre of its neighbours in space and back onto
//   the face through its parameters (one Gauss-Newton step), kept when the star's smallest
//   angle rises or its angles improve on the whole with the smallest staying above
//   min(before, 30°); then a compass search on the nodes of triangles below 40°;
// - last, splits of the inner edge of triangles whose corners may not move (all on the
//   boundary), kept when the four new triangles' smallest angle rises and no more of them
//   are below 20°.
// Every change is checked in the parameter plane with the exact orient2d, so the face's
// triangulation stays valid there; nodes below `fixed` (boundary, isolated, pre-placed) never
// move; constrained edges never flip and their ends are never removed (they may move: the
// neighbours of a cone's apex). Triangles with two corners at one point (the strip of a
// degenerate edge) are judged in the parameters only.
#pragma once
#include <array>
#include <functional>
#include <vector>

#include "common/types.h"

namespace topopt::mesh {

/// Evaluates the face at parameters uv: the point X and the derivatives along the two
/// parameters (each a 3-vector).
using SurfaceEval = std::function<void(const double* uv, double* X, double* Xu, double* Xv)>;

struct SurfaceOptimizeStats {
  long flips = 0, moves = 0, collapses = 0, splits = 0;
  double min_angle_before = 0, min_angle_after = 0;  ///< degrees, over the triangles
};

/// Improves (P, T) in place (splits add nodes to P, collapses leave unused ones); X receives
/// the 3D points of every node of P (rows of P).
SurfaceOptimizeStats optimize_on_surface(MatX2d& P, MatX3i& T, MatX3d& X, int fixed, const SurfaceEval& eval,
                                         const std::vector<std::array<int, 2>>& constrained = {}, int rounds = 3);

}  // namespace topopt::mesh
