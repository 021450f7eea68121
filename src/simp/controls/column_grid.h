// The intermediate structured grid of the draw-direction control (issue 22): cells of side h
// in a frame (u, v, d) whose third axis is a given direction, so that each (u, v) column of
// cells is a line of layers along d. Element densities go to the grid as the volume-weighted
// mean of the elements whose centroid lies in a cell, and come back as the value of the cell
// that holds each element's centroid; both maps are linear, stored as sparse matrices.
#pragma once
#include <Eigen/Sparse>
#include <vector>

#include "common/types.h"

namespace topopt::simp {

class ColumnGrid {
 public:
  /// centroids: #D by 3 element centroids; volumes: #D element volumes (> 0); d: the column
  /// direction (unit); h: the cell side (mm, > 0). The grid spans the centroids' box in the
  /// frame (u, v, d), starting at `origin` projected into the frame when `origin_set`,
  /// otherwise at the smallest coordinates (cell faces then pass through origin + multiples of h).
  ColumnGrid(const Eigen::MatrixX3d& centroids, const VecXd& volumes, const Eigen::Vector3d& d, double h,
             const Eigen::Vector3d& origin = Eigen::Vector3d::Zero(), bool origin_set = false);

  /// Number of columns (#C) and of layers along d in each (#K); cells are #C × #K, the cell of
  /// column c and layer k is c * #K + k.
  int num_columns() const { return num_columns_; }
  int num_layers() const { return num_layers_; }
  /// The layer index of the coordinate s along d (clamped to [0, #K)).
  int layer_of(double s) const;
  /// Coordinate along d of the grid's lower end (layer 0's lower face).
  double start() const { return start_; }
  /// #cells: the grid values of element values z (#D): volume-weighted means, 0 in empty cells.
  VecXd to_grid(const VecXd& z) const { return to_grid_ * z; }
  /// #D: the element values of grid values g (#cells): each element the value of its cell.
  VecXd to_elements(const VecXd& g) const { return to_elements_ * g; }
  /// Transposes of the two maps (for the chain rule): #D of #cells, and #cells of #D.
  VecXd to_grid_transpose(const VecXd& g) const { return to_grid_.transpose() * g; }
  VecXd to_elements_transpose(const VecXd& z) const { return to_elements_.transpose() * z; }
  /// #cells: true for the cells that hold at least one element centroid.
  const std::vector<char>& occupied() const { return occupied_; }

 private:
  int num_columns_ = 0, num_layers_ = 0;
  double start_ = 0, h_ = 1;
  Eigen::SparseMatrix<double> to_grid_;      // #cells by #D
  Eigen::SparseMatrix<double> to_elements_;  // #D by #cells
  std::vector<char> occupied_;
};

}  // namespace topopt::simp
