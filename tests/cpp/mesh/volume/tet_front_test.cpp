// The 3D front container: twin faces close each other, a tet made from a face closes the
// faces it meets, admits() accepts a tet inside the region and refuses one that crosses the
// front or falls below the quality bound, and the node search returns only active nodes;
// the exact segment-triangle test on crossing, touching, shared-vertex and coplanar cases.
#include "mesh/volume/tet_front.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace topopt::mesh {
namespace {

using Vec3 = Eigen::Vector3d;

/// A front on the inward faces of the positive tet (0, 1, 2, 3): each face (kTetFace turned
/// over) faces the node opposite it.
TetFront inward_tet_front(const std::vector<Vec3>& P) {
  TetFront front(P, 0.1, Vec3(-1, -1, -1));
  for (const auto& f : kTetFace) EXPECT_GE(front.add_face(f[0], f[2], f[1]), 0);
  return front;
}

std::vector<Vec3> big_tet() { return {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {0, 0, 4}}; }

TEST(TetFront, OppositeFacesCloseEachOther) {
  const std::vector<Vec3> P = big_tet();
  TetFront front(P, 0.1, Vec3::Zero());
  EXPECT_EQ(front.add_face(0, 1, 2), 0);
  EXPECT_EQ(front.size(), 1);
  EXPECT_TRUE(front.active(0));
  EXPECT_EQ(front.add_face(1, 0, 2), -1) << "the twin closes both";
  EXPECT_EQ(front.size(), 0);
  EXPECT_FALSE(front.alive(0));
  EXPECT_FALSE(front.active(0));
  EXPECT_EQ(front.any_alive(), -1);
}

TEST(TetFront, ATetFromAFaceClosesTheFacesItMeets) {
  // the region is the tet itself: closing the face opposite node 3 with node 3 makes the tet
  // (positive) and its other three faces close against the front's
  const std::vector<Vec3> P = big_tet();
  TetFront front = inward_tet_front(P);
  ASSERT_EQ(front.size(), 4);
  std::vector<Tet> tets;
  const std::array<int, 3> added = front.close_with(3, 3, tets);  // face 3: opposite node 3
  EXPECT_EQ(added, (std::array<int, 3>{-1, -1, -1}));
  ASSERT_EQ(tets.size(), 1u);
  Tet t = tets[0];
  std::sort(t.begin(), t.end());
  EXPECT_EQ(t, (Tet{0, 1, 2, 3}));
  EXPECT_EQ(front.size(), 0);
  EXPECT_TRUE(front.alive_faces().empty());
}

TEST(TetFront, AdmitsTetsInsideTheRegionOnly) {
  std::vector<Vec3> P = big_tet();
  P.push_back({1, 1, 1});     // 4: inside
  P.push_back({3, 3, 1});     // 5: beyond the face (1, 2, 3), on face 3's side
  P.push_back({1, 1, 0.01});  // 6: inside, nearly on face 3: a flat tet
  TetFront front = inward_tet_front(P);
  const Tri f = front.face(3);  // (0, 1, 2) turned towards node 3
  EXPECT_TRUE(front.admits(f[0], f[1], f[2], 4, 0.0, 3));
  EXPECT_TRUE(front.admits(f[0], f[1], f[2], 3, 0.0, 3)) << "closing against the other faces";
  EXPECT_FALSE(front.admits(f[0], f[1], f[2], 5, 0.0, 3)) << "its edges cross the face (1, 2, 3)";
  EXPECT_FALSE(front.admits(f[0], f[1], f[2], 6, 0.1, 3)) << "below the quality bound";
  EXPECT_TRUE(front.admits(f[0], f[1], f[2], 6, 0.0, 3));
  EXPECT_FALSE(front.admits(f[0], f[2], f[1], 4, 0.0, 3)) << "on the wrong side of the face";
}

TEST(TetFront, NodeSearchReturnsTheActiveNodesOnly) {
  const std::vector<Vec3> P = big_tet();
  TetFront front = inward_tet_front(P);
  std::vector<int> out;
  front.nodes_near(Vec3(-1, -1, -1), Vec3(5, 5, 5), out);
  std::sort(out.begin(), out.end());
  EXPECT_EQ(out, (std::vector<int>{0, 1, 2, 3}));
  front.nodes_near(Vec3(3.5, -0.5, -0.5), Vec3(4.5, 0.5, 0.5), out);  // candidates: 1 among them
  EXPECT_NE(std::find(out.begin(), out.end(), 1), out.end());
  std::vector<Tet> tets;
  front.close_with(3, 3, tets);
  front.nodes_near(Vec3(-1, -1, -1), Vec3(5, 5, 5), out);
  EXPECT_TRUE(out.empty()) << "a closed front has no active node";
  front.faces_near(Vec3(-1, -1, -1), Vec3(5, 5, 5), out);
  EXPECT_TRUE(out.empty());
}

TEST(SegmentMeetsTriangle, CrossingTouchingSharedVertexAndCoplanar) {
  // triangle 0, 1, 2 in z = 0; the other nodes are segment ends
  const std::vector<Vec3> P = {{0, 0, 0},    {1, 0, 0},   {0, 1, 0},   {0.2, 0.2, -1}, {0.2, 0.2, 1},
                               {2, 2, -1},   {2, 2, 1},   {-1, -1, 1}, {0.2, 0.2, 0},  {0.3, 0.3, 0},
                               {-1, 0.2, 0}, {2, 0.2, 0}, {-1, -1, 0}, {2, 0, 0},      {3, 0, 0}};
  auto meets = [&](int u, int v) { return segment_meets_triangle(P, u, v, 0, 1, 2); };
  EXPECT_TRUE(meets(3, 4)) << "through the interior";
  EXPECT_FALSE(meets(5, 6)) << "beside it";
  EXPECT_FALSE(meets(0, 7)) << "from a vertex, away from the triangle";
  EXPECT_FALSE(meets(0, 4)) << "from a vertex, touching only there";
  EXPECT_TRUE(meets(8, 4)) << "touching the interior counts";
  EXPECT_TRUE(meets(8, 9)) << "coplanar, inside";
  EXPECT_TRUE(meets(10, 11)) << "coplanar, across";
  EXPECT_FALSE(meets(0, 12)) << "coplanar, from a vertex outwards";
  EXPECT_FALSE(meets(13, 14)) << "coplanar, apart";
  EXPECT_FALSE(meets(0, 1)) << "an edge of the triangle";
}

}  // namespace
}  // namespace topopt::mesh
