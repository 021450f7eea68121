#include "mesh/core/structured_box.h"

#include <gtest/gtest.h>

#include <map>

using namespace topopt;

namespace {
double tet_volume(const TetMesh& m, int t) {
  Eigen::Vector3d a = m.V.row(m.T(t, 1)) - m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 2)) - m.V.row(m.T(t, 0)),
                  c = m.V.row(m.T(t, 3)) - m.V.row(m.T(t, 0));
  return a.cross(b).dot(c) / 6.0;
}
}  // namespace

TEST(StructuredBox, ConformalPositiveAndTagged) {
  mesh::StructuredBoxParams p;
  p.origin = {1, 2, 3};
  p.size = {6, 4, 2};
  p.cells = {3, 2, 2};
  p.nondesign = {{1, 2, 3, 3, 6, 5}};  // the first third in x
  TetMesh m = mesh::structured_box_mesh(p);
  ASSERT_EQ(m.T.rows(), 6 * 12);
  double volume = 0, nd_volume = 0;
  for (int t = 0; t < m.T.rows(); ++t) {
    double v = tet_volume(m, t);
    EXPECT_GT(v, 0);
    volume += v;
    if (m.domain[t] == 1) nd_volume += v;
  }
  EXPECT_NEAR(volume, 48.0, 1e-12);
  EXPECT_NEAR(nd_volume, 16.0, 1e-12);
  // Every tet face is shared by two tets or is a boundary triangle, exactly once.
  std::map<std::array<int, 3>, int> count;
  static const int faces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (int t = 0; t < m.T.rows(); ++t)
    for (const auto& f : faces) {
      std::array<int, 3> key{m.T(t, f[0]), m.T(t, f[1]), m.T(t, f[2])};
      std::sort(key.begin(), key.end());
      ++count[key];
    }
  int boundary = 0;
  for (const auto& [key, n] : count) {
    EXPECT_LE(n, 2);
    boundary += n == 1;
  }
  EXPECT_EQ(boundary, m.F.rows());
  double area[7] = {0};
  for (int f = 0; f < m.F.rows(); ++f) {
    std::array<int, 3> key{m.F(f, 0), m.F(f, 1), m.F(f, 2)};
    std::sort(key.begin(), key.end());
    EXPECT_EQ(count[key], 1) << "boundary triangle " << f << " is not a tet face";
    Eigen::Vector3d a = m.V.row(m.F(f, 1)) - m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 2)) - m.V.row(m.F(f, 0));
    Eigen::Vector3d n = a.cross(b);
    Eigen::Vector3d centroid = (m.V.row(m.F(f, 0)) + m.V.row(m.F(f, 1)) + m.V.row(m.F(f, 2))).transpose() / 3;
    Eigen::Vector3d centre(4, 4, 4);
    EXPECT_GT(n.dot(centroid - centre), 0) << "triangle " << f << " points inwards";
    area[m.face[f]] += n.norm() / 2;
  }
  EXPECT_NEAR(area[1], 8, 1e-12);
  EXPECT_NEAR(area[2], 8, 1e-12);
  EXPECT_NEAR(area[3], 12, 1e-12);
  EXPECT_NEAR(area[4], 12, 1e-12);
  EXPECT_NEAR(area[5], 24, 1e-12);
  EXPECT_NEAR(area[6], 24, 1e-12);
}
