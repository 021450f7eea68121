// Local optimisation of a face's triangles judged in 3D (issue 3, "local optimisation on the
// surface"): the face front works in scaled parameters, which are only an approximation of
// lengths on a curved surface, so the triangles are improved afterwards by their angles on
// the surface itself. SurfaceOptimizer holds a face's mesh with what the surface says at each
// node, and offers the operations one by one; optimize_on_surface() runs them in rounds:
// - edge flips that raise the smaller angle of the pair (flip_edges);
// - edge collapses (a node removed onto a neighbour, the survivor placed by a compass search)
//   for edges much shorter than their triangles' others (needles where fronts met) and around
//   triangles below 20° (a node squeezed against a boundary segment), kept when the region's
//   smallest angle rises by 1° (collapse_edges);
// - smoothing that moves a node towards the centre of its neighbours in space and back onto
//   the face through its parameters (one Gauss-Newton step), kept when the star's smallest
//   angle rises or its angles improve on the whole with the smallest staying above
//   min(before, 30°) (smooth_nodes); then a compass search on the nodes of triangles below 40°
//   (compass_search_nodes);
// - last, splits of the inner edge of triangles whose corners may not move (all on the
//   boundary), kept when the four new triangles' smallest angle rises and no more of them
//   are below 20° (split_fixed_triangles).
// Every change is checked in the parameter plane with the exact orient2d, so the face's
// triangulation stays valid there; nodes below `fixed` (boundary, isolated, pre-placed) never
// move; constrained edges never flip and their ends are never removed (they may move: the
// neighbours of a cone's apex). Triangles with two corners at one point (the strip of a
// degenerate edge) are judged in the parameters only.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "common/types.h"
#include "mesh/surface/triangle_stars.h"

namespace topopt::mesh {

/// Evaluates the face at parameters uv: the point X and the derivatives along the two
/// parameters (each a 3-vector).
using SurfaceEval = std::function<void(const double* uv, double* X, double* Xu, double* Xv)>;

struct SurfaceOptimizeStats {
  long flips = 0, moves = 0, collapses = 0, splits = 0;
  double min_angle_before = 0, min_angle_after = 0;  ///< degrees, over the triangles
};

/// A face's triangles under improvement on the surface, with each node's point, derivatives
/// and normal kept up to date. Every operation changes (P, T, X) in place and returns how many
/// changes it kept; nodes below `fixed` never move.
class SurfaceOptimizer {
 public:
  /// P: #P by 2 node parameters (splits append rows; collapses leave rows unused). T: #T by 3
  /// counter-clockwise triangles in the parameters. X: receives #P by 3 points on the surface.
  /// fixed: nodes 0..fixed-1 never move nor go. eval: the surface at parameters. constrained:
  /// node pairs (either order) whose edges never flip; their ends are never removed.
  SurfaceOptimizer(MatX2d& P, MatX3i& T, MatX3d& X, int fixed, const SurfaceEval& eval,
                   const std::vector<std::array<int, 2>>& constrained);

  /// Smallest angle (degrees) over the triangles on the surface (180 for none).
  double smallest_angle() const;
  /// Flips every inner edge whose flip keeps both triangles counter-clockwise in the
  /// parameters and facing out, and raises the pair's smallest angle by more than 0.5°; sweeps
  /// until one flips nothing (at most 6 sweeps). Returns the number of flips.
  long flip_edges();
  /// One sweep of collapses: per triangle, its shortest edge when clearly shorter than the
  /// others (≤ 0.7 of both), and for a triangle below 20° each of its edges, then each movable
  /// corner onto each neighbour, nearest first. A collapse is kept when the region's smallest
  /// angle rises by min(1°, a quarter of itself). Compacts T. Returns the number of collapses.
  long collapse_edges();
  /// One sweep of smoothing over the movable nodes: towards their neighbours' centre in space,
  /// back onto the surface by one Gauss-Newton step, at steps 1, 1/2, 1/4 of that move. Returns
  /// the number of nodes moved.
  long smooth_nodes();
  /// A compass search (compass_node) on every movable corner of the triangles below 40°.
  /// Returns the number of nodes moved.
  long compass_search_nodes();
  /// Splits the longest edge of triangles below 40° whose three corners may not move, when that
  /// edge is inside the face: a new node at its middle placed by the compass search, kept when
  /// the four triangles' smallest angle rises by over 0.5° and no more of them are below 20°.
  /// Appends the new nodes to P and X, the new triangles to T. Returns the number of splits.
  long split_fixed_triangles();

 private:
  /// A node's position with what evaluate() derived from it, to put back a failed move.
  struct NodeState {
    Eigen::RowVector2d p;
    Eigen::RowVector3d x, n;
    Eigen::Vector3d u, v;
  };
  /// What a tried collapse changed, to keep or undo it.
  struct Collapse {
    std::vector<int> na, nb, region, live;  ///< neighbours of a and b; triangles touched; kept
    std::vector<Eigen::RowVector3i> saved;  ///< region's rows before
  };
  using EdgeTriangles = std::unordered_map<uint64_t, std::array<int, 2>>;

  void evaluate(long i);
  NodeState save(long i) const;
  void restore(long i, const NodeState& s);
  double triangle_angle(long t) const;
  double worst_of(const int* begin, const int* end) const;
  EdgeTriangles edge_triangles() const;
  bool try_flip(uint64_t key, int t0, int t1);
  bool smooth_node(long i, const TriangleStars& star, std::vector<int>& nbr);
  double compass_node(int i, const int* begin, const int* end, bool& moved);
  bool collapse_around(int t0, const TriangleStars& star, std::vector<int>& around);
  bool try_collapse(int a, int b, const TriangleStars& star);
  bool collapse_allowed(int a, int b, const TriangleStars& star);
  double place_survivor(int a, const Eigen::RowVector2d& pa, const Eigen::RowVector2d& pb);
  void undo_collapse(int a, const NodeState& old_a);
  void commit_collapse(int a, int b);
  void drop_dead_triangles();
  bool try_split(int t0, const EdgeTriangles& edge_tris, std::vector<char>& touched);
  void resize_nodes(long rows);

  MatX2d& P_;
  MatX3i& T_;
  MatX3d& X_;
  MatX3d N_;  ///< #P by 3 unit normals, in the parameters' orientation (Xu × Xv)
  std::vector<Eigen::Vector3d> Xu_, Xv_;
  const SurfaceEval eval_;
  const long fixed_;
  long n_, nt_;                          ///< nodes and triangles in use (rows of P and T)
  std::unordered_set<uint64_t> locked_;  ///< constrained edges (undirected keys)
  std::vector<char> keep_node_;          ///< #P: may not move nor go (below `fixed`)
  std::vector<char> pinned_;             ///< #P: an end of a constrained edge
  std::vector<char> dead_;               ///< #T: removed by a collapse, dropped at the sweep's end
  std::vector<char> busy_;               ///< #P: touched by a collapse in this sweep
  Collapse collapse_;
};

/// Improves (P, T) in place (splits add nodes to P, collapses leave unused ones); X receives
/// the 3D points of every node of P (rows of P). Runs `rounds` rounds of flips, collapses and
/// smoothing, flips, then min(rounds, 2) rounds of compass searches, flips and collapses, then
/// (rounds > 0) the splits and a last flip sweep. See SurfaceOptimizer for the arguments.
SurfaceOptimizeStats optimize_on_surface(MatX2d& P, MatX3i& T, MatX3d& X, int fixed, const SurfaceEval& eval,
                                         const std::vector<std::array<int, 2>>& constrained = {}, int rounds = 3);

}  // namespace topopt::mesh
