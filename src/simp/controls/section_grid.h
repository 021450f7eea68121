// The extrusion's section field (issue 22): a 2-D grid of nodes over the cross-section of a
// direction d, in the frame (u, v) of cross_section_basis(d). A field on the nodes gives every
// point the bilinear interpolation at its projection on the section, so it is constant along d by
// construction and continuous across. The extrusion's design variables live on these nodes
// (design_map.h), and the result is cut from node densities fitted on them
// (section_node_densities), so that both are one extruded shape on any mesh.
#pragma once
#include <Eigen/Sparse>

#include "common/types.h"

namespace topopt::simp {

class SectionGrid {
 public:
  /// points: #P by 3, the points the grid must cover (their projections lie inside it); d: the
  /// direction (unit); h: the node spacing (mm, > 0).
  SectionGrid(const Eigen::MatrixX3d& points, const Eigen::Vector3d& d, double h);
  /// Number of nodes #G (node (i, j) is i * #j + j).
  int num_nodes() const { return n_[0] * n_[1]; }
  /// #P by #G: the bilinear weights of each point's projection (clamped into the grid); every row
  /// holds at most four non-negative weights summing to 1. points: #P by 3.
  Eigen::SparseMatrix<double> interpolation(const Eigen::MatrixX3d& points) const;
  /// The point of node k at coordinate s along d.
  Eigen::Vector3d node_point(int k, double s) const;
  /// The up to four nodes next to node k along u and v.
  std::vector<int> neighbours(int k) const;

 private:
  Eigen::Vector3d u_, v_, d_;
  double h_ = 1;
  double lo_[2] = {0, 0};
  int n_[2] = {2, 2};
};

/// #V node densities for the result's cut under an extrusion along d (unit): the design tets'
/// densities fitted on a SectionGrid of spacing h over the design tets' nodes (each grid node the
/// mean of the densities of the design tets around it, weighted by volume × the bilinear weight of
/// their centroid's projection; a node no centroid reaches takes its neighbours' mean), then each
/// node of a design tet the section field at its projection — equal along d. Nodes of non-design
/// tets only keep base (#V, result::node_densities: 1). mesh: the tagged mesh; density: #T.
VecXd section_node_densities(const TetMesh& mesh, const VecXd& density, const VecXd& base, const Eigen::Vector3d& d,
                             double h);

}  // namespace topopt::simp
