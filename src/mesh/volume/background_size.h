// Graded volume size from a closed surface, and how many tets a size asks for.
//
// BackgroundSize: a uniform grid (cells of h/2, coarser if that would pass 20 M cells) holding
// at each cell centre min(h, s_i + g·d) over the boundary nodes' spacings s_i (the mean length
// of their edges), relaxed by a two-pass chamfer sweep and interpolated trilinearly. The
// volume front and the Delaunay bulk use it as their size when the caller gives none, so a
// region bounded by a fine surface part grows to the coarse size instead of keeping the
// finest edge throughout (or jumping to the full size in one layer).
//
// expected_tets: the number of tets a size function asks for inside a closed surface, from a
// grid of cell centres classified by the parity of crossings along z; the volume front stops
// with a named error when it makes many times that (a front that keeps shrinking its faces).
#pragma once
#include <array>
#include <functional>
#include <vector>

#include "common/types.h"

namespace topopt::mesh {

class BackgroundSize {
 public:
  /// V, F: the boundary (F's edges give the node spacings); h: the size far from it (also
  /// the cap); g: growth of the size per unit distance (0.3: 30 % per element length);
  /// seeds: more (x, y, z, size) points, e.g. the middle of thin walls (ModelSurface).
  BackgroundSize(const MatX3d& V, const MatX3i& F, double h, double g,
                 const std::vector<std::array<double, 4>>& seeds = {});
  double at(const double* x) const;  ///< trilinear between the cell centres

 private:
  double cell_;
  Eigen::Vector3d lo_;
  long n_[3];
  std::vector<float> size_;
};

/// The mean length of the edges of F (#F by 3) at each node of V (#V by 3), #V values, 0
/// where a node has none.
std::vector<double> node_spacing(const MatX3d& V, const MatX3i& F);
/// The same on nodes P and triangles F as the volume fill holds them.
std::vector<double> node_spacing(const std::vector<Eigen::Vector3d>& P, const std::vector<std::array<int, 3>>& F);

/// About how many tets a mesh with edge length size(x) has inside the closed surface (V, F):
/// Σ cell volume × 6√2 / size³ over ~`cells` grid cells whose centres are inside.
double expected_tets(const MatX3d& V, const MatX3i& F, const std::function<double(const double*)>& size,
                     long cells = 1'000'000);

}  // namespace topopt::mesh
