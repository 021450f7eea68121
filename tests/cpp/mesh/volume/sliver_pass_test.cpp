// The last sliver pass on a finished tagged mesh: a structured box with a non-design lower
// half whose nodes on a boundary plane and on the interface plane have been slid within their
// plane until their tets are slivers — slivers the fills' improvement cannot reach, since it
// never moves such nodes. The pass must lift every tet to radius ratio 0.1, keep the mesh
// conformal, every domain's volume, every boundary and interface node in its plane and every
// node of an edge where it was. And NIST 6's four slivers that hold each other around a node of
// a curved face: the pass splits that node.
#include "mesh/volume/sliver_pass.h"

#include <gtest/gtest.h>

#include <cmath>

#include "mesh/core/conformity.h"
#include "mesh/core/predicates.h"
#include "mesh/core/structured_box.h"
#include "mesh/core/tet_quality.h"
#include "io/msh.h"

namespace topopt::mesh {
namespace {

using Vec3 = Eigen::Vector3d;

/// 4 x 4 x 4 unit cells, the lower half (z < 2) non-design: an interface at z = 2.
TetMesh two_domain_box() {
  StructuredBoxParams p;
  p.size = {4, 4, 4};
  p.cells = {4, 4, 4};
  p.nondesign = {{0, 0, 0, 4, 4, 2}};
  return structured_box_mesh(p);
}

int node_at(const TetMesh& m, const Vec3& x) {
  for (long i = 0; i < m.V.rows(); ++i)
    if ((m.V.row(i).transpose() - x).norm() < 1e-12) return static_cast<int>(i);
  return -1;
}

double worst(const TetMesh& m) {
  double w = 1;
  for (long t = 0; t < m.T.rows(); ++t)
    w = std::min(w, radius_ratio(m.V.row(m.T(t, 0)), m.V.row(m.T(t, 1)), m.V.row(m.T(t, 2)), m.V.row(m.T(t, 3))));
  return w;
}

bool all_positive(const TetMesh& m) {
  for (long t = 0; t < m.T.rows(); ++t) {
    const Vec3 a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)), d = m.V.row(m.T(t, 3));
    if (predicates::orient3d(a.data(), b.data(), c.data(), d.data()) <= 0) return false;
  }
  return true;
}

/// What the pass must leave: no tet below radius ratio 0.1, every tet positively oriented, a
/// conformal mesh and, unless `kept` is null (moves along a curved face change the faceted
/// volume), every domain's volume as in `kept` to 1e-9.
void expect_sound(const TetMesh& m, const ConformityReport* kept) {
  EXPECT_GE(worst(m), 0.1);
  EXPECT_TRUE(all_positive(m));
  const ConformityReport c = check_conformity(m);
  EXPECT_TRUE(c.ok()) << c.to_json().dump();
  if (!kept) return;
  ASSERT_EQ(c.domain_volume.size(), kept->domain_volume.size());
  for (size_t d = 0; d < c.domain_volume.size(); ++d)
    EXPECT_NEAR(c.domain_volume[d], kept->domain_volume[d], 1e-9 * kept->domain_volume[d]) << "domain " << d;
}

/// The planes x, y, z = 0 or 4 and the interface z = 2 a node lies on (bit k: coordinate k/3
/// at value k%3 of {0, 2, 4}; 2 only for z).
int planes_of(const Vec3& x) {
  int bits = 0;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k)
      if ((k != 1 || c == 2) && x[c] == 2.0 * k) bits |= 1 << (3 * c + k);
  return bits;
}

/// Slides node v from its place towards `to` (a fraction of the way), within its plane.
void slide(TetMesh& m, int v, const Vec3& to, double fraction) {
  const Vec3 x = m.V.row(v);
  m.V.row(v) = (x + fraction * (to - x)).transpose();
}

TEST(SliverPass, LiftsSliversOfBoundaryAndInterfaceNodesWithinTheirPlanes) {
  TetMesh m = two_domain_box();
  const int floor_node = node_at(m, {2, 2, 0}), wall_node = node_at(m, {4, 1, 3}), interface_node = node_at(m, {1, 2, 2});
  ASSERT_GE(floor_node, 0);
  ASSERT_GE(wall_node, 0);
  ASSERT_GE(interface_node, 0);
  const ConformityReport c0 = check_conformity(m);
  ASSERT_TRUE(c0.ok());
  slide(m, floor_node, {3, 2, 0}, 0.93);       // on the face z = 0
  slide(m, wall_node, {4, 2, 3}, 0.94);        // on the face x = 4
  slide(m, interface_node, {1, 3, 2}, 0.95);   // on the interface z = 2
  ASSERT_TRUE(all_positive(m));
  ASSERT_LT(worst(m), 0.1);  // the fixture holds slivers
  const TetMesh before = m;

  const SliverPassReport r = remove_final_slivers(m);
  EXPECT_GT(r.below_before, 0);
  EXPECT_EQ(r.below_after, 0);
  EXPECT_GT(r.moved_plane, 0);
  expect_sound(m, &c0);
  EXPECT_EQ(m.F, before.F);
  EXPECT_EQ(m.face, before.face);
  // every node keeps its planes; a node on two or more (an edge, a corner, where the interface
  // meets the boundary) does not move at all; old nodes keep their numbers
  ASSERT_GE(m.V.rows(), before.V.rows());
  for (long i = 0; i < before.V.rows(); ++i) {
    const Vec3 was = before.V.row(i), now = m.V.row(i);
    const int bits = planes_of(was);
    EXPECT_EQ(planes_of(now) & bits, bits) << "node " << i << " left a plane";
    if (__builtin_popcount(bits) >= 2) {
      EXPECT_EQ(was, now) << "node " << i << " on an edge moved";
    }
  }
}

