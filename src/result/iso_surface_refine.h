// The result surface at a resolution of its own: the design tets the iso-level cuts (and their
// face neighbours) subdivided once, 1 -> 8, the mesh kept conformal around them, and the node
// densities at the new points interpolated to higher order, so that marching tetrahedra
// (iso_surface.h) on the finer mesh follows the density field more closely than the FE mesh.
#pragma once
#include "result/iso_surface.h"

namespace topopt::result {

/// A tet mesh finer than the FE mesh near the level, with node densities on it.
struct RefinedField {
  TetMesh mesh;        ///< conformal, positively oriented, domain tags and Ω's face tags carried over
  VecXd node_density;  ///< #V of `mesh`: the input's node densities at the input's nodes, interpolated elsewhere
  long refined = 0;    ///< input tets split 1 -> 8 (red)
  long closed = 0;     ///< input tets with some split edges, filled from their centre (the closure)
};

/// Refines `mesh` for the iso-surface at `threshold` of the node densities (#V, node_densities):
/// every design tet whose nodes lie on both sides of the level, and every design tet sharing a
/// face with one, is split into eight at its edge midpoints (the inner octahedron along its
/// shortest diagonal). A tet with only some of its edges split (a neighbour across an edge) is
/// filled conformally: each of its faces is triangulated the same way from both sides (four
/// triangles when all three edges are split, else fanned from the face's centre) and coned to
/// the tet's centre, so the refined mesh has no hanging nodes and marching tetrahedra on it gives
/// a closed surface. The density at an edge midpoint is the cubic Hermite interpolant along the
/// edge from the two node values and the nodes' gradients (the volume-weighted mean of the
/// linear field's gradients in the design tets around each node), clamped to [0, 1]; at face
/// and tet centres it is the mean of the corner values. Ω's boundary triangles (F, face, nd_face)
/// are subdivided with their faces, orientation and tags kept, so Ω's faces stay where they were.
RefinedField refine_near_level(const TetMesh& mesh, const VecXd& node_density, double threshold);

}  // namespace topopt::result
