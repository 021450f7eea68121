// A triangle surface under local edits: the result surface's remeshing (remesh.h) and its
// coarsening for the CAD solid (step_coarsen.h) both work on it. It holds the connectivity only
// (triangles alive or removed, each triangle's tag, the live triangles around each point); the
// points stay with the caller, who decides where they are and whether an edit is wanted. The
// edits keep the surface manifold when their preconditions hold (link condition for a collapse,
// the new edge not there yet for a flip).
#pragma once
#include <array>
#include <vector>

#include "common/types.h"

namespace topopt::result {

class EditableSurface {
 public:
  using Tri = std::array<int, 3>;

  /// The surface F (#Q by 3 point indices below `points`) with tags `tag` (#Q); every triangle
  /// alive; the star of each point in triangle order.
  EditableSurface(const MatX3i& F, const VecXi& tag, long points);

  /// Number of triangles ever held (alive or not): the range of triangle indices.
  int triangles() const { return static_cast<int>(tris_.size()); }
  /// Number of points (those given and those added by split_edge).
  int points() const { return static_cast<int>(star_.size()); }
  const Tri& tri(int t) const { return tris_[t]; }
  int tag(int t) const { return tags_[t]; }
  bool alive(int t) const { return alive_[t] != 0; }
  /// The live triangles around point v, in the order they came to it.
  const std::vector<int>& star(int v) const { return star_[v]; }

  /// The live triangles with both points a and b (two on a manifold edge).
  std::vector<int> edge_triangles(int a, int b) const;
  /// The points joined to a by an edge, sorted.
  std::vector<int> neighbours(int a) const;
  /// The corner of triangle t that is neither a nor b (-1 if none).
  int third(int t, int a, int b) const;
  /// Link condition of edge ab: exactly two triangles share it and the points joined to both a
  /// and b are only their two opposite corners, so collapsing ab keeps the surface manifold.
  bool link_condition(int a, int b) const;

  /// Collapses v into u: the triangles on edge uv go, every other triangle of v takes u in its
  /// place (and joins u's star). Call only when link_condition(u, v) holds.
  void collapse(int v, int u);

  /// The flip of edge ab: its two triangles t1 (with the directed edge a→b) and t2, their
  /// opposite corners c (of t1) and d (of t2), and the two triangles that replace them,
  /// (a, d, c) and (d, b, c), which keep the orientation.
  struct Flip {
    int t1 = -1, t2 = -1, c = -1, d = -1;
    Tri u{}, w{};
  };
  /// The flip of edge ab when it is possible: two triangles of one tag share ab with opposite
  /// orientations, their opposite corners differ and are not joined by an edge yet. False else.
  bool flip_of(int a, int b, Flip& f) const;
  /// Applies a flip found by flip_of (a and b are its edge).
  void flip(int a, int b, const Flip& f);

  /// Splits edge ab at a new point (returned; the caller places it): each triangle (a, b, c) on
  /// the edge becomes (a, p, c) and (p, b, c), with the tag it had. The new triangles take new
  /// indices; the old ones are reused for the first halves.
  int split_edge(int a, int b);

  /// The live triangles (#Q' by 3) and their tags, with points renumbered by new_index (#P,
  /// -1 for points no live triangle uses) when it is given.
  void live(MatX3i& F, VecXi& tag, const std::vector<int>* new_index = nullptr) const;
  /// For each point, whether a live triangle uses it.
  std::vector<char> used_points() const;

 private:
  void drop(int v, int t);

  std::vector<Tri> tris_;
  std::vector<int> tags_;
  std::vector<char> alive_;
  std::vector<std::vector<int>> star_;
};

/// Twice the area times the unit normal of triangle t of points V (by its corners' order).
inline Eigen::Vector3d normal_of(const MatX3d& V, const EditableSurface::Tri& t) {
  const Eigen::Vector3d a = V.row(t[0]), b = V.row(t[1]), c = V.row(t[2]);
  return (b - a).cross(c - a);
}

}  // namespace topopt::result
