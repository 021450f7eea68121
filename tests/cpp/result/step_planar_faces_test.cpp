// Planar faces on the triangle surface: coplanar triangles grouped into the polyhedron's faces,
// loops oriented with the face on their left, straight runs reduced to the polygon's corners,
// and the points next to triangles left out of the merge kept.
#include "result/step_planar_faces.h"

#include <gtest/gtest.h>

#include <array>
#include <map>
#include <set>
#include <tuple>

namespace topopt::result {
namespace {

using Cell = std::array<int, 3>;

/// The closed, outward boundary of the union of unit cells `cells` (each cell [i, i+1] x [j,
/// j+1] x [k, k+1] scaled by `h`): two triangles per cell side not shared with another cell,
/// points shared. Tags 0.
TriSurface voxel_surface(const std::set<Cell>& cells, double h) {
  std::map<Cell, int> index;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::array<int, 3>> tris;
  const auto id = [&](Cell c) {
    const auto [it, added] = index.emplace(c, static_cast<int>(points.size()));
    if (added) points.emplace_back(h * c[0], h * c[1], h * c[2]);
    return it->second;
  };
  for (const Cell& c : cells)
    for (int axis = 0; axis < 3; ++axis)
      for (int side : {0, 1}) {
        Cell next = c;
        next[axis] += side ? 1 : -1;
        if (cells.count(next)) continue;
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        std::array<int, 4> q;
        for (int corner = 0; corner < 4; ++corner) {
          Cell p = c;
          p[axis] += side;
          p[u] += corner == 1 || corner == 2;
          p[v] += corner >= 2;
          q[corner] = id(p);
        }
        // (u, v) turns about +axis: counter-clockwise seen from +axis on the side 1
        if (side) {
          tris.push_back({q[0], q[1], q[2]}), tris.push_back({q[0], q[2], q[3]});
        } else {
          tris.push_back({q[0], q[2], q[1]}), tris.push_back({q[0], q[3], q[2]});
        }
      }
  TriSurface s;
  s.V.resize(static_cast<long>(points.size()), 3);
  for (size_t i = 0; i < points.size(); ++i) s.V.row(static_cast<long>(i)) = points[i].transpose();
  s.F.resize(static_cast<long>(tris.size()), 3);
  for (size_t i = 0; i < tris.size(); ++i) s.F.row(static_cast<long>(i)) << tris[i][0], tris[i][1], tris[i][2];
  s.tag = VecXi::Zero(s.F.rows());
  s.lock = VecXi::Zero(s.V.rows());
  return s;
}

/// The cells of the box [0, nx) x [0, ny) x [0, nz).
std::set<Cell> box(int nx, int ny, int nz) {
  std::set<Cell> out;
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k) out.insert({i, j, k});
  return out;
}

/// Area vector of the closed polygon `loop` of points of s.
Eigen::Vector3d loop_area(const TriSurface& s, const std::vector<int>& loop) {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < loop.size(); ++i)
    a += s.V.row(loop[i]).transpose().cross(s.V.row(loop[(i + 1) % loop.size()]).transpose()) / 2;
  return a;
}

/// Every face's loops enclose its triangles' area on the outward side (outer loop
/// counter-clockwise, holes clockwise), every triangle is in one face, every face is flat.
void expect_sound(const TriSurface& s, const std::vector<PlanarFace>& faces, long mergeable) {
  long triangles = 0;
  for (const PlanarFace& f : faces) {
    Eigen::Vector3d area = Eigen::Vector3d::Zero(), loops = Eigen::Vector3d::Zero();
    for (long q : f.triangles) {
      const Eigen::Vector3d a = s.V.row(s.F(q, 0)).transpose();
      area += (s.V.row(s.F(q, 1)).transpose() - a).cross(s.V.row(s.F(q, 2)).transpose() - a) / 2;
      for (int k = 0; k < 3; ++k) EXPECT_NEAR((s.V.row(s.F(q, k)).transpose() - f.origin).dot(f.normal), 0, 1e-12);
    }
    for (const auto& loop : f.loops) loops += loop_area(s, loop);
    EXPECT_NEAR((loops - area).norm(), 0, 1e-9 * std::max(1.0, area.norm()));
    EXPECT_NEAR(area.normalized().dot(f.normal), 1, 1e-12);
    triangles += static_cast<long>(f.triangles.size());
  }
  EXPECT_EQ(triangles, mergeable);
}

