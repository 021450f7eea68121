// The 3D advancing front on closed surfaces built in code: conformal, positive, volume
// exact, boundary unchanged; and a box already holding tets, which stay as they are.
#include "mesh/volume_front.h"

#include <gtest/gtest.h>

#include <cmath>

#include "io/msh.h"
#include "mesh/conformity.h"
#include "mesh/structured_box.h"
#include "mesh/tet_quality.h"
#include "simp/density_filter.h"

namespace topopt::mesh {
namespace {

/// The closed surface of the given tets (outward), on compacted nodes.
void surface_of(const TetMesh& m, const std::vector<int>& keep, MatX3d& V, MatX3i& F) {
  MatX4i T(keep.size(), 4);
  for (size_t i = 0; i < keep.size(); ++i) T.row(i) = m.T.row(keep[i]);
  MatX3i B = io::boundary_triangles(T);
  std::vector<int> map(m.V.rows(), -1);
  std::vector<Eigen::RowVector3d> pts;
  F.resize(B.rows(), 3);
  for (long t = 0; t < B.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      int v = B(t, k);
      if (map[v] < 0) map[v] = static_cast<int>(pts.size()), pts.push_back(m.V.row(v));
      F(t, k) = map[v];
    }
  V.resize(pts.size(), 3);
  for (size_t i = 0; i < pts.size(); ++i) V.row(i) = pts[i];
}

/// Checks the filled mesh (T0 ∪ new tets) against the surface and returns its volume.
double check_fill(const MatX3d& V, const MatX3i& F, const MatX4i& T0, const VolumeFillResult& r, double expected_volume) {
  TetMesh m;
  m.V = r.V;
  m.T.resize(T0.rows() + r.T.rows(), 4);
  if (T0.rows()) m.T.topRows(T0.rows()) = T0;
  m.T.bottomRows(r.T.rows()) = r.T;
  m.domain = VecXi::Zero(m.T.rows());
  m.F = F;
  m.face = VecXi::Ones(F.rows());
  EXPECT_EQ(r.V.topRows(V.rows()), V) << "input nodes moved";
  ConformityReport c = check_conformity(m);
  EXPECT_EQ(c.inverted_tets, 0);
  EXPECT_EQ(c.overshared_faces, 0);
  EXPECT_EQ(c.boundary_not_in_F, 0) << "the mesh's boundary is not the input surface";
  EXPECT_EQ(c.F_not_boundary, 0);
  EXPECT_EQ(c.duplicate_nodes, 0);
  double vol = simp::tet_volumes(m).sum();
  EXPECT_NEAR(vol, expected_volume, 1e-9 * expected_volume);
  return vol;
}

TEST(VolumeFront, FillsABox) {
  StructuredBoxParams p;
  p.size = {4, 3, 2};
  p.cells = {8, 6, 4};
  TetMesh box = structured_box_mesh(p);
  std::vector<int> all(box.T.rows());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  MatX3d V;
  MatX3i F;
  surface_of(box, all, V, F);
  VolumeFillResult r = fill_volume(V, F, MatX4i());
  check_fill(V, F, MatX4i(), r, 24.0);
  TetMesh m;
  m.V = r.V, m.T = r.T;
  QualityReport q = tet_quality(m);
  // No flips or sliver removal yet: a few slivers remain (issue 4's targets are not met yet);
  // this bounds what the engine does today so that it cannot get worse unnoticed.
  EXPECT_GT(q.min_radius_ratio, 0.0);
  EXPECT_LT(q.share_radius_ratio_below_01, 0.03);
  EXPECT_GT(q.mean_radius_ratio, 0.65);
}

TEST(VolumeFront, FillsANonConvexLShapeWithAHole) {
  StructuredBoxParams p;
  p.size = {6, 6, 2};
  p.cells = {12, 12, 4};
  TetMesh box = structured_box_mesh(p);
  MatX3d c = simp::tet_centroids(box);
  std::vector<int> keep;
  double removed = 0;
  VecXd vol = simp::tet_volumes(box);
  for (long t = 0; t < box.T.rows(); ++t) {
    bool notch = c(t, 0) > 3 && c(t, 1) > 3;                                     // L-shape
    bool hole = c(t, 0) > 1 && c(t, 0) < 2 && c(t, 1) > 1 && c(t, 1) < 2;        // a through hole
    if (notch || hole)
      removed += vol[t];
    else
      keep.push_back(static_cast<int>(t));
  }
  MatX3d V;
  MatX3i F;
  surface_of(box, keep, V, F);
  VolumeFillResult r = fill_volume(V, F, MatX4i());
  check_fill(V, F, MatX4i(), r, 72.0 - removed);
}

TEST(VolumeFront, FillsAPrismOverAPolygon) {
  // a 24-gon prism of radius 3 and height 2: fans at both ends, split quads around
  const int n = 24;
  MatX3d V(2 * n + 2, 3);
  for (int i = 0; i < n; ++i) {
    double a = 2 * M_PI * i / n;
    V.row(i) << 3 * std::cos(a), 3 * std::sin(a), 0;
    V.row(n + i) << 3 * std::cos(a), 3 * std::sin(a), 2;
  }
  V.row(2 * n) << 0, 0, 0;
  V.row(2 * n + 1) << 0, 0, 2;
  MatX3i F(4 * n, 3);
  for (int i = 0; i < n; ++i) {
    int j = (i + 1) % n;
    F.row(4 * i) << 2 * n, j, i;              // bottom, outward −z
    F.row(4 * i + 1) << 2 * n + 1, n + i, n + j;  // top, outward +z
    F.row(4 * i + 2) << i, j, n + j;          // side
    F.row(4 * i + 3) << i, n + j, n + i;
  }
  double area = 0.5 * n * 9 * std::sin(2 * M_PI / n);
  VolumeFillResult r = fill_volume(V, F, MatX4i());
  check_fill(V, F, MatX4i(), r, 2 * area);
}

TEST(VolumeFront, KeepsTetsAlreadyThereUnchanged) {
  StructuredBoxParams p;
  p.size = {4, 4, 4};
  p.cells = {6, 6, 6};
  TetMesh box = structured_box_mesh(p);
  MatX3d c = simp::tet_centroids(box);
  // the whole box's surface, a slab of tets along x = 0 and one isolated tet touching the
  // boundary at a single node (the corner (4, 4, 4))
  std::vector<int> all(box.T.rows());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  MatX3d V;
  MatX3i F;
  surface_of(box, all, V, F);
  std::vector<Eigen::RowVector4i> t0;
  std::vector<Eigen::RowVector3d> extra;
  // slab: the structured tets with centroid x < 0.7, on the surface's nodes where they exist
  std::vector<int> map(box.V.rows(), -1);
  for (long i = 0; i < V.rows(); ++i)
    for (long j = 0; j < box.V.rows(); ++j)
      if ((box.V.row(j) - V.row(i)).norm() < 1e-12) map[j] = static_cast<int>(i);
  MatX3d VV = V;
  auto node = [&](int j) {
    if (map[j] < 0) {
      map[j] = static_cast<int>(VV.rows());
      VV.conservativeResize(VV.rows() + 1, 3);
      VV.row(VV.rows() - 1) = box.V.row(j);
    }
    return map[j];
  };
  for (long t = 0; t < box.T.rows(); ++t)
    if (c(t, 0) < 0.7) t0.push_back({node(box.T(t, 0)), node(box.T(t, 1)), node(box.T(t, 2)), node(box.T(t, 3))});
  int corner = -1;
  for (long i = 0; i < V.rows(); ++i)
    if ((V.row(i) - Eigen::RowVector3d(4, 4, 4)).norm() < 1e-12) corner = static_cast<int>(i);
  ASSERT_GE(corner, 0);
  int base = static_cast<int>(VV.rows());
  VV.conservativeResize(base + 3, 3);
  VV.row(base) << 3.3, 3.6, 3.55;
  VV.row(base + 1) << 3.6, 3.3, 3.55;
  VV.row(base + 2) << 3.6, 3.6, 3.2;
  Eigen::RowVector4i lone(corner, base, base + 1, base + 2);
  {
    Eigen::Vector3d a = VV.row(lone[0]), b = VV.row(lone[1]), cc = VV.row(lone[2]), d = VV.row(lone[3]);
    if ((b - a).dot((cc - a).cross(d - a)) < 0) std::swap(lone[2], lone[3]);
  }
  t0.push_back(lone);
  MatX4i T0(t0.size(), 4);
  for (size_t i = 0; i < t0.size(); ++i) T0.row(i) = t0[i];
  ASSERT_GT(T0.rows(), 100);
  VolumeFillResult r = fill_volume(VV, F, T0);
  check_fill(VV, F, T0, r, 64.0);
}

}  // namespace
}  // namespace topopt::mesh
