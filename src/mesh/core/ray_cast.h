// Rays against a triangle soup: a bounding-volume hierarchy (axis-aligned boxes, median
// splits, at most 4 triangles a leaf) and the Möller–Trumbore test. The surface mesher casts a
// ray inward from each triangle of a coarse tessellation to measure the wall thickness there.
#pragma once
#include <vector>

#include "common/types.h"

namespace topopt::mesh {

class TriangleRays {
 public:
  TriangleRays(const MatX3d& V, const MatX3i& F);
  /// Distance along the unit direction d from o to the nearest triangle other than `skip`
  /// hit at a distance in (0, tmax]; tmax if none.
  double first_hit(const double* o, const double* d, long skip, double tmax) const;

 private:
  struct Node {
    double lo[3], hi[3];
    int left = -1, right = -1;  // children; -1: a leaf holding items_[first, first + count)
    int first = 0, count = 0;
  };
  int build(int first, int count, int depth);
  const MatX3d& V_;
  const MatX3i& F_;
  std::vector<int> items_;
  std::vector<Node> nodes_;
};

}  // namespace topopt::mesh
