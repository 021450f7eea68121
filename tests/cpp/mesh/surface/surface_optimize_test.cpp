// Local optimisation of a face's triangles on a plane (the surface is z = 0, parameters = x, y):
// what it must reach from meshes the 2D front can leave behind, with the face's boundary
// unchanged and the triangulation still covering the face exactly once; and each operation of
// SurfaceOptimizer alone on a small mesh whose answer is known.
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

/// Whether the triangles of T hold the undirected edge ab.
bool has_edge(const MatX3i& T, int a, int b) {
  for (long t = 0; t < T.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if ((T(t, k) == a && T(t, (k + 1) % 3) == b) || (T(t, k) == b && T(t, (k + 1) % 3) == a)) return true;
  return false;
}

/// Two thin triangles on the long edge 0-1 of a rhombus: its other diagonal 2-3 is better.
struct Rhombus {
  MatX2d P{4, 2};
  MatX3i T{2, 3};
  Rhombus() {
    P << 0, 0, 2, 0, 1, 0.3, 1, -0.3;
    T << 0, 1, 2, 1, 0, 3;
  }
};

TEST(SurfaceOptimize, FlipTakesTheBetterDiagonal) {
  Rhombus r;
  const MatX2d P0 = r.P;
  MatX3d X;
  SurfaceOptimizer opt(r.P, r.T, X, 4, plane, {});
  EXPECT_NEAR(opt.smallest_angle(), std::atan(0.3) * 180 / M_PI, 1e-9);  // 16.7°
  EXPECT_EQ(opt.flip_edges(), 1);
  EXPECT_TRUE(has_edge(r.T, 2, 3));
  EXPECT_FALSE(has_edge(r.T, 0, 1));
  EXPECT_NEAR(opt.smallest_angle(), 2 * std::atan(0.3) * 180 / M_PI, 1e-9);  // 33.4° at nodes 0 and 1
  expect_valid(P0, r.P, r.T, 4, 0.6);
  EXPECT_EQ(opt.flip_edges(), 0);  // and it stays
}

TEST(SurfaceOptimize, ConstrainedEdgeNeverFlips) {
  Rhombus r;
  MatX3d X;
  SurfaceOptimizer opt(r.P, r.T, X, 4, plane, {{1, 0}});
  EXPECT_EQ(opt.flip_edges(), 0);
  EXPECT_TRUE(has_edge(r.T, 0, 1));
}

/// The unit square fanned around one inner node (node 4) at (x, y).
struct SquareFan {
  MatX2d P{5, 2};
  MatX3i T{4, 3};
  SquareFan(double x, double y) {
    P << 0, 0, 1, 0, 1, 1, 0, 1, x, y;
    T << 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4;
  }
};

TEST(SurfaceOptimize, SmoothingMovesANodeToItsNeighboursCentre) {
  SquareFan s(0.2, 0.3);
  const MatX2d P0 = s.P;
  MatX3d X;
  SurfaceOptimizer opt(s.P, s.T, X, 4, plane, {});
  EXPECT_EQ(opt.smooth_nodes(), 1);
  EXPECT_NEAR(s.P(4, 0), 0.5, 1e-12);
  EXPECT_NEAR(s.P(4, 1), 0.5, 1e-12);
  EXPECT_NEAR(X(4, 0), 0.5, 1e-12);  // X follows P
  EXPECT_NEAR(opt.smallest_angle(), 45.0, 1e-9);
  expect_valid(P0, s.P, s.T, 4, 1.0);
  EXPECT_EQ(opt.smooth_nodes(), 0);  // nothing left to gain
}

TEST(SurfaceOptimize, CompassSearchLiftsANodeOffTheBoundary) {
  // node 4 nearly on the bottom side: triangle (0, 1, 4) has corners of 5.7°; the best place
  // for the smallest angle of the fan is the centre (45°)
  SquareFan s(0.5, 0.05);
  const MatX2d P0 = s.P;
  MatX3d X;
  SurfaceOptimizer opt(s.P, s.T, X, 4, plane, {});
  EXPECT_LT(opt.smallest_angle(), 6.0);
  EXPECT_EQ(opt.compass_search_nodes(), 1);  // one node, moved
  EXPECT_GT(opt.smallest_angle(), 44.0);
  expect_valid(P0, s.P, s.T, 4, 1.0);
}

TEST(SurfaceOptimize, NodesThatMayNotMoveStayInTheCompassSearch) {
  SquareFan s(0.5, 0.05);
  const MatX2d P0 = s.P;
  MatX3d X;
  SurfaceOptimizer opt(s.P, s.T, X, 5, plane, {});  // node 4 fixed too
  EXPECT_EQ(opt.compass_search_nodes(), 0);
  EXPECT_EQ(opt.smooth_nodes(), 0);
  EXPECT_EQ(s.P, P0);
}

TEST(SurfaceOptimize, CollapseRemovesTheShortEdgeBetweenTwoNeedles) {
  // two inner nodes 0.04 apart: triangles (2, 4, 5) and (0, 5, 4) are needles on the edge 4-5
  MatX2d P(6, 2);
  P << 0, 0, 1, 0, 1, 1, 0, 1, 0.48, 0.5, 0.52, 0.5;
  MatX3i T(6, 3);
  T << 0, 1, 5, 1, 2, 5, 2, 4, 5, 2, 3, 4, 3, 0, 4, 0, 5, 4;
  const MatX2d P0 = P;
  MatX3d X;
  SurfaceOptimizer opt(P, T, X, 4, plane, {});
  EXPECT_LT(opt.smallest_angle(), 3.0);
  EXPECT_EQ(opt.collapse_edges(), 1);
  ASSERT_EQ(T.rows(), 4);  // the edge's two triangles are gone
  int inner = -1;          // the one inner node left, used by all four
  for (int v : {4, 5}) inner = has_edge(T, 0, v) ? v : inner;
  ASSERT_GE(inner, 0);
  for (int c = 0; c < 4; ++c) EXPECT_TRUE(has_edge(T, c, inner)) << "corner " << c;
  EXPECT_GT(opt.smallest_angle(), 40.0);
  expect_valid(P0, P, T, 4, 1.0);
}

TEST(SurfaceOptimize, SplitOpensATriangleWhoseCornersMayNotMove) {
  // two triangles on the edge 0-1, every corner fixed: (0, 1, 2) has a 14° corner at node 1
  MatX2d P(4, 2);
  P << 0, 0, 2, 0, 0.4, 0.4, 1, -1;
  MatX3i T(2, 3);
  T << 0, 1, 2, 1, 0, 3;
  const MatX2d P0 = P;
  MatX3d X;
  SurfaceOptimizer opt(P, T, X, 4, plane, {});
  const double before = opt.smallest_angle();
  EXPECT_LT(before, 15.0);
  EXPECT_EQ(opt.split_fixed_triangles(), 1);
  ASSERT_EQ(P.rows(), 5);  // a node on the edge 0-1, moved by the compass search
  ASSERT_EQ(T.rows(), 4);
  ASSERT_EQ(X.rows(), 5);
  EXPECT_FALSE(has_edge(T, 0, 1));
  for (int c = 0; c < 4; ++c) EXPECT_TRUE(has_edge(T, c, 4));
  EXPECT_GT(opt.smallest_angle(), 20.0);
  expect_valid(P0, P, T, 4, 1.4);
}

TEST(SurfaceOptimize, SplitLeavesAConstrainedEdgeWhole) {
  MatX2d P(4, 2);
  P << 0, 0, 2, 0, 0.4, 0.4, 1, -1;
  MatX3i T(2, 3);
  T << 0, 1, 2, 1, 0, 3;
  MatX3d X;
  SurfaceOptimizer opt(P, T, X, 4, plane, {{0, 1}});
  EXPECT_EQ(opt.split_fixed_triangles(), 0);
  EXPECT_EQ(P.rows(), 4);
  EXPECT_EQ(T.rows(), 2);
}

}  // namespace
}  // namespace topopt::mesh
