// The remesher's check, edit by edit, that the surface does not cross itself: a uniform grid of the
// live triangles of an EditableSurface, asked whether the triangles an edit would make cross one
// another or any live triangle the edit keeps (exact, as mesh::self_intersections decides).
#pragma once
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "result/editable_surface.h"

namespace topopt::result {

class CrossingGuard {
 public:
  using Tri = EditableSurface::Tri;

  /// Registers every live triangle of m, its points in V (#P by 3, held by reference: the caller
  /// moves and adds points in it). Cells about two mean edges wide.
  CrossingGuard(const MatX3d& V, const EditableSurface& m);

  /// Registers triangle t of m under the box its points have now; call after an edit changed or
  /// made it (a stale registration is harmless: queries test the triangles' current boxes).
  void add(int t);

  /// Whether triangles `tris` (point triples of V) cross one another or a live triangle of m that
  /// is not in `replaced` (the triangles the edit removes or changes): a zero-area triangle, or two
  /// triangles meeting other than along what they share (mesh::triangles_cross).
  bool crosses(const std::vector<Tri>& tris, const std::vector<int>& replaced) const;

 private:
  uint64_t key(long i, long j, long k) const;
  void cells_of(const Tri& t, long lo[3], long hi[3]) const;

  const MatX3d& V_;
  const EditableSurface& m_;
  Eigen::RowVector3d origin_;
  double cell_ = 1;
  std::unordered_map<uint64_t, std::vector<int>> cells_;
  mutable std::vector<int> seen_;  ///< per triangle: the query that last tested it
  mutable int query_ = 0;
};

}  // namespace topopt::result
