// Checks of triangle surface meshes that the meshers' tests, `topopt surface --stats` and
// bench/surface rely on: self-intersection decided by the exact predicates, and the angle
// figures by which surface meshes are compared.
#pragma once
#include <vector>

#include "common/types.h"

namespace topopt::mesh {

/// Pairs of triangles of (V, F) that intersect other than along what they share: triangles
/// with no common node that touch at all, triangles sharing one node that meet elsewhere too,
/// triangles sharing an edge that fold onto each other (coplanar, on the same side). Exact
/// (orient2d/orient3d), so touching counts. Degenerate triangles (zero area) are reported as
/// pairs (t, t). Stops after `max_pairs` pairs.
std::vector<std::pair<int, int>> self_intersections(const MatX3d& V, const MatX3i& F, long max_pairs = 100);

/// Whether the triangle with points x (3 doubles each) has zero area (exact), which
/// self_intersections reports as the pair (t, t).
bool triangle_degenerate(const double* const x[3]);

/// Whether two triangles cross as self_intersections decides for a pair: either has zero area, or
/// they intersect other than along what they share. x, y: each triangle's three points (3
/// doubles each); xi, yi: their ids (equal ids name one point, shared by both triangles). Exact.
bool triangles_cross(const double* const x[3], const int xi[3], const double* const y[3], const int yi[3]);

struct SurfaceQuality {
  long triangles = 0;
  double min_angle = 0;       ///< smallest angle of any triangle (degrees)
  double mean_min_angle = 0;  ///< mean over triangles of their smallest angle (degrees)
  double share_below_20 = 0;  ///< fraction of triangles whose smallest angle is below 20°
  double mean_quality = 0;    ///< mean of 4√3·area / Σ edge² (1 = equilateral)
};
SurfaceQuality surface_quality(const MatX3d& V, const MatX3i& F);

}  // namespace topopt::mesh
