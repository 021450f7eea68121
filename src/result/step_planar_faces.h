// The result's planar B-Rep faces worked out on the triangle surface itself, before any OCCT
// shape exists: coplanar neighbouring triangles grouped into one face (Ω's planar faces come
// back whole, bounded by the polygon of the kept region), each group's boundary loops, and the
// points along a straight run of boundary between the same two faces dropped so that the run
// becomes one edge. The STEP export (step_export.h) builds each face once from this, in time
// linear in the surface; OCCT's ShapeUpgrade_UnifySameDomain did the same merge on the built
// shell in time growing as its square (its edge merge re-orients the whole shell; measured in
// BENCHMARKS.md, branch step7).
#pragma once
#include <optional>
#include <vector>

#include "result/iso_surface.h"

namespace topopt::result {

struct PlanarFacesParams {
  /// Angle (radians) within which a triangle's normal counts as the face's. Ω's planar faces
  /// are exactly planar; a small value keeps the free-form region's facets apart.
  double angular_tolerance = 1e-6;
  /// Largest distance (mm) of a grouped triangle's corners from the face's plane, and of a
  /// dropped boundary point from the straight edge that replaces its run. Half OCCT's
  /// Precision::Confusion, so the default vertex and edge tolerance covers it.
  double linear_tolerance = 5e-8;
};

/// One planar face of the result: triangles of the surface (#triangles, rows of s.F) in one
/// plane through `origin` with outward unit `normal`, bounded by `loops`: each a closed
/// sequence of point numbers (rows of s.V) with the face on the left seen from outside
/// (counter-clockwise about `normal` for the outer loop, clockwise for holes), holding only
/// the points where an edge ends (a corner, or where the boundary meets a third face).
struct PlanarFace {
  std::vector<long> triangles;
  std::vector<std::vector<int>> loops;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

/// The boundary loops of the triangles `tris` of `s` (points in order; each step is a
/// half-edge of one of the triangles whose twin belongs to none of them, so a loop has the
/// triangles on its left seen from outside); nullopt where the boundary pinches (a point with
/// two boundary edges leaving it).
std::optional<std::vector<std::vector<int>>> boundary_loops(const TriSurface& s, const std::vector<long>& tris);

/// The planar faces of the closed, outward surface `s` (every edge in exactly two triangles)
/// made of the triangles with mergeable[q] != 0 (#Q; the others, e.g. triangles that become
/// faces on the input's curved surfaces, are left out, and no point they touch is dropped from
/// a loop). A face grows from a triangle over shared edges to every triangle whose normal lies
/// within params.angular_tolerance of its first triangle's and whose corners lie within
/// params.linear_tolerance of that plane; where a group's boundary pinches (touches itself at
/// a point), the triangles at that point are faces of their own and the rest is split into its
/// connected pieces, again until none pinches; a triangle without area is a face of its own. A point of a loop is dropped when every
/// triangle around it is mergeable, exactly two face boundaries' edges meet there and they
/// run on in a straight line (both tolerances), so that both faces along the run see the same
/// single edge. Every mergeable triangle is in exactly one face. Linear in the surface.
std::vector<PlanarFace> planar_faces(const TriSurface& s, const std::vector<char>& mergeable,
                                     const PlanarFacesParams& params = {});

}  // namespace topopt::result
