// The overhang control's carry of the non-design solids' undersides (src/simp/controls/overhang_carry):
// under a block hanging from Ω's top, the held tets are the funnel under its downward face (every tet
// wholly inside it held, none whose centroid lies outside it), every tet on the face held, the
// level is 1 in the funnel and 0 where no carried face lies above; a face that faces up carries
// nothing. The property on an optimised part is Overhang.UprightBeamCarriesItsPadsUnderside.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "mesh/core/structured_box.h"
#include "simp/controls/overhang_carry.h"

namespace topopt::simp {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// An 8 mm cube of 0.5 mm cells with a non-design block x, y in [2, 6], z in [6, 8] hanging from
/// its top face: the block's underside z = 6 (4 × 4 mm) faces down inside Ω along +z.
TetMesh hanging_block() {
  mesh::StructuredBoxParams p;
  p.size = {8, 8, 8};
  p.cells = {16, 16, 16};
  p.nondesign = {{2, 2, 6, 6, 6, 8}};
  return mesh::structured_box_mesh(p);
}

OverhangControl along(const Eigen::Vector3d& d) {
  OverhangControl c;
  c.enabled = true;
  c.direction = d;
  return c;  // angle 45, margin 20: the funnel's sides rise at 65°
}

/// How far p lies inside the funnel under the block's face (mm, negative outside; -inf when the
/// face is not above p), the funnel's sides rising at `slope` (tan of the angle).
double funnel_inside(const Eigen::Vector3d& p, double slope) {
  if (p.x() < 2 || p.x() > 6 || p.y() < 2 || p.y() > 6 || p.z() > 6) return -1e300;
  const double inset = std::min({p.x() - 2, 6 - p.x(), p.y() - 2, 6 - p.y()});
  return inset - (6 - p.z()) / slope;
}

TEST(OverhangCarry, TheFunnelUnderAHangingBlockIsHeldAndNothingElse) {
  const TetMesh m = hanging_block();
  const double slope = std::tan(65 * kPi / 180);
  const std::vector<char> held = carried_tets(m, along(Eigen::Vector3d::UnitZ()));
  long count = 0, wholly_inside = 0;
  for (long t = 0; t < m.T.rows(); ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    int on_face = 0, inside = 0;
    for (int a = 0; a < 4; ++a) {
      const Eigen::Vector3d p = m.V.row(m.T(t, a));
      c += p / 4;
      on_face += std::abs(p.z() - 6) < 1e-9 && funnel_inside(p, slope) >= 0;
      inside += funnel_inside(p, slope) >= -1e-9;
    }
    if (m.domain[t] != 0) {
      EXPECT_FALSE(held[t]) << "a non-design tet is kept anyway, not held";
      continue;
    }
    count += held[t];
    if (on_face == 3) {
      EXPECT_TRUE(held[t]) << "a tet on the block's underside must carry it";
    }
    if (inside == 4) {
      EXPECT_TRUE(held[t]) << "tet " << t << " lies wholly in the funnel";
      ++wholly_inside;
    }
    if (held[t] && on_face < 3) {
      EXPECT_GE(funnel_inside(c, slope), -1e-9) << "tet " << t << " lies outside the funnel";
    }
  }
  EXPECT_GT(wholly_inside, 100) << "the funnel reaches 2 tan 65° = 4.3 mm below the face";
  EXPECT_GE(count, wholly_inside);
}

TEST(OverhangCarry, TheLevelIsOneInTheFunnelAndZeroWhereNothingIsCarriedAbove) {
  const TetMesh m = hanging_block();
  const double slope = std::tan(65 * kPi / 180), ramp = 0.5;
  const VecXd level = carried_level(m, along(Eigen::Vector3d::UnitZ()), ramp);
  for (long v = 0; v < m.V.rows(); ++v) {
    const Eigen::Vector3d p = m.V.row(v);
    const double inside = funnel_inside(p, slope);
    EXPECT_GE(level[v], 0.0);
    EXPECT_LE(level[v], 1.0);
    if (inside >= 1e-9) {
      EXPECT_EQ(level[v], 1.0) << p.transpose();
    }
    if (inside == -1e300 || inside < -ramp - 1e-9) {
      EXPECT_EQ(level[v], 0.0) << p.transpose() << " lies outside the funnel and its ramp";
    }
  }
}

TEST(OverhangCarry, AFaceThatFacesUpOrAnUntaggedMeshCarriesNothing) {
  const TetMesh m = hanging_block();
  // built downwards the block's underside faces up and its sides stand along the build
  const std::vector<char> held = carried_tets(m, along(-Eigen::Vector3d::UnitZ()));
  EXPECT_EQ(std::count(held.begin(), held.end(), 1), 0);
  EXPECT_EQ(carried_level(m, along(-Eigen::Vector3d::UnitZ()), 0.5).maxCoeff(), 0.0);
  TetMesh untagged = m;
  untagged.domain.resize(0);
  const std::vector<char> none = carried_tets(untagged, along(Eigen::Vector3d::UnitZ()));
  EXPECT_EQ(std::count(none.begin(), none.end(), 1), 0);
}

}  // namespace
}  // namespace topopt::simp
