// The triangles around each node: every corner listed once under its node, in triangle order,
// and the dead triangles left out.
#include "mesh/surface/triangle_stars.h"

#include <gtest/gtest.h>

namespace topopt::mesh {
namespace {

std::vector<int> row(const TriangleStars& a, int v) { return {a.begin(v), a.end(v)}; }

TEST(TriangleStars, EveryCornerUnderItsNode) {
  // a fan of three triangles around node 0, and node 5 that no triangle uses
  MatX3i T(3, 3);
  T << 0, 1, 2, 0, 2, 3, 4, 0, 3;
  const TriangleStars s = triangle_stars(T, T.rows(), 6);
  ASSERT_EQ(s.rows(), 6);
  EXPECT_EQ(row(s, 0), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(row(s, 1), (std::vector<int>{0}));
  EXPECT_EQ(row(s, 2), (std::vector<int>{0, 1}));
  EXPECT_EQ(row(s, 3), (std::vector<int>{1, 2}));
  EXPECT_EQ(row(s, 4), (std::vector<int>{2}));
  EXPECT_EQ(s.size(5), 0);
  EXPECT_EQ(s.index.size(), 9u);
}

TEST(TriangleStars, DeadTrianglesAndRowsPastTheCountAreLeftOut) {
  MatX3i T(3, 3);
  T << 0, 1, 2, 0, 2, 3, 4, 0, 3;
  const TriangleStars dead = triangle_stars(T, 3, 5, {0, 1, 0});
  EXPECT_EQ(row(dead, 0), (std::vector<int>{0, 2}));
  EXPECT_EQ(row(dead, 2), (std::vector<int>{0}));
  EXPECT_EQ(row(dead, 3), (std::vector<int>{2}));
  const TriangleStars first = triangle_stars(T, 1, 5);  // only row 0 of T is read
  EXPECT_EQ(row(first, 0), (std::vector<int>{0}));
  EXPECT_EQ(first.size(3), 0);
  EXPECT_EQ(first.size(4), 0);
}

}  // namespace
}  // namespace topopt::mesh
