// Steps 12-14 on a given conformal surface mesh: a box with a non-design block inside, both
// surfaces from a structured mesh. The non-design block is filled first and tagged 1, the
// rest of the box around it and tagged 0; together they fill the box exactly, their outer
// boundary is the box's surface and their interface the block's.
#include "mesh/two_brep/volume_steps.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>

#include "common/face_key.h"
#include "common/tet_boundary.h"
#include "mesh/core/structured_box.h"

namespace topopt::mesh {
namespace {

double tet_volume(const MatX3d& V, const MatX4i& T, long t) {
  const Eigen::Vector3d a = V.row(T(t, 0)), b = V.row(T(t, 1)), c = V.row(T(t, 2)), d = V.row(T(t, 3));
  return (b - a).dot((c - a).cross(d - a)) / 6;
}

/// The tets of T tagged `dom`.
MatX4i tets_of(const MatX4i& T, const VecXi& domain, int dom) {
  MatX4i out((domain.array() == dom).count(), 4);
  long k = 0;
  for (long t = 0; t < T.rows(); ++t)
    if (domain[t] == dom) out.row(k++) = T.row(t);
  return out;
}

std::set<FaceKey> keys_of(const MatX3i& F) {
  std::set<FaceKey> k;
  for (long i = 0; i < F.rows(); ++i) k.insert(face_key(F(i, 0), F(i, 1), F(i, 2)));
  return k;
}

TEST(VolumeSteps, FillTheNonDesignBlockThenTheRestAroundIt) {
  // a 30 x 20 x 20 box in 5 mm cells, the block [10, 20] x [5, 15] x [5, 15] inside it
  StructuredBoxParams p;
  p.size = {30, 20, 20};
  p.cells = {6, 4, 4};
  p.nondesign = {{10, 5, 5, 20, 15, 15}};
  const TetMesh box = structured_box_mesh(p);
  const MatX4i B = tets_of(box.T, box.domain, 1);
  // the two surfaces on the nodes they use (the structured mesh's inner nodes are dropped)
  MatX3i outer = box.F, inner = boundary_triangles(B);
  std::map<int, int> renum;
  for (const MatX3i* F : {&outer, &inner})
    for (long i = 0; i < F->rows(); ++i)
      for (int c = 0; c < 3; ++c) renum.emplace((*F)(i, c), static_cast<int>(renum.size()));
  MatX3d V(static_cast<long>(renum.size()), 3);
  for (const auto& [old, now] : renum) V.row(now) = box.V.row(old);
  for (MatX3i* F : {&outer, &inner})
    for (long i = 0; i < F->rows(); ++i)
      for (int c = 0; c < 3; ++c) (*F)(i, c) = renum.at((*F)(i, c));

  VolumeFillParams params;
  params.size = [](const double*) { return 5.0; };
  const TwoBRepVolumes r = fill_two_brep_volumes(V, {inner}, outer, params, 1);

  ASSERT_GE(r.V.rows(), V.rows());
  EXPECT_EQ(r.V.topRows(V.rows()), V);  // the input nodes kept, same indices
  ASSERT_EQ(r.domain.size(), r.T.rows());
  double volume[2] = {0, 0};
  bool block_first = true;
  for (long t = 0; t < r.T.rows(); ++t) {
    const double v = tet_volume(r.V, r.T, t);
    EXPECT_GT(v, 0);
    ASSERT_TRUE(r.domain[t] == 0 || r.domain[t] == 1);
    volume[r.domain[t]] += v;
    if (t > 0 && r.domain[t] == 1 && r.domain[t - 1] == 0) block_first = false;
  }
  EXPECT_TRUE(block_first);  // step 12's tets come before step 14's
  EXPECT_NEAR(volume[1], 1000, 1e-9);
  EXPECT_NEAR(volume[0], 12000 - 1000, 1e-9);
  EXPECT_EQ(keys_of(boundary_triangles(r.T)), keys_of(outer));  // conformal: the only open faces are the box's
  const MatX4i FB = tets_of(r.T, r.domain, 1);
  EXPECT_EQ(keys_of(boundary_triangles(FB)), keys_of(inner));  // the interface is the block's surface
  EXPECT_GE(r.seconds_design, 0);
}

}  // namespace
}  // namespace topopt::mesh
