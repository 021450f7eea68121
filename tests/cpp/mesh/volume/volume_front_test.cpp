// The 3D volume fill on closed surfaces built in code — with the Delaunay bulk (the default)
// and by the advancing front alone: conformal, positive, volume exact, boundary unchanged;
// a box already holding tets, which stay as they are; the rocker at issue 4's quality bounds
// and a part graded from a fine boundary. (The Delaunay bulk's own tests: delaunay_bulk_test.)
#include "mesh/volume/volume_front.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "brep/two_breps.h"
#include "mesh/core/structured_box.h"
#include "mesh/core/tet_quality.h"
#include "mesh/volume/volume_checks.h"
#include "pipeline/mesh_model.h"

namespace topopt::mesh {
namespace {

/// Every fill test runs twice: Delaunay bulk then front (the default), and front alone.
class VolumeFill : public ::testing::TestWithParam<bool> {
 protected:
  static VolumeFillParams params() {
    VolumeFillParams p;
    p.delaunay_bulk = GetParam();
    return p;
  }
};

TEST_P(VolumeFill, FillsABox) {
  StructuredBoxParams p;
  p.size = {4, 3, 2};
  p.cells = {8, 6, 4};
  TetMesh box = structured_box_mesh(p);
  std::vector<int> all(box.T.rows());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  MatX3d V;
  MatX3i F;
  surface_of(box, all, V, F);
  VolumeFillResult r = fill_volume(V, F, MatX4i(), params());
  check_fill(V, F, MatX4i(), r, 24.0);
  TetMesh m;
  m.V = r.V, m.T = r.T;
  QualityReport q = tet_quality(m);
  // after flips, smoothing and sliver removal (issue 4's bounds for the rocker are 0.2 worst
  // and 12°; this coarse box, whose structured faces the bulk cannot use, reaches 11°)
  EXPECT_GT(q.min_radius_ratio, 0.2);
  EXPECT_GT(q.min_dihedral, 10.0);
  EXPECT_GT(q.mean_radius_ratio, 0.65);
}

/// The surface of a 6 x 6 x 2 L-shape (the quarter x > 3, y > 3 cut away) with a through hole
/// over 1 < x, y < 2, from a structured mesh; returns its volume. With `jitter`, each node
/// coordinate that is not an integer (every face lies on an integer plane) moves by up to
/// that much, which keeps the node within its faces, so that no four nodes of a face
/// are cocircular (a structured face is cocircular everywhere, and a tetrahedralisation then
/// picks the other diagonal of each square).
double l_shape_surface(MatX3d& V, MatX3i& F, double jitter = 0) {
  StructuredBoxParams p;
  p.size = {6, 6, 2};
  p.cells = {12, 12, 4};
  TetMesh box = structured_box_mesh(p);
  MatX3d c = simp::tet_centroids(box);
  std::vector<int> keep;
  double removed = 0;
  VecXd vol = simp::tet_volumes(box);
  for (long t = 0; t < box.T.rows(); ++t) {
    bool notch = c(t, 0) > 3 && c(t, 1) > 3;                               // L-shape
    bool hole = c(t, 0) > 1 && c(t, 0) < 2 && c(t, 1) > 1 && c(t, 1) < 2;  // a through hole
    if (notch || hole)
      removed += vol[t];
    else
      keep.push_back(static_cast<int>(t));
  }
  surface_of(box, keep, V, F);
  unsigned seed = 2026;
  for (long i = 0; i < V.rows(); ++i)
    for (int k = 0; k < 3; ++k)
      if (jitter > 0 && std::abs(V(i, k) - std::round(V(i, k))) > 1e-9) {
        seed = seed * 1664525u + 1013904223u;
        V(i, k) += jitter * (((seed >> 8) & 0xFFFF) / 32767.5 - 1.0);
      }
  return 72.0 - removed;
}

TEST_P(VolumeFill, FillsANonConvexLShapeWithAHole) {
  MatX3d V;
  MatX3i F;
  for (double jitter : {0.0, 0.1}) {
    const double volume = l_shape_surface(V, F, jitter);
    VolumeFillResult r = fill_volume(V, F, MatX4i(), params());
    check_fill(V, F, MatX4i(), r, volume);
  }
}

TEST_P(VolumeFill, FillsAPrismOverAPolygon) {
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
    F.row(4 * i) << 2 * n, j, i;                  // bottom, outward −z
    F.row(4 * i + 1) << 2 * n + 1, n + i, n + j;  // top, outward +z
    F.row(4 * i + 2) << i, j, n + j;              // side
    F.row(4 * i + 3) << i, n + j, n + i;
  }
  double area = 0.5 * n * 9 * std::sin(2 * M_PI / n);
  VolumeFillResult r = fill_volume(V, F, MatX4i(), params());
  check_fill(V, F, MatX4i(), r, 2 * area);
}

TEST_P(VolumeFill, KeepsTetsAlreadyThereUnchanged) {
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
  VolumeFillResult r = fill_volume(VV, F, T0, params());
  check_fill(VV, F, T0, r, 64.0);
}

/// The retry by the front alone is for a fill that started from a Delaunay bulk and could
/// not finish; a fill that fails otherwise (here: nothing to fill) fails once, by name,
/// without a retry that would do the same work again or a warning about a bulk it never had.
TEST(VolumeFill, AFailureWithoutABulkIsNotRetriedByTheFrontAlone) {
  std::string log;
  Progress pr;
  pr.log = [&log](LogLevel, const std::string& m) { log += m + "\n"; };
  try {
    fill_volume(MatX3d(0, 3), MatX3i(0, 3), MatX4i(), VolumeFillParams(), pr);
    FAIL() << "an empty boundary was filled";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::MeshingFailed);
    EXPECT_NE(std::string(e.what()).find("nothing to fill"), std::string::npos) << e.what();
  }
  EXPECT_EQ(log.find("front alone"), std::string::npos) << log;
}

