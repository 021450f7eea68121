// Size fields that grow away from fine points at the gradation rate, over a face's scaled
// parameter plane: the size at q is min(cap, s_i + grade·|q − p_i|) over points (u_i, v_i, s_i).
// Two ways to the same field: PointSizeField evaluates it exactly from the points near q (the
// face fill's and the edges' size near fine boundary pieces), SizeRaster precomputes it on a
// grid by a chamfer transform (the wall-thickness points, many of them, read often).
#pragma once
#include <array>
#include <vector>

#include "mesh/core/spatial_grid.h"

namespace topopt::mesh {

/// The exact field min(h, s_i + grade·|q − p_i|), the points looked up in a SpatialGrid
/// (mesh/core/spatial_grid.h) whose cells are as large as the reach of a point (where
/// s_i + grade·d reaches the largest size h), so a query visits at most 3 x 3 cells.
class PointSizeField {
 public:
  /// pts: (u, v, s) per point, s > 0; h: the size with no point near (the field's cap);
  /// grade: how much the size grows per unit of distance (gradation − 1).
  PointSizeField(std::vector<std::array<double, 3>> pts, double h, double grade);
  /// min(h, s_i + grade·|q − p_i|) over the points; q: (u, v). `h` may be below the
  /// construction's cap (never above it: points farther than the cap's reach are not seen).
  double size_at(const double* q, double h) const;

 private:
  static SpatialGrid<2> index(const std::vector<std::array<double, 3>>& pts, double reach);
  std::vector<std::array<double, 3>> pts_;
  double grade_, reach_;
  SpatialGrid<2> grid_;
};

/// The same field on a grid: min(cap, s_i + grade·distance) by a chamfer transform (two
/// sweeps, 8 neighbours; exact in the cells around each point), read bilinearly. Cells of half
/// the smallest size, at most 512 a side; cap outside the grid. Empty points: cap everywhere.
class SizeRaster {
 public:
  SizeRaster() = default;
  /// pts: (u, v, s) per point; cap: the largest size; grade: growth per unit of distance.
  SizeRaster(const std::vector<std::array<double, 3>>& pts, double cap, double grade);
  /// min(h, the field at q); q: (u, v).
  double size_at(const double* q, double h) const;
  /// No points: the field is the cap everywhere.
  bool empty() const { return v_.empty(); }
  /// The smallest size of the field (the cap when empty).
  double smallest() const { return smallest_; }

 private:
  void chamfer(float straight, float diagonal);
  double cap_ = 0, smallest_ = 0, cell_ = 1, lo_[2] = {0, 0};
  long nx_ = 0, ny_ = 0;
  std::vector<float> v_;
};

/// The sources of a face's graded size: boundary nodes whose spacing (mean length of their
/// segments) is below 0.7 h, as (u, v, spacing). uv: the nodes' (u, v); segs: node pairs.
std::vector<std::array<double, 3>> fine_points(const std::vector<std::array<double, 2>>& uv,
                                               const std::vector<std::array<int, 2>>& segs, double h);

}  // namespace topopt::mesh
