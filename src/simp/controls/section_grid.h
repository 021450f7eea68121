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

/// The node spacing (mm) of an extrusion's section grid for the controls' tolerance (mm, > 0: a
/// mean edge by default): half of it, so the section is drawn finer than the mesh (columns one
/// tolerance wide drew it in squares that coarse, branch repeat23).
inline double section_spacing(double tolerance) { return tolerance / 2; }

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
  /// The node spacing h (mm).
  double spacing() const { return h_; }
  /// The point of node k at coordinate s along d.
  Eigen::Vector3d node_point(int k, double s) const;
  /// The up to four nodes next to node k along u and v.
  std::vector<int> neighbours(int k) const;
  /// The value at p's projection of the field g (#G, bilinear; clamped into the grid); with
  /// `gradient`, its gradient in the section plane there (a 3-vector normal to d).
  double value(const VecXd& g, const Eigen::Vector3d& p, Eigen::Vector3d* gradient = nullptr) const;

 private:
  /// The cell (i, j) of p's projection, clamped into the grid, and p's place in it (f in [0, 1]²).
  void locate(const Eigen::Vector3d& p, int i[2], double f[2]) const;

  Eigen::Vector3d u_, v_, d_;
  double h_ = 1;
  double lo_[2] = {0, 0};
  int n_[2] = {2, 2};
};

/// A field on a section grid's nodes.
struct SectionField {
  SectionGrid grid;
  VecXd g;  ///< #G node values
};

/// The design tets' densities (density: #T) fitted on a SectionGrid of spacing h (mm) along d
/// (unit) over the design tets' nodes: each grid node the mean of the densities of the design
/// tets around it, weighted by volume × the bilinear weight of their centroid's projection; a
/// node no centroid reaches takes its neighbours' mean.
SectionField fit_section_field(const TetMesh& mesh, const VecXd& density, const Eigen::Vector3d& d, double h);

/// Moves the free points (lock 0) of a surface cut at level t from section_node_densities of `field` onto the
/// level curve of the section field itself: Newton steps in the section plane (each at most a grid
/// spacing, three at most), so that the cut's points lie on one extruded surface whatever the
/// tets' orientation (the linear crossings on tet edges wander along d by the interpolation's
/// error). V: #P by 3 (moved in place); lock: #P.
void snap_to_section_level(const SectionField& field, double t, MatX3d& V, const VecXi& lock);

/// #V node densities for the result's cut under an extrusion: each node of a design tet the
/// section field (fit_section_field of the design's densities) at its projection — equal along
/// the direction. Nodes of non-design tets only keep base (#V, result::node_densities: 1).
/// mesh: the tagged mesh the field was fitted on.
VecXd section_node_densities(const TetMesh& mesh, const SectionField& field, const VecXd& base);

}  // namespace topopt::simp