TEST(StepPlanarFaces, ABoxOfManyTrianglesIsSixFacesOfFourCorners) {
  const TriSurface s = voxel_surface(box(5, 3, 2), 0.7);
  const std::vector<PlanarFace> faces = planar_faces(s, std::vector<char>(s.F.rows(), 1));
  ASSERT_EQ(faces.size(), 6u);
  for (const PlanarFace& f : faces) {
    ASSERT_EQ(f.loops.size(), 1u);
    EXPECT_EQ(f.loops[0].size(), 4u);  // the points along the box's edges dropped
  }
  expect_sound(s, faces, s.F.rows());
}

TEST(StepPlanarFaces, AnLShapeKeepsItsSixCornersAndARingItsHole) {
  // an L-shaped prism: two 2x1 faces, six rectangles
  std::set<Cell> l = box(4, 2, 2);
  for (const Cell& c : box(2, 2, 2)) l.insert({c[0], c[1], c[2] + 2});
  const TriSurface sl = voxel_surface(l, 1);
  const std::vector<PlanarFace> fl = planar_faces(sl, std::vector<char>(sl.F.rows(), 1));
  ASSERT_EQ(fl.size(), 8u);
  std::multiset<size_t> corners;
  for (const PlanarFace& f : fl) corners.insert(f.loops.at(0).size());
  EXPECT_EQ(corners, (std::multiset<size_t>{4, 4, 4, 4, 4, 4, 6, 6}));
  expect_sound(sl, fl, sl.F.rows());
  // a square ring: top and bottom are faces with a hole (two loops of four corners)
  std::set<Cell> ring = box(3, 3, 1);
  ring.erase({1, 1, 0});
  const TriSurface sr = voxel_surface(ring, 2);
  const std::vector<PlanarFace> fr = planar_faces(sr, std::vector<char>(sr.F.rows(), 1));
  ASSERT_EQ(fr.size(), 10u);
  int holed = 0;
  for (const PlanarFace& f : fr)
    if (f.loops.size() == 2) {
      ++holed;
      EXPECT_EQ(f.loops[0].size() + f.loops[1].size(), 8u);
    }
  EXPECT_EQ(holed, 2);
  expect_sound(sr, fr, sr.F.rows());
}

TEST(StepPlanarFaces, TrianglesLeftOutKeepTheirPointsAndNoAngleMergesNothing) {
  const TriSurface s = voxel_surface(box(3, 3, 3), 1);
  // the side x = 3 left out (as a curved input face would be): the four faces next to it keep
  // every point along their edge with it (4 corners + 2 points each)
  std::vector<char> mergeable(s.F.rows(), 1);
  long left_out = 0;
  for (long q = 0; q < s.F.rows(); ++q)
    if (s.V(s.F(q, 0), 0) == 3 && s.V(s.F(q, 1), 0) == 3 && s.V(s.F(q, 2), 0) == 3) mergeable[q] = 0, ++left_out;
  ASSERT_EQ(left_out, 18);
  const std::vector<PlanarFace> faces = planar_faces(s, mergeable);
  ASSERT_EQ(faces.size(), 5u);
  std::multiset<size_t> corners;
  for (const PlanarFace& f : faces) corners.insert(f.loops.at(0).size());
  EXPECT_EQ(corners, (std::multiset<size_t>{4, 6, 6, 6, 6}));
  expect_sound(s, faces, s.F.rows() - left_out);
  // a negative angle: every triangle its own face
  EXPECT_EQ(planar_faces(s, std::vector<char>(s.F.rows(), 1), {-1, -1}).size(), static_cast<size_t>(s.F.rows()));
}

}  // namespace
}  // namespace topopt::result
