// The density filter against its definition: every weight of H compared with a brute-force
// O(n²) evaluation of w_ij v_j / Σ_k w_ik v_k, for both kernels, with non-design tets left out.
#include "simp/density_filter.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mesh/core/structured_box.h"

namespace topopt::simp {
namespace {

TEST(DensityFilter, WeightsMatchTheDefinitionByBruteForce) {
  mesh::StructuredBoxParams p;
  p.size = {6, 4, 3};
  p.cells = {6, 4, 3};
  p.nondesign = {{5, 0, 0, 6, 4, 3}};  // the last slab of cells is non-design
  TetMesh m = mesh::structured_box_mesh(p);
  std::vector<int> design;
  for (long t = 0; t < m.T.rows(); ++t)
    if (m.domain[t] == 0) design.push_back(static_cast<int>(t));
  ASSERT_LT(design.size(), static_cast<size_t>(m.T.rows()));
  const VecXd vol = tet_volumes(m);
  const MatX3d c = tet_centroids(m);
  EXPECT_NEAR(vol.sum(), 72.0, 1e-9);
  const int n = static_cast<int>(design.size());
  const double R = 1.7;
  for (FilterKind kind : {FilterKind::Gaussian, FilterKind::Cone}) {
    DensityFilter f(m, design, vol, {kind, R, 0});
    // H's column j is H e_j
    Eigen::MatrixXd H(n, n);
    for (int j = 0; j < n; ++j) H.col(j) = f.apply(VecXd::Unit(n, j));
    const double sigma = R / 3;
    double worst = 0;
    for (int i = 0; i < n; ++i) {
      VecXd w(n);
      for (int j = 0; j < n; ++j) {
        const double d = (c.row(design[i]) - c.row(design[j])).norm();
        const double k = d >= R ? 0.0 : (kind == FilterKind::Gaussian ? std::exp(-d * d / (2 * sigma * sigma)) : R - d);
        w[j] = k * vol[design[j]];
      }
      w /= w.sum();
      worst = std::max(worst, (H.row(i).transpose() - w).cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst, 1e-12) << (kind == FilterKind::Gaussian ? "gaussian" : "cone");
  }
}

}  // namespace
}  // namespace topopt::simp
