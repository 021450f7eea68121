// The remesher's edit-by-edit crossing check: a triangle an edit would make is tested against the
// live triangles it keeps, exactly.
#include "result/crossing_guard.h"

#include <gtest/gtest.h>

namespace topopt::result {
namespace {

/// The closed tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1), oriented outwards, and two points
/// more for the triangles under test: (0.2, 0.2, -0.5) below the base and (0.2, 0.2, 0.5) inside.
struct Tetrahedron {
  MatX3d V;
  MatX3i F;
  VecXi tag;
  Tetrahedron() {
    V.resize(6, 3);
    V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0.2, 0.2, -0.5, 0.2, 0.2, 0.5;
    F.resize(4, 3);
    F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
    tag = VecXi::Zero(4);
  }
};

TEST(CrossingGuard, FindsAPiercingTriangleAndNotTheOnesItReplaces) {
  Tetrahedron t;
  EditableSurface m(t.F, t.tag, t.V.rows());
  CrossingGuard guard(t.V, m);
  // (1, 3, 4) runs from below the base through it to the apex edge: it pierces the base (0, 2, 1)
  EXPECT_TRUE(guard.crosses({{1, 3, 4}}, {}));
  EXPECT_TRUE(guard.crosses({{1, 3, 4}}, {1}));      // still the base, (0, 1, 3) aside
  EXPECT_FALSE(guard.crosses({{1, 3, 4}}, {0, 1}));  // without the base and the face it replaces
  // the base moved up to the inner point: (0, 5, 1) and (5, 2, 1) instead of (0, 2, 1) stay inside
  EXPECT_FALSE(guard.crosses({{0, 2, 5}, {0, 5, 1}, {5, 2, 1}}, {0}));
  // a zero-area triangle is a crossing, as mesh::self_intersections counts it
  t.V.row(4) << 0.5, 0.5, 0;  // on the edge between (1, 0, 0) and (0, 1, 0)
  EXPECT_TRUE(guard.crosses({{1, 2, 4}}, {0, 1, 2, 3}));
}

TEST(CrossingGuard, FindsAMovedTriangleOnceItIsAddedUnderItsNewBox) {
  Tetrahedron t;
  EditableSurface m(t.F, t.tag, t.V.rows());
  CrossingGuard guard(t.V, m);
  // the apex moved to (0.2, 0.2, 20): the three faces around it now reach z = 20; at z = 10 the
  // solid's section is the triangle (0.1, 0.1), (0.6, 0.1), (0.1, 0.6), which the upright triangle
  // (0.3, -1, 10), (0.3, 1, 10), (0.3, 0, 10.5) cuts through
  t.V.row(3) << 0.2, 0.2, 20;
  t.V.row(4) << 0.3, -1, 10;
  t.V.row(5) << 0.3, 1, 10;
  t.V.conservativeResize(7, 3);
  t.V.row(6) << 0.3, 0, 10.5;
  EXPECT_FALSE(guard.crosses({{4, 5, 6}}, {}));  // registered under their old boxes, near z < 1
  for (int f : m.star(3)) guard.add(f);
  EXPECT_TRUE(guard.crosses({{4, 5, 6}}, {}));
  EXPECT_FALSE(guard.crosses({{4, 5, 6}}, {1, 2, 3}));
}

}  // namespace
}  // namespace topopt::result
