// Morton renumbering: the same mesh (tets as coordinate tuples with their tags, boundary
// triangles in order with their faces, orientations) with node numbers that follow space.
#include "mesh/core/reorder.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>

#include "mesh/core/structured_box.h"

namespace topopt::mesh {
namespace {

/// Median over tets of (largest - smallest node number): how far apart a tet's nodes sit in
/// memory. (A Morton curve has a few long jumps, so the median, not the mean, is the measure.)
double median_tet_spread(const TetMesh& m) {
  std::vector<int> s(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) s[t] = m.T.row(t).maxCoeff() - m.T.row(t).minCoeff();
  std::nth_element(s.begin(), s.begin() + s.size() / 2, s.end());
  return s[s.size() / 2];
}

using Tuple = std::array<double, 12>;
std::multiset<std::pair<Tuple, int>> tets_by_coordinates(const TetMesh& m) {
  std::multiset<std::pair<Tuple, int>> out;
  for (long t = 0; t < m.T.rows(); ++t) {
    // rotate the tet so its smallest-coordinate node comes first (same orientation)
    std::array<int, 4> v{m.T(t, 0), m.T(t, 1), m.T(t, 2), m.T(t, 3)};
    Tuple best;
    best.fill(1e300);
    static const int kEven[12][4] = {{0, 1, 2, 3}, {0, 2, 3, 1}, {0, 3, 1, 2}, {1, 0, 3, 2},
                                     {1, 2, 0, 3}, {1, 3, 2, 0}, {2, 0, 1, 3}, {2, 1, 3, 0},
                                     {2, 3, 0, 1}, {3, 0, 2, 1}, {3, 1, 0, 2}, {3, 2, 1, 0}};
    for (const auto& p : kEven) {
      Tuple c;
      for (int a = 0; a < 4; ++a)
        for (int k = 0; k < 3; ++k) c[3 * a + k] = m.V(v[p[a]], k);
      best = std::min(best, c);
    }
    out.insert({best, m.domain[t]});
  }
  return out;
}

TEST(Reorder, SameMeshWithLocalNumbers) {
  StructuredBoxParams p;
  p.size = {16, 16, 8};
  p.cells = {16, 16, 8};
  p.nondesign = {{12, 0, 0, 16, 16, 8}};
  TetMesh m = structured_box_mesh(p);
  // scramble the numbering as a mesh generator might
  std::mt19937 rng(5);
  std::vector<int> perm(m.V.rows());
  std::iota(perm.begin(), perm.end(), 0);
  std::shuffle(perm.begin(), perm.end(), rng);
  TetMesh s = m;
  for (long i = 0; i < m.V.rows(); ++i) s.V.row(perm[i]) = m.V.row(i);
  for (long t = 0; t < m.T.rows(); ++t)
    for (int a = 0; a < 4; ++a) s.T(t, a) = perm[m.T(t, a)];
  for (long f = 0; f < m.F.rows(); ++f)
    for (int a = 0; a < 3; ++a) s.F(f, a) = perm[m.F(f, a)];
  TetMesh r = s;
  VecXi new_id = reorder_for_locality(r);
  // same tets with the same tags and orientation
  EXPECT_TRUE(tets_by_coordinates(r) == tets_by_coordinates(s));
  for (long t = 0; t < r.T.rows(); ++t) {
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) J.col(k) = (r.V.row(r.T(t, k + 1)) - r.V.row(r.T(t, 0))).transpose();
    ASSERT_GT(J.determinant(), 0);
  }
  // boundary triangles: same order, same corners, same faces
  ASSERT_EQ(r.F.rows(), s.F.rows());
  for (long f = 0; f < r.F.rows(); ++f) {
    for (int a = 0; a < 3; ++a) ASSERT_EQ((r.V.row(r.F(f, a)) - s.V.row(s.F(f, a))).norm(), 0.0);
    ASSERT_EQ(r.face[f], s.face[f]);
  }
  for (long i = 0; i < s.V.rows(); ++i) ASSERT_EQ((r.V.row(new_id[i]) - s.V.row(i)).norm(), 0.0);
  // locality: a tet's node numbers lie close together
  EXPECT_LT(median_tet_spread(r), 0.1 * median_tet_spread(s)) << median_tet_spread(r) << " vs " << median_tet_spread(s);
}

}  // namespace
}  // namespace topopt::mesh
