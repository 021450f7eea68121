// The explicit density filter on an unstructured tet mesh (radius in mm), built once: the
// weights w_ij of every pair of design elements whose centroids lie within the radius, held
// once as the upper triangle of the symmetric sparse matrix W (j >= i: 12 bytes a stored
// entry, about 6 a pair; the full matrix took twice that, 0.4 GB per million tets at the
// automatic radius). The filter is
//     ρ̃_i = Σ_j w_ij v_j x_j / Σ_j w_ij v_j,
// so F = S⁻¹ W V with S the row sums of W V and V the volumes; Fᵀ = V W S⁻¹ since W is
// symmetric (w depends on the distance only). See filter.h for the interface.
#pragma once
#include <Eigen/Sparse>

#include "simp/filter.h"

namespace topopt::simp {

class DensityFilter final : public Filter {
 public:
  /// mesh: the tagged mesh; design: #D indices of the design tets in mesh.T (the order of the
  /// design variables); volume: #T element volumes; params.kind Gaussian or Cone; held: #V or
  /// empty, the nodes whose faces params.pad_free_faces leaves unpadded (filter.h).
  DensityFilter(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volume, const FilterParams& params,
                const std::vector<char>& held = {});

  VecXd apply(const VecXd& x) const override;
  VecXd apply_transpose(const VecXd& g) const override;
  /// Σ_j w_ij x_j g_j / (max(1e-3, x_i) Σ_j w_ij): the seed paper's unweighted rows.
  VecXd filter_sensitivity(const VecXd& x, const VecXd& g) const override;
  std::string describe() const override;
  /// Average number of neighbours per element (for logs and tests).
  double mean_neighbours() const;

 private:
  /// y = W z with W held as its upper triangle; the same sums in the same order as the full
  /// matrix's row-by-row product on one thread (to the bit), per-thread partial sums on more.
  VecXd product(const VecXd& z) const;

  /// raw weights, the upper triangle (j >= i, the diagonal included) in compressed rows
  Eigen::SparseMatrix<double, Eigen::RowMajor> W_;
  int threads_ = 1;
  VecXd volume_;        // #D v_j
  VecXd weighted_sum_;  // #D Σ_j w_ij v_j (+ the void padding's mass)
  VecXd plain_sum_;     // #D Σ_j w_ij
  std::string kind_;
  double radius_ = 0;
  bool padded_ = false;
  double pad_weight_ = 1;  // FilterParams::pad_weight of the padding
};

/// #T element volumes (positive for positively oriented tets).
VecXd tet_volumes(const TetMesh& mesh);
/// #T by 3 element centroids.
MatX3d tet_centroids(const TetMesh& mesh);

}  // namespace topopt::simp
