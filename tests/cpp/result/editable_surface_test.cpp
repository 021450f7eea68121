// The editable triangle surface shared by the remeshing and the STEP coarsening: stars kept
// exact under collapse, flip and split; the link condition refuses the collapse that would
// pinch the surface; orientation kept.
#include "result/editable_surface.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "common/closed_surface.h"

namespace topopt::result {
namespace {

/// An octahedron (6 points, 8 triangles, outward), tags 0 on the upper half, 3 on the lower.
void octahedron(MatX3d& V, MatX3i& F, VecXi& tag) {
  V.resize(6, 3);
  V << 1, 0, 0, 0, 1, 0, -1, 0, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  F.resize(8, 3);
  F << 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4, 1, 0, 5, 2, 1, 5, 3, 2, 5, 0, 3, 5;
  tag.resize(8);
  tag << 0, 0, 0, 0, 3, 3, 3, 3;
}

/// Every live triangle is in the star of each of its corners and in no other star.
void expect_stars_exact(const EditableSurface& m) {
  for (int v = 0; v < m.points(); ++v)
    for (int t : m.star(v)) {
      EXPECT_TRUE(m.alive(t));
      EXPECT_EQ(std::count(m.tri(t).begin(), m.tri(t).end(), v), 1);
    }
  for (int t = 0; t < m.triangles(); ++t)
    if (m.alive(t)) {
      for (int v : m.tri(t)) EXPECT_EQ(std::count(m.star(v).begin(), m.star(v).end(), t), 1);
    }
}

TEST(EditableSurface, LinkConditionRefusesThePinchOfAnOctahedron) {
  MatX3d V;
  MatX3i F;
  VecXi tag;
  octahedron(V, F, tag);
  const EditableSurface m(F, tag, V.rows());
  EXPECT_EQ(m.edge_triangles(0, 4).size(), 2u);
  EXPECT_EQ(m.neighbours(0), (std::vector<int>{1, 3, 4, 5}));
  // 0 and 4 have common neighbours 1 and 3 only: collapsing gives a closed 5-point surface
  EXPECT_TRUE(m.link_condition(0, 4));
  // 0 and 2 are not joined: no edge, no collapse
  EXPECT_FALSE(m.link_condition(0, 2));
}

TEST(EditableSurface, CollapseKeepsTheSurfaceClosedAndTheStarsExact) {
  MatX3d V;
  MatX3i F;
  VecXi tag;
  octahedron(V, F, tag);
  EditableSurface m(F, tag, V.rows());
  m.collapse(4, 0);  // the apex goes into point 0
  expect_stars_exact(m);
  EXPECT_TRUE(m.star(4).empty());
  MatX3i G;
  VecXi gtag;
  m.live(G, gtag);
  EXPECT_EQ(G.rows(), 6);  // the two triangles on edge (0, 4) went
  const SurfaceCheck c = check_surface(V, G);
  EXPECT_TRUE(c.closed_manifold());
  EXPECT_GT(c.volume, 0);  // still outward (the upper half folded flat onto the plane z = 0)
  // now the surface is a double pyramid over a triangle: points 0 and 2 are joined, and
  // their common neighbours are 1, 3 and 5: collapsing them would pinch it
  EXPECT_FALSE(m.link_condition(0, 2));
}

TEST(EditableSurface, FlipTurnsTheEdgeAndKeepsOrientation) {
  MatX3d V;
  MatX3i F;
  VecXi tag;
  octahedron(V, F, tag);
  EditableSurface m(F, tag, V.rows());
  EditableSurface::Flip f;
  // edge (0, 1) lies between triangles of tags 0 and 3: not one face, no flip
  EXPECT_FALSE(m.flip_of(0, 1, f));
  // edge (0, 4) lies between triangles 0 and 3 (both tag 0); its flip would join 1 and 3
  ASSERT_TRUE(m.flip_of(0, 4, f));
  EXPECT_EQ(std::min(f.c, f.d), 1);
  EXPECT_EQ(std::max(f.c, f.d), 3);
  m.flip(0, 4, f);
  expect_stars_exact(m);
  EXPECT_EQ(m.edge_triangles(1, 3).size(), 2u);
  EXPECT_TRUE(m.edge_triangles(0, 4).empty());
  MatX3i G;
  VecXi gtag;
  m.live(G, gtag);
  const SurfaceCheck c = check_surface(V, G);
  EXPECT_TRUE(c.closed_manifold());
  // the tet (0, 1, 3, 4) cut off the octahedron (4/3): 1/3 less
  EXPECT_NEAR(c.volume, 1.0, 1e-12);
}

TEST(EditableSurface, SplitMakesFourTrianglesOfTheTagsTheyCameFrom) {
  MatX3d V;
  MatX3i F;
  VecXi tag;
  octahedron(V, F, tag);
  EditableSurface m(F, tag, V.rows());
  const int p = m.split_edge(0, 1);  // between a tag-0 and a tag-3 triangle
  EXPECT_EQ(p, 6);
  expect_stars_exact(m);
  EXPECT_EQ(m.star(p).size(), 4u);
  EXPECT_TRUE(m.edge_triangles(0, 1).empty());
  MatX3i G;
  VecXi gtag;
  m.live(G, gtag);
  EXPECT_EQ(G.rows(), 10);
  EXPECT_EQ((gtag.array() == 0).count(), 5);
  EXPECT_EQ((gtag.array() == 3).count(), 5);
  MatX3d W(7, 3);
  W.topRows(6) = V;
  W.row(6) = 0.5 * (V.row(0) + V.row(1));  // on the edge: the same solid
  const SurfaceCheck c = check_surface(W, G);
  EXPECT_TRUE(c.closed_manifold());
  EXPECT_NEAR(c.volume, 4.0 / 3.0, 1e-12);
}

}  // namespace
}  // namespace topopt::result
