// The self-intersection check on configurations with a known answer: every kind of improper
// contact is found (crossing, touching at a point, overlapping coplanar triangles with and
// without a common node, a fold across a common edge, a zero-area triangle), while proper
// neighbours (a closed tetrahedron surface, a flat fan, a bent pair) pass.
#include "mesh/surface/surface_check.h"

#include <gtest/gtest.h>

namespace topopt::mesh {
namespace {

MatX3d points(std::initializer_list<std::array<double, 3>> p) {
  MatX3d V(static_cast<long>(p.size()), 3);
  long i = 0;
  for (const auto& x : p) V.row(i++) << x[0], x[1], x[2];
  return V;
}
MatX3i tris(std::initializer_list<std::array<int, 3>> t) {
  MatX3i F(static_cast<long>(t.size()), 3);
  long i = 0;
  for (const auto& x : t) F.row(i++) << x[0], x[1], x[2];
  return F;
}

TEST(SurfaceCheck, ProperNeighboursPass) {
  // a tetrahedron's closed surface
  MatX3d V = points({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  EXPECT_TRUE(self_intersections(V, tris({{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}})).empty());
  // a flat fan around a node and a bent pair on a common edge
  V = points({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {1, 1, 1}});
  EXPECT_TRUE(self_intersections(V, tris({{0, 1, 2}, {0, 2, 3}, {0, 3, 4}, {0, 4, 1}})).empty());
  EXPECT_TRUE(self_intersections(V, tris({{0, 1, 2}, {1, 5, 2}})).empty());
}

TEST(SurfaceCheck, ImproperContactsAreFound) {
  // crossing, no common node
  MatX3d V = points({{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, -1}, {0.5, 0.5, 1}, {3, 3, 0}});
  EXPECT_EQ(self_intersections(V, tris({{0, 1, 2}, {3, 4, 5}})).size(), 1u);
  // touching at a single point (a vertex on the other's interior), no common node
  V = points({{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, 0}, {0.5, 0.5, 1}, {1, 1.5, 1}});
  EXPECT_EQ(self_intersections(V, tris({{0, 1, 2}, {3, 4, 5}})).size(), 1u);
  // coplanar overlap sharing one node
  V = points({{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {2, 1, 0}, {1, 2, 0}});
  EXPECT_EQ(self_intersections(V, tris({{0, 1, 2}, {0, 3, 4}})).size(), 1u);
  // sharing one node, the other's edge pierces it
  V = points({{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, -1}, {0.5, 0.5, 1}});
  EXPECT_EQ(self_intersections(V, tris({{0, 1, 2}, {0, 3, 4}})).size(), 1u);
  // folded onto each other across a common edge
  V = points({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5, 0.3, 0}});
  EXPECT_EQ(self_intersections(V, tris({{0, 1, 2}, {1, 0, 3}})).size(), 1u);
  // a zero-area triangle
  V = points({{0, 0, 0}, {1, 1, 1}, {2, 2, 2}});
  EXPECT_EQ(self_intersections(V, tris({{0, 1, 2}})).size(), 1u);
}

TEST(SurfaceCheck, AnglesOfKnownTriangles) {
  const MatX3d V = points({{0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}, {0, 1, 0}});
  SurfaceQuality q = surface_quality(V, tris({{0, 1, 2}}));
  EXPECT_NEAR(q.min_angle, 60, 1e-9);
  EXPECT_NEAR(q.mean_quality, 1, 1e-12);
  q = surface_quality(V, tris({{0, 1, 2}, {0, 1, 3}}));  // equilateral + right isosceles (45°)
  EXPECT_NEAR(q.min_angle, 45, 1e-9);
  EXPECT_NEAR(q.mean_min_angle, 52.5, 1e-9);
  EXPECT_EQ(q.share_below_20, 0);
}

}  // namespace
}  // namespace topopt::mesh
