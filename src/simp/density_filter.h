// Density and sensitivity filters on an unstructured tet mesh (radius in mm), built once:
// the neighbour weights of every design element are kept as a sparse matrix.
#pragma once
#include <Eigen/Sparse>

#include "common/types.h"

namespace topopt::simp {

enum class FilterKind {
  Gaussian,  ///< w = exp(−d²/(2σ²)), σ = r/3, cut at d = r (the seed paper's choice)
  Cone       ///< w = max(0, r − d) (top88's linear weights)
};

struct FilterParams {
  FilterKind kind = FilterKind::Gaussian;
  double radius = 0;  ///< mm; <= 0 means no filtering (identity)
  int threads = 0;
};

/// A filter over the design elements (domain == 0) only; non-design elements keep ρ = 1
/// and neither give to nor take from their neighbours.
class DensityFilter {
 public:
  /// mesh: the tagged mesh; design: #D indices of the design tets in mesh.T (the order of the
  /// design variables); volume: #T element volumes.
  DensityFilter(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volume, const FilterParams& params);

  /// ρ̃ = H x: x and the result are #D. Weighted by w_ij v_j and normalised per row.
  VecXd apply(const VecXd& x) const;
  /// Chain rule of apply: given dF/dρ̃ (#D) returns dF/dx = Hᵀ g.
  VecXd apply_transpose(const VecXd& g) const;
  /// Sigmund's sensitivity filter: Σ_j w_ij x_j g_j / (max(1e-3, x_i) Σ_j w_ij).
  VecXd filter_sensitivity(const VecXd& x, const VecXd& g) const;
  /// Average number of neighbours per element (for logs and tests).
  double mean_neighbours() const;

 private:
  Eigen::SparseMatrix<double, Eigen::RowMajor> H_;  // normalised, with volumes
  Eigen::SparseMatrix<double, Eigen::RowMajor> W_;  // raw weights (sensitivity filter)
};

/// #T element volumes (positive for positively oriented tets).
VecXd tet_volumes(const TetMesh& mesh);
/// #T by 3 element centroids.
MatX3d tet_centroids(const TetMesh& mesh);

}  // namespace topopt::simp
