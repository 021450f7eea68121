// The density filter against its definition: every weight of H compared with a brute-force
// O(n²) evaluation of w_ij v_j / Σ_k w_ik v_k, for both kernels, with non-design tets left out;
// its half-stored matrix summed as the full one, on one thread and on several.
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

// W is held as its upper triangle (density_filter.h); on one thread its product makes the same
// sums in the same order as the full matrix's rows, so the filter is the full matrix's to the bit.
TEST(DensityFilter, OneThreadSumsAsTheFullMatrixToTheBit) {
  mesh::StructuredBoxParams p;
  p.size = {6, 4, 3};
  p.cells = {6, 4, 3};
  const TetMesh m = mesh::structured_box_mesh(p);
  std::vector<int> design(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) design[t] = static_cast<int>(t);
  const VecXd vol = tet_volumes(m);
  const MatX3d c = tet_centroids(m);
  const int n = static_cast<int>(design.size());
  const double R = 1.7, sigma = R / 3.0;
  const DensityFilter f(m, design, vol, {FilterKind::Gaussian, R, 1});
  const VecXd x = (VecXd::Random(n).array() + 1) / 2;
  const VecXd y = f.apply(x);
  int differing = 0;
  for (int i = 0; i < n; ++i) {
    double num = 0, den = 0;  // row i of the full matrix, left to right
    for (int j = 0; j < n; ++j) {
      const double d = (c.row(j) - c.row(i)).norm();
      if (d >= R) continue;
      const double w = std::exp(-d * d / (2 * sigma * sigma));
      num += w * (vol[j] * x[j]);
      den += w * vol[j];
    }
    differing += num / den != y[i];
  }
  EXPECT_EQ(differing, 0);
}

// On several threads each takes a range of rows with its own partial sums: the same filter to
// round-off, still constant-preserving, and its transpose still its adjoint.
TEST(DensityFilter, ThreadsGiveTheSameFilterAndAdjoint) {
  mesh::StructuredBoxParams p;
  p.size = {20, 20, 16};
  p.cells = {20, 20, 16};  // 38 400 tets
  const TetMesh m = mesh::structured_box_mesh(p);
  std::vector<int> design(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) design[t] = static_cast<int>(t);
  const VecXd vol = tet_volumes(m);
  const DensityFilter one(m, design, vol, {FilterKind::Gaussian, 1.6, 1});
  const DensityFilter two(m, design, vol, {FilterKind::Gaussian, 1.6, 2});
  // two parts: the stored half, (pairs + n) / 2, above 2^20 entries
  ASSERT_GT(one.mean_neighbours() * static_cast<double>(design.size()), (1 << 21) + static_cast<double>(design.size()));
  const long n = static_cast<long>(design.size());
  const VecXd x = (VecXd::Random(n).array() + 1) / 2, g = VecXd::Random(n);
  const VecXd y1 = one.apply(x), y2 = two.apply(x);
  EXPECT_LT((y1 - y2).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_GT((y1 - x).cwiseAbs().maxCoeff(), 1e-3);  // it does filter
  EXPECT_LT((two.apply(VecXd::Ones(n)).array() - 1).abs().maxCoeff(), 1e-14);
  EXPECT_NEAR(g.dot(two.apply(x)), two.apply_transpose(g).dot(x), 1e-12 * std::abs(g.dot(y2)) + 1e-12);
  EXPECT_LT((one.apply_transpose(g) - two.apply_transpose(g)).cwiseAbs().maxCoeff(), 1e-14 * g.cwiseAbs().maxCoeff());
}

}  // namespace
}  // namespace topopt::simp
