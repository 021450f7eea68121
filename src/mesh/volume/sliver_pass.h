// The last sliver pass, on any finished tagged tet mesh (TetMesh): the fills' improvement
// (tet_improve.h) never moves a node of the boundary or of the interface between Ω0 and Ω̄,
// so a sliver whose nodes are all there stays. This pass also moves such a node, but only
// within its plane: a node whose boundary (or interface) triangles all lie in one plane and
// on one face (the same B-Rep face and load-pad face, or the same pair of domains) slides in
// that plane, so every face keeps its place and every domain its volume; a node of one curved
// B-Rep face of Ω slides on it when the caller gives the projection onto the face (the volume
// then changes by the faceting's change only); free nodes move anywhere. Every move keeps each tet of the node's ball positive (exact orientation) and is
// kept only when it lifts the ball's worst radius ratio without leaving more of the ball
// below the floor; after the moves, edge removal, 2-3 flips and cavity refills within each
// domain.
#pragma once
#include <functional>
#include <vector>

#include "common/types.h"

namespace topopt::mesh {

/// How a node of a finished mesh may move.
enum class NodeFreedom : char {
  Free,   ///< inside one domain: anywhere
  Plane,  ///< on one planar face (boundary or interface): within its plane
  Curved, ///< on one curved face of Ω's boundary: on it, through SliverPassParams::onto_face
  Fixed,  ///< on an edge, a vertex, a curved face or between faces: never
};

struct SliverPassParams {
  double floor = 0.1;  ///< tets below this radius ratio are worked on
  int rounds = 4;      ///< at most this many rounds of moves and flips, while the count falls
  /// A node's face triangles are one plane when every node of them lies within this share of
  /// its distance from the node off the plane of the largest of them.
  double plane_tolerance = 1e-9;
  /// Moves x onto Ω's B-Rep face `face` (1-based, TetMesh::face's numbering): the nearest point
  /// of its surface; false when there is none. Empty: nodes of curved faces never move.
  std::function<bool(int face, Eigen::Vector3d& x)> onto_face;
  /// After the flips and refills, the slivers still below floor that have a node on the
  /// boundary or an interface get that node's ball (within its domain) re-filled from a new
  /// inner point: the node keeps its place and its faces, the new point takes its inner edges.
  bool split_boundary_nodes = true;
};

struct SliverPassReport {
  long below_before = 0, below_after = 0;  ///< tets below floor
  double worst_before = 0, worst_after = 0;
  long moved_free = 0, moved_plane = 0, moved_curved = 0;  ///< node moves made, by the node's freedom
  long flips = 0;  ///< edge removals, 2-3 flips, cavities re-filled and boundary nodes split
};

/// The pass: the tets of `mesh` below params.floor, worst first, each of their movable nodes
/// moved (pattern search in space, in the plane, or in the tangent plane and back onto the face) when that lifts the worst tet of its
/// ball and leaves no more of it below floor; then edge removal and 2-3 flips at what is left
/// and wider cavities re-filled from one point (tet_improve's remove_tets_below), then the balls
/// of their boundary and interface nodes re-filled from a new inner point (node splits), within each
/// domain (the boundary and the interfaces stay faces); rounds while the count falls. mesh.F, face, nd_face and domain are unchanged (flips may reorder tets of a domain
/// that changed; domain follows). Returns what it did.
SliverPassReport remove_final_slivers(TetMesh& mesh, const SliverPassParams& params = {});

}  // namespace topopt::mesh
