// The closed-surface check on a tetrahedron's surface: closed with its volume; then with a
// triangle missing, turned over, or given twice, each defect counted where it is.
#include "common/closed_surface.h"

#include <gtest/gtest.h>

namespace topopt {
namespace {

/// The unit corner tetrahedron's surface, oriented outwards (volume 1/6).
struct Tetrahedron {
  MatX3d V{4, 3};
  MatX3i F{4, 3};
  Tetrahedron() {
    V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
    F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  }
};

TEST(ClosedSurface, ATetrahedronIsClosedWithItsVolume) {
  Tetrahedron s;
  const SurfaceCheck c = check_surface(s.V, s.F);
  EXPECT_TRUE(c.closed_manifold());
  EXPECT_EQ(c.open_edges + c.overshared_edges + c.misoriented_edges + c.unpaired_edges, 0);
  EXPECT_NEAR(c.volume, 1.0 / 6, 1e-15);
  EXPECT_EQ(check_surface(s.F).volume, 0.0);  // no points, no volume
  s.F.col(1).swap(s.F.col(2));                // every triangle turned inwards
  EXPECT_NEAR(check_surface(s.V, s.F).volume, -1.0 / 6, 1e-15);
  EXPECT_TRUE(check_surface(s.V, s.F).closed_manifold());
}

TEST(ClosedSurface, AMissingTriangleLeavesItsThreeEdgesOpen) {
  Tetrahedron s;
  const MatX3i open = s.F.topRows(3);
  const SurfaceCheck c = check_surface(open);
  EXPECT_FALSE(c.closed_manifold());
  EXPECT_EQ(c.open_edges, 3);
  EXPECT_EQ(c.overshared_edges, 0);
  EXPECT_EQ(c.misoriented_edges, 0);
  EXPECT_EQ(c.unpaired_edges, 3);
}

TEST(ClosedSurface, ATriangleTurnedOverUsesItsEdgesTwice) {
  Tetrahedron s;
  std::swap(s.F(3, 1), s.F(3, 2));
  const SurfaceCheck c = check_surface(s.F);
  EXPECT_EQ(c.overshared_edges, 3);  // its edges, also used by its neighbours in that direction
  EXPECT_EQ(c.open_edges, 3);        // so their opposites are missing
  EXPECT_EQ(c.misoriented_edges, 0);
  EXPECT_EQ(c.unpaired_edges, 3);
  EXPECT_FALSE(c.closed_manifold());
}

TEST(ClosedSurface, ATriangleGivenTwiceIsOversharedAndMisoriented) {
  Tetrahedron s;
  MatX3i F(5, 3);
  F << s.F, s.F.row(0);
  const SurfaceCheck c = check_surface(F);
  EXPECT_EQ(c.overshared_edges, 3);
  EXPECT_EQ(c.open_edges, 0);
  EXPECT_EQ(c.misoriented_edges, 6);  // each of its edges (twice) against its opposite (once), and back
  EXPECT_EQ(c.unpaired_edges, 6);
}

}  // namespace
}  // namespace topopt
