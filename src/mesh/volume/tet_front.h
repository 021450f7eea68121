// The 3D front of the volume fill: the oriented triangles from which tets grow, with their
// spatial search (mesh/core/spatial_grid.h) and the one test every new tet passes — does it
// cross the front? Exact: every decision goes through mesh/core/predicates.
//
// A front face (a, b, c) faces the unfilled region (its normal, by the right-hand rule, points
// into it); a tet grown from it has a fourth node p on that side. Adding a face whose opposite
// twin is on the front closes both. Faces are numbered in the order they are added; a killed
// face keeps its number (the driver's queue holds numbers).
#pragma once
#include <array>
#include <unordered_map>
#include <vector>

#include "common/face_key.h"
#include "common/types.h"
#include "mesh/core/spatial_grid.h"
#include "mesh/volume/node_stars.h"

namespace topopt::mesh {

class TetFront {
 public:
  /// P: the nodes (#P, grown by the caller as it adds points; read, never changed here);
  /// cell: the finest grid level's cell (the shortest edge); origin: a corner of the region.
  TetFront(const std::vector<Eigen::Vector3d>& P, double cell, const Eigen::Vector3d& origin);

  /// Adds face (a, b, c); returns its number, or -1 when its opposite was on the front (both
  /// close: the opposite is killed).
  int add_face(int a, int b, int c);
  void kill(int id);  ///< removes face `id` from the front (no-op when already dead)
  /// Puts the faces of tet t back on the front, facing into t (t is being removed).
  void reopen(const Tet& t);
  /// The tet (face f, p): appended to tets; f leaves the front and the tet's three other faces
  /// join it. Returns their numbers (-1 for a face that closed against its opposite).
  std::array<int, 3> close_with(int f, int p, std::vector<Tet>& tets);

  bool alive(int id) const { return alive_[id]; }       ///< face `id` is on the front
  const Tri& face(int id) const { return faces_[id]; }  ///< its nodes (also once dead)
  long size() const { return count_; }                  ///< live faces
  size_t capacity() const { return faces_.size(); }     ///< faces ever added (live or not)
  std::vector<int> alive_faces() const;                 ///< the live faces' numbers, ascending
  int any_alive() const;                                ///< a live face, or -1
  bool active(int v) const { return v < static_cast<int>(active_.size()) && active_[v] > 0; }

  /// Live faces whose boxes may meet [lo, hi] (out is cleared first).
  void faces_near(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, std::vector<int>& out);
  /// Active front nodes (corners of live faces) in cells meeting [lo, hi] (out cleared).
  void nodes_near(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, std::vector<int>& out);

  /// Would tet (a, b, c, p), grown from front face `self` = (a, b, c), be valid: positive, of
  /// radius ratio >= qmin, its new edges crossing no front face, the front's edges crossing
  /// none of its new faces (an edge of a face it closes against excepted), and no front node
  /// inside it or on it?
  bool admits(int a, int b, int c, int p, double qmin, int self);

 private:
  const std::vector<Eigen::Vector3d>& P_;
  std::vector<Tri> faces_;
  std::vector<char> alive_;
  std::unordered_map<FaceKey, int, FaceKeyHash> index_;  ///< live faces by their sorted key
  std::vector<int> active_;                              ///< live faces at each node
  std::vector<char> in_grid_;                            ///< node registered in nodes_grid_
  SpatialGrid<3> faces_grid_, nodes_grid_;
  long count_ = 0;
  std::vector<int> near_faces_;  ///< admits()' scratch
  std::vector<unsigned> seen_node_;
  unsigned seen_ticket_ = 0;
};

/// Does segment (u, v) meet triangle (x, y, z) of P anywhere other than at a shared vertex?
/// Exact; touching counts as meeting (conservative), coplanar configurations too unless the
/// segment shares a vertex with the triangle and leaves it outside.
bool segment_meets_triangle(const std::vector<Eigen::Vector3d>& P, int u, int v, int x, int y, int z);

}  // namespace topopt::mesh
