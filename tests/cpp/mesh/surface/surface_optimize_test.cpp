// Local optimisation of a face's triangles on a plane (the surface is z = 0, parameters = x, y):
// what it must reach from meshes the 2D front can leave behind, with the face's boundary
// unchanged and the triangulation still covering the face exactly once.
#include "mesh/surface/surface_optimize.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mesh/core/predicates.h"

namespace topopt::mesh {
namespace {

void plane(const double* uv, double* x, double* xu, double* xv) {
  x[0] = uv[0], x[1] = uv[1], x[2] = 0;
  xu[0] = 1, xu[1] = 0, xu[2] = 0;
  xv[0] = 0, xv[1] = 1, xv[2] = 0;
}

double smallest_angle(const MatX3d& X, const MatX3i& T) {
  double m = 180;
  for (long t = 0; t < T.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d a = X.row(T(t, k)), b = X.row(T(t, (k + 1) % 3)), c = X.row(T(t, (k + 2) % 3));
      m = std::min(m, std::acos((b - a).normalized().dot((c - a).normalized())) * 180 / M_PI);
    }
  return m;
}

/// Every triangle counter-clockwise, their areas summing to `area`, the first `fixed` nodes
/// where they were.
void expect_valid(const MatX2d& P0, const MatX2d& P, const MatX3i& T, int fixed, double area) {
  double sum = 0;
  for (long t = 0; t < T.rows(); ++t) {
    EXPECT_GT(predicates::orient2d(P.row(T(t, 0)).data(), P.row(T(t, 1)).data(), P.row(T(t, 2)).data()), 0)
        << "triangle " << t;
    const Eigen::Vector2d a = P.row(T(t, 0)), b = P.row(T(t, 1)), c = P.row(T(t, 2));
    sum += 0.5 * ((b - a).x() * (c - a).y() - (b - a).y() * (c - a).x());
  }
  EXPECT_NEAR(sum, area, 1e-12 * area);
  for (int i = 0; i < fixed; ++i) EXPECT_EQ(P.row(i), P0.row(i)) << "boundary node " << i << " moved";
}

TEST(SurfaceOptimize, NodeSqueezedAgainstTheBoundaryIsFreed) {
  // the unit square with two inner nodes, one 0.02 above the bottom side: a flat cap (176°)
  MatX2d P(6, 2);
  P << 0, 0, 1, 0, 1, 1, 0, 1, 0.5, 0.02, 0.5, 0.6;
  MatX3i T(6, 3);
  T << 0, 1, 4, 1, 5, 4, 1, 2, 5, 2, 3, 5, 3, 0, 5, 0, 4, 5;
  const MatX2d P0 = P;
  MatX3d X;
  const SurfaceOptimizeStats st = optimize_on_surface(P, T, X, 4, plane);
  EXPECT_LT(st.min_angle_before, 3.0);
  EXPECT_GT(smallest_angle(X, T), 30.0);
  expect_valid(P0, P, T, 4, 1.0);
}

}  // namespace
}  // namespace topopt::mesh
