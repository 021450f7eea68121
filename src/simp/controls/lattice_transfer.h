// Transfer between the tets and an intermediate structured lattice of nodes that need not be
// aligned with the mesh (issue 22, the overhang control's grid). Lattice node (i, j, k) sits at
// (i·s₀, j·s₁, k·s₂) in the lattice's own coordinates (the caller's frame, shifted to node 0).
//
// Element → lattice: a node takes the volume-weighted mean of the elements whose centroid lies
// in its dual cell (the box of the lattice spacing around it); a node whose dual cell holds no
// centroid takes the element with the nearest centroid in the 3 × 3 × 3 neighbouring dual cells;
// a node with none there is inactive (outside the mesh). Every element reaches the lattice and
// no active node is empty, whatever the ratio of element size to spacing and however the
// lattice is turned against the mesh (assigning elements to cells by centroid alone leaves
// empty cells inside the part on a turned lattice: a hole in every column through them).
// Lattice → element: trilinear interpolation at the element's centroid over the active corners
// of its lattice cell, the weights renormalised (a wall element does not blend with the void
// outside the part). Both maps are linear (plus a constant for the elements of fixed density
// 1, the non-design solids), stored as sparse matrices.
#pragma once
#include <Eigen/Sparse>
#include <array>
#include <vector>

#include "common/types.h"

namespace topopt::simp {

class LatticeTransfer {
 public:
  /// local: #E by 3 element centroids in lattice coordinates (node (0,0,0) at the origin);
  /// volumes: #E element volumes (> 0); variable: #E, the index of each element in the field
  /// that to_grid reads (#D entries, 0 … num_variables−1), or −1 for an element of fixed
  /// density 1; spacing: the lattice spacing along the three axes (mm, > 0); n: nodes per axis
  /// (each >= 2; the nodes must cover every centroid).
  LatticeTransfer(const Eigen::MatrixX3d& local, const VecXd& volumes, const std::vector<int>& variable,
                  int num_variables, const Eigen::Vector3d& spacing, const std::array<int, 3>& n);

  /// Number of nodes #G = n₀ n₁ n₂; node (i, j, k) is (k n₁ + j) n₀ + i (a layer k is one block).
  long num_nodes() const { return static_cast<long>(n_[0]) * n_[1] * n_[2]; }
  int nodes_along(int axis) const { return n_[axis]; }
  /// #G: the lattice values of the element field z (#D): P z + c, 0 at inactive nodes.
  VecXd to_grid(const VecXd& z) const { return to_grid_ * z + fixed_; }
  /// #D: the element values of lattice values g (#G).
  VecXd to_elements(const VecXd& g) const { return to_elements_ * g; }
  /// Transposes of the linear parts (chain rule): #D of #G, and #G of #D.
  VecXd to_grid_transpose(const VecXd& g) const { return to_grid_.transpose() * g; }
  VecXd to_elements_transpose(const VecXd& z) const { return to_elements_.transpose() * z; }
  /// #G: the share of each node's value that comes from the elements of fixed density.
  const VecXd& fixed_share() const { return fixed_; }
  /// #G: 1 for the nodes that some element reaches.
  const std::vector<char>& active() const { return active_; }
  /// #G by 3: where a node's variable elements lie against its fixed ones, in lattice
  /// coordinates: the volume-weighted mean centroid of the variable elements in its dual cell
  /// minus that of the fixed elements there (0 unless the dual cell holds both kinds).
  const Eigen::MatrixX3d& variable_offset() const { return offset_; }

 private:
  std::array<int, 3> n_;
  Eigen::SparseMatrix<double> to_grid_;      // #G by #D
  Eigen::SparseMatrix<double> to_elements_;  // #D by #G
  VecXd fixed_;                              // #G: the fixed elements' share
  Eigen::MatrixX3d offset_;                  // #G by 3: see variable_offset()
  std::vector<char> active_;
  void build_to_grid(const Eigen::MatrixX3d& local, const VecXd& volumes, const std::vector<int>& variable,
                     int num_variables, const Eigen::Vector3d& spacing);
  void build_to_elements(const Eigen::MatrixX3d& local, const std::vector<int>& variable, int num_variables,
                         const Eigen::Vector3d& spacing);
};

}  // namespace topopt::simp
