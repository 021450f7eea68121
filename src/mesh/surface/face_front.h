// 2D advancing front for (partially meshed) faces, in the plane of the face's parameters:
// the engine of steps 9 and 11 of the two-B-Rep method (DESIGN.md). The front starts from
// the face's boundary segments plus the free edges of triangles already on the face; an
// isolated segment enters as two opposite half-edges and an isolated node as a front node
// without edges, so the front may be non-manifold. Every orientation decision goes through
// the exact predicates; pre-placed triangles, boundary segments and isolated entities are
// never changed.
//
// The engine in three parts (DESIGN.md), in face_front.cpp: the container `FaceFront`
// (directed edges with the unmeshed region on their left, the nodes that may still take
// triangles, and for the searches a spatial grid over each, mesh/core/spatial_grid.h; named
// apart from the 3D front of mesh/volume), the geometry of candidates (`Reach`: the ideal apex
// from the size field, the search radius and quality bound of the pass), and the driver
// `FaceFill`: take the shortest front edge, gather candidates, accept the first valid
// triangle, update the front; edges that fail are retried later with a wider search and a
// lower quality bound. fill_face() below runs it, then Delaunay flips and smoothing of the new
// nodes.
#pragma once
#include <functional>
#include <vector>

#include "common/progress.h"
#include "common/types.h"

namespace topopt::mesh {

struct FaceFrontParams {
  /// Target edge length at a point (u, v); empty: the mean length of the front's edges.
  std::function<double(const double*)> size;
  int passes = 5;  ///< rounds over edges that failed, each wider and less strict
  long max_triangles = 20'000'000;
  int flip_sweeps = 8;           ///< Delaunay flip sweeps over the new triangles
  int smoothing_iterations = 4;  ///< Laplacian sweeps over the new nodes (never invert)
};

/// What is already on the face. Triangles and boundary segments are oriented so that the
/// region to mesh lies to the LEFT of a boundary segment (outer loop counter-clockwise, holes
/// clockwise) and triangles are counter-clockwise.
struct FaceFrontInput {
  MatX2d P;                   ///< #P by 2: every given point (boundary, pre-placed, isolated)
  MatX2i boundary;            ///< #B by 2 directed boundary segments
  MatX3i triangles;           ///< #K by 3 pre-placed triangles (kept)
  MatX2i segments;            ///< #S by 2 isolated segments inside the region (kept as edges)
  std::vector<int> isolated;  ///< nodes that must become vertices of the mesh
};

struct FaceFrontResult {
  MatX2d P;  ///< #P' by 2: the input points (same indices) then the new ones
  MatX3i T;  ///< the new triangles only, counter-clockwise
};

/// Meshes the part of the region not covered by the pre-placed triangles. Together, the
/// pre-placed and the new triangles tile the region conformally: every input segment and
/// every pre-placed triangle edge is an edge of the result, every isolated node a vertex.
/// Throws Error(MeshingFailed) saying where the front could not be closed, and
/// Error(InvalidParameter) for inconsistent input (an open boundary).
FaceFrontResult fill_face(const FaceFrontInput& input, const FaceFrontParams& params = {},
                          const Progress& progress = {});

}  // namespace topopt::mesh