/// NIST 2 as the product meshes it (`topopt mesh --mesher native`, default size): the Delaunay
/// bulk (1.08 M tets) lacks 116 boundary triangles, and the front's first round closes all
/// but 12 faces around them. Before, the whole bulk was then thrown away and the part filled
/// again by the front alone (1.25 M tets, 234 s CPU instead of about 50); now the stuck region
/// is re-meshed locally (90 tets) and closes in one round. No small fixture was found that
/// leaves faces stuck (boxes of 30-250 mm cut out of NIST 2 around them close in the first
/// round; a sweep over coarser sizes did not finish in time), so this takes the whole part:
/// about 100 s of CPU.
TEST(VolumeFill, Nist2BulkHolesCloseByLocalReMeshingWithoutTheFrontAlone) {
  std::string info, warnings;
  Progress pr;
  pr.log = [&](LogLevel level, const std::string& m) { (level == LogLevel::Warning ? warnings : info) += m + "\n"; };
  const brep::TwoBReps model = brep::load_two_breps(
      brep::read_shape_file(std::string(TOPOPT_SHARED_DATA) + "/nist/NIST_MBE_PMI_2.stp"), TopoDS_Shape());
  pipeline::MeshSettings settings;
  settings.mesher = pipeline::Mesher::Native;
  const TetMesh m = pipeline::mesh_model(model, settings, pr);
  // the case still trips the mechanism: the front got stuck on the bulk and re-meshed around it
  EXPECT_NE(info.find("Delaunay bulk of"), std::string::npos) << info;
  EXPECT_NE(info.find("re-meshing around a stuck region"), std::string::npos) << info;
  EXPECT_EQ(warnings.find("front alone"), std::string::npos) << warnings;
  const ConformityReport c = check_conformity(m, &model);
  EXPECT_TRUE(c.ok()) << c.describe();
  EXPECT_EQ(c.flat_tets, 0);
  const QualityReport q = tet_quality(m);
  EXPECT_GE(q.min_radius_ratio, 0.1);
  EXPECT_LT(m.T.rows(), 1'150'000);  // the bulk kept: about 1.04 M (the front alone made 1.25 M)
}