TEST(SliverPass, SlidesANodeOfACurvedFaceOnItThroughTheProjection) {
  // the box's top (face 6) lifted onto a sphere of radius 10 whose cap rises 0.5 above z = 4
  TetMesh m = two_domain_box();
  const Vec3 centre(2, 2, 4.5 - 10);
  const double radius = 10;
  auto onto_sphere = [&](Vec3& x) { x = centre + radius * (x - centre).normalized(); };
  for (long i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 2) == 4.0) {
      Vec3 x = m.V.row(i);
      x.z() = centre.z() + std::sqrt(radius * radius - std::pow(x.x() - 2, 2) - std::pow(x.y() - 2, 2));
      m.V.row(i) = x.transpose();
    }
  const int top = node_at(m, {2, 1, centre.z() + std::sqrt(radius * radius - 1)});
  ASSERT_GE(top, 0);
  Vec3 to(3, 1, 4);  // slid towards its neighbour, back on the sphere, until its tets are slivers
  onto_sphere(to);
  const TetMesh lifted = m;
  for (double fraction = 0.5; fraction < 1 && !(all_positive(m) && worst(m) < 0.1); fraction += 0.01) {
    m = lifted;
    slide(m, top, to, fraction);
    Vec3 x = m.V.row(top);
    onto_sphere(x);
    m.V.row(top) = x.transpose();
  }
  ASSERT_TRUE(all_positive(m));
  ASSERT_LT(worst(m), 0.1);
  const TetMesh before = m;

  SliverPassParams without;  // no projection: the node may not move (a re-filled cavity may still lift the sliver)
  TetMesh fixed = m;
  EXPECT_EQ(remove_final_slivers(fixed, without).moved_curved, 0);
  EXPECT_EQ(fixed.V.row(top), before.V.row(top));

  SliverPassParams params;
  params.onto_face = [&](int face, Vec3& y) {
    if (face != 6) return false;
    onto_sphere(y);
    return true;
  };
  const SliverPassReport r = remove_final_slivers(m, params);
  EXPECT_EQ(r.below_after, 0);
  EXPECT_GT(r.moved_curved, 0);
  expect_sound(m, nullptr);
  for (long i = 0; i < before.V.rows(); ++i) {
    const Vec3 was = before.V.row(i), now = m.V.row(i);
    if (std::abs((was - centre).norm() - radius) < 1e-12) {
      EXPECT_NEAR((now - centre).norm(), radius, 1e-9) << "node " << i << " left the sphere";
    }
    const int bits = planes_of(was) & ~(1 << 8);  // not the flat top any more
    EXPECT_EQ(planes_of(now) & bits, bits) << "node " << i << " left a plane";
  }
}

TEST(SliverPass, SplitsTheFaceNodeOfSliversThatHoldEachOther) {
  // NIST 6's last four slivers with the balls of their nodes (tests/data/slivers/README.md):
  // every move of one node lifts one sliver and drops another, and the flips and one-point
  // refills find nothing; the face node they share must keep its place
  const std::string path = std::string(TOPOPT_TEST_DATA) + "/slivers/nist6_locked_cluster.msh";
  const TetMesh cluster = io::read_msh(path);
  const ConformityReport c0 = check_conformity(cluster);
  ASSERT_TRUE(c0.ok()) << c0.to_json().dump();
  ASSERT_LT(worst(cluster), 0.1);

  SliverPassParams without;
  without.split_boundary_nodes = false;
  TetMesh locked = cluster;
  const SliverPassReport r0 = remove_final_slivers(locked, without);
  EXPECT_EQ(r0.below_after, r0.below_before) << "the fixture's slivers no longer hold each other";
  EXPECT_LT(worst(locked), 0.1);

  TetMesh m = cluster;
  const SliverPassReport r = remove_final_slivers(m);
  EXPECT_EQ(r.below_before, 4);
  EXPECT_EQ(r.below_after, 0);
  expect_sound(m, &c0);
  EXPECT_EQ(m.F, cluster.F);
  EXPECT_EQ(m.face, cluster.face);
  EXPECT_GT(m.V.rows(), cluster.V.rows());  // the split's inner point
  // without a projection no node of the boundary moves (the cut's and the faces' alike)
  for (long f = 0; f < cluster.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(m.V.row(cluster.F(f, k)), cluster.V.row(cluster.F(f, k))) << "node " << cluster.F(f, k);
    }
}

TEST(SliverPass, LeavesAMeshWithoutSliversAsItIs) {
  TetMesh m = two_domain_box();
  const TetMesh before = m;
  const SliverPassReport r = remove_final_slivers(m);
  EXPECT_EQ(r.below_before, 0);
  EXPECT_EQ(m.V, before.V);
  EXPECT_EQ(m.T, before.T);
  EXPECT_EQ(m.domain, before.domain);
}

}  // namespace
}  // namespace topopt::mesh
