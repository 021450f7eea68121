// The front's last resort on cavities whose answer is known: the components of a front, a
// convex cavity filled from the node that gives the best worst tet, and a cube whose
// triangulation no node of it sees whole, filled from one new point inside.
#include "mesh/volume/front_cavities.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "mesh/core/predicates.h"

namespace topopt::mesh {
namespace {

using Vec3 = Eigen::Vector3d;

/// Adds the triangles F (outward from the region) to the front turned inwards.
void add_inward(TetFront& front, const std::vector<Tri>& F) {
  for (const Tri& f : F) ASSERT_GE(front.add_face(f[0], f[2], f[1]), 0);
}

double volume(const std::vector<Vec3>& P, const std::vector<Tet>& tets) {
  double v = 0;
  for (const Tet& t : tets) {
    EXPECT_GT(predicates::orient3d(P[t[0]].data(), P[t[1]].data(), P[t[2]].data(), P[t[3]].data()), 0);
    v += (P[t[1]] - P[t[0]]).dot((P[t[2]] - P[t[0]]).cross(P[t[3]] - P[t[0]])) / 6;
  }
  return v;
}

TEST(FrontCavities, ComponentsAreThePiecesOfTheFrontThatShareNodes) {
  std::vector<Vec3> P = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 4; ++i) P.push_back(P[i] + Vec3(5, 0, 0));
  TetFront front(P, 0.1, Vec3(-1, -1, -1));
  add_inward(front, {{4, 5, 6}, {1, 2, 3}, {0, 3, 2}, {4, 7, 5}, {0, 1, 3}, {5, 7, 6}, {0, 2, 1}, {4, 6, 7}});
  const std::vector<std::vector<int>> c = front_components(front);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c[0], (std::vector<int>{0, 3, 5, 7})) << "the second tet's faces, first by face 0";
  EXPECT_EQ(c[1], (std::vector<int>{1, 2, 4, 6}));
}

/// The regular octahedron of vertices ±e_i, outward triangles.
std::vector<Tri> octahedron(std::vector<Vec3>& P) {
  P = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<Tri> F;
  for (int i : {0, 1})
    for (int j : {2, 3})
      for (int k : {4, 5}) {
        Tri t{i, j, k};
        if (P[i].dot(P[j].cross(P[k])) < 0) std::swap(t[1], t[2]);
        F.push_back(t);
      }
  return F;
}

TEST(FrontCavities, AConvexCavityIsFilledFromItsBestNode) {
  // from a vertex: four tets of radius ratio 0.8038; from the centre (the best inner point):
  // eight of 0.7321. The vertex wins and no point is added
  std::vector<Vec3> P;
  const std::vector<Tri> F = octahedron(P);
  TetFront front(P, 0.1, Vec3(-1, -1, -1));
  add_inward(front, F);
  std::vector<Tet> tets;
  close_cavities(front, P, tets, Progress());
  EXPECT_EQ(front.size(), 0);
  EXPECT_EQ(P.size(), 6u);
  ASSERT_EQ(tets.size(), 4u);
  int apex = -1;
  for (int v = 0; v < 6; ++v)
    if (std::all_of(tets.begin(), tets.end(), [v](const Tet& t) { return std::count(t.begin(), t.end(), v) == 1; }))
      apex = v;
  EXPECT_GE(apex, 0) << "the tets share one apex";
  EXPECT_NEAR(volume(P, tets), 4.0 / 3.0, 1e-15);
}

TEST(FrontCavities, ACubeNoNodeSeesWholeIsFilledFromAPointInside) {
  // the unit cube's faces split by the diagonals that avoid their lowest-numbered corner: no
  // corner lies on all three diagonals of its faces, so each is coplanar with a triangle it
  // is not a node of and sees no tet there; a point inside sees all twelve
  std::vector<Vec3> P;
  for (int c = 0; c < 8; ++c) P.emplace_back(c & 1, (c >> 1) & 1, (c >> 2) & 1);
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  std::vector<Tri> F;
  for (const auto& q : quads) {  // outward quads (a, b, c, d): split along b-d (avoiding a, the lowest)
    const int* m = std::min_element(q, q + 4);
    const int k = static_cast<int>(m - q);
    const int a = q[k], b = q[(k + 1) % 4], c = q[(k + 2) % 4], d = q[(k + 3) % 4];
    F.push_back({a, b, d});
    F.push_back({b, c, d});
  }
  double enclosed = 0;  // outward: the divergence theorem gives the cube's volume
  for (const Tri& f : F) enclosed += P[f[0]].dot(P[f[1]].cross(P[f[2]])) / 6;
  ASSERT_NEAR(enclosed, 1.0, 1e-15);
  for (int v = 0; v < 8; ++v) {  // the premise: no corner sees every triangle it is not on
    bool sees_all = true;
    for (const Tri& f : F)
      if (std::count(f.begin(), f.end(), v) == 0)
        sees_all &= predicates::orient3d(P[f[0]].data(), P[f[2]].data(), P[f[1]].data(), P[v].data()) > 0;
    ASSERT_FALSE(sees_all) << "corner " << v;
  }
  TetFront front(P, 0.1, Vec3(-1, -1, -1));
  add_inward(front, F);
  std::vector<Tet> tets;
  close_cavities(front, P, tets, Progress());
  EXPECT_EQ(front.size(), 0);
  ASSERT_EQ(P.size(), 9u) << "one new point";
  EXPECT_EQ(tets.size(), 12u);
  for (const Tet& t : tets) EXPECT_EQ(std::count(t.begin(), t.end(), 8), 1);
  EXPECT_NEAR(volume(P, tets), 1.0, 1e-14);
  for (int d = 0; d < 3; ++d) EXPECT_TRUE(P[8][d] > 0 && P[8][d] < 1);
}

}  // namespace
}  // namespace topopt::mesh