TEST(VolumeFill, RockerAtOneMillimetreMeetsIssueFoursQualityBounds) {
  // issue 4's case: the rocker's surface at 1 mm filled at 1 mm (about 140 000 tets): radius
  // ratio min >= 0.2 and mean >= 0.78, smallest dihedral >= 12 deg (bench/volume times it).
  // The shape goes through a BREP string, as from FreeCAD and in the bench (its surface then
  // differs slightly from the STEP file's)
  const TopoDS_Shape rocker = brep::read_shape_file(std::string(TOPOPT_SHARED_DATA) + "/examples/rocker.step");
  const brep::TopologyIndex topo =
      brep::index_topology(brep::read_brep_string(brep::write_brep_string(rocker), "rocker"));
  SurfaceMeshParams sp;
  sp.size = 1.0;
  const SurfaceMesh s = mesh_surface(topo, sp);
  ASSERT_TRUE(s.failed_faces.empty());
  long tets = 0;
  const QualityReport q = fill_at_size(s.V, s.F, 1.0, &tets);
  EXPECT_GT(tets, 100000);
  EXPECT_GE(q.min_radius_ratio, 0.2);
  EXPECT_GE(q.mean_radius_ratio, 0.78);
  EXPECT_GE(q.min_dihedral, 12.0);
}

TEST(VolumeFill, GradesFromAFineBoundaryWithoutASize) {
  // CrankArm's two solids (edges from 0.07 to 5 mm; the bulk gives up on them, 2.5 % of the
  // triangles missing, and the front fills alone). Without a size the front used to keep its
  // finest faces' size across the whole volume and ran towards 20 M tets; the size now grows
  // from the boundary's spacing
  const SurfaceMesh s = default_surface("occt/CrankArm.brep");
  ASSERT_TRUE(s.failed_faces.empty());
  const double volume = surface_volume(s.V, s.F);
  const VolumeFillResult r = fill_volume(s.V, s.F, MatX4i());
  check_fill(s.V, s.F, MatX4i(), r, volume);
  EXPECT_LT(r.T.rows(), 150000);  // about 42 000; the runaway passed a million in 30 s
}

/// A shared part's surface at its default size, filled with the default settings: conformal,
/// the volume of the surface, no flat tet, no tet below radius ratio `floor` and at most
/// `share` of them below 0.1 (issue 20 asks for none below 0.1 anywhere).
void expect_no_sliver(const std::string& file, double floor = 0.1, double share = 0) {
  const SurfaceMesh s = default_surface(file);
  ASSERT_TRUE(s.failed_faces.empty()) << file;
  const double volume = surface_volume(s.V, s.F);
  const VolumeFillResult r = fill_volume(s.V, s.F, MatX4i());
  check_fill(s.V, s.F, MatX4i(), r, volume);
  TetMesh m;
  m.V = r.V, m.T = r.T;
  m.F = s.F;
  m.domain = VecXi::Zero(m.T.rows());
  const ConformityReport c = check_conformity(m);
  EXPECT_EQ(c.flat_tets, 0) << c.describe();
  const QualityReport q = tet_quality(m);
  EXPECT_GE(q.min_radius_ratio, floor) << file;
  EXPECT_LE(q.share_radius_ratio_below_01, share) << file;
  EXPECT_GT(q.mean_radius_ratio, 0.7) << file;
}

// one part per family of ../shared/data (bench/volume --product covers them all, at the
// default size and at 0.6x, through the product's path)
TEST(VolumeFillQuality, NoSliverOnTheBracketExample) { expect_no_sliver("examples/bracket.step"); }
TEST(VolumeFillQuality, NoSliverOnNist5) {
  // before remove_slivers (perturbation of sliver nodes, flips, wider refills in rounds): worst
  // 0.038, 0.12 % of the tets below 0.1 here
  expect_no_sliver("nist/NIST_MBE_PMI_5.stp");
}
TEST(VolumeFillQuality, NoSliverOnLinkrods) { expect_no_sliver("occt/linkrods.step"); }
TEST(VolumeFillQuality, NoSliverOnNist1) { expect_no_sliver("nist/NIST_MBE_PMI_1.stp"); }

INSTANTIATE_TEST_SUITE_P(BulkThenFrontAndFrontAlone, VolumeFill, ::testing::Values(true, false),
                         [](const ::testing::TestParamInfo<bool>& i) {
                           return i.param ? "DelaunayBulk" : "FrontAlone";
                         });

}  // namespace
}  // namespace topopt::mesh
