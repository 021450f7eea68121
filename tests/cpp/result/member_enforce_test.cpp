// The minimum member size held on the crisp design (src/result/member_enforce.h): thin plates of
// known thickness thickened to the size, in the middle and along the part's face, measured by the
// product's member measure on the crisp design the user gets; a thick plate left alone; the
// volume the report names equal to what the densities gained; the tets next to a non-design
// solid or on a supported face not held to the size.
#include <gtest/gtest.h>

#include <functional>

#include "mesh/core/structured_box.h"
#include "result/design_hygiene.h"
#include "result/iso_surface.h"
#include "result/member_enforce.h"
#include "simp/controls/member_measure.h"

namespace topopt::result {
namespace {

/// Element densities 1 where `inside` holds the tet's centre, else 0.
VecXd design_where(const TetMesh& mesh, const std::function<bool(const Eigen::Vector3d&)>& inside) {
  VecXd rho(mesh.T.rows());
  for (long t = 0; t < mesh.T.rows(); ++t) rho[t] = inside(tet_centre(mesh, t)) ? 1 : 0;
  return rho;
}

/// The crisp design (0/1, #T) of element densities at 0.5, as the result surface is cut from it.
VecXd crisp(const TetMesh& mesh, const VecXd& rho) {
  const std::vector<char> solid = crisp_tets(mesh, node_densities(mesh, rho), 0.5);
  VecXd c(static_cast<long>(solid.size()));
  for (size_t t = 0; t < solid.size(); ++t) c[static_cast<long>(t)] = solid[t];
  return c;
}

/// The smallest local thickness (reach `cell`) of the crisp design's design tets whose centre's
/// x lies in [lo, hi].
double smallest_in(const TetMesh& mesh, const VecXd& c, double cell, double lo, double hi) {
  simp::MemberMeasureParams mp;
  mp.reach = cell;
  const simp::MemberMeasure m = simp::measure_members(mesh, c, mp);
  double s = 1e300;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    const double x = tet_centre(mesh, t).x();
    if (c[t] > 0.5 && mesh.domain[t] == 0 && x >= lo && x <= hi) s = std::min(s, m.thickness[t]);
  }
  return s;
}

double mass(const TetMesh& mesh, const VecXd& rho, double lo = -1e300, double hi = 1e300) {
  double v = 0;
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (const double x = tet_centre(mesh, t).x(); x >= lo && x <= hi) v += tet_volume(mesh, t) * rho[t];
  return v;
}

TEST(MemberEnforce, ThinPlatesReachTheSizeAndAThickOneIsLeftAlone) {
  // 26 × 8 × 8 mm of 1 mm cells, size 6 mm: a 2 mm plate along the part's face x = 0 (it can
  // grow on one side only), a 2 mm plate in the middle (x 10–12) and an 8 mm one along x = 26
  mesh::StructuredBoxParams box;
  box.size = {26, 8, 8};
  box.cells = {26, 8, 8};
  const TetMesh mesh = mesh::structured_box_mesh(box);
  const double size = 6;
  const VecXd rho = design_where(
      mesh, [](const Eigen::Vector3d& c) { return c.x() < 2 || (c.x() > 10 && c.x() < 12) || c.x() > 18; });
  const double cell = member_cell(mesh);
  EXPECT_NEAR(cell, 1.12, 0.01);  // (√2)^(1/3) cells: the edge of a regular tet of a cell's sixth
  // the crisp design as given: both thin plates read about 2 mm (the measure, to half a cell)
  const VecXd before = crisp(mesh, rho);
  EXPECT_LT(smallest_in(mesh, before, cell, 0, 4), 3.0);
  EXPECT_LT(smallest_in(mesh, before, cell, 8, 14), 3.0);
  MemberEnforcement r;
  const VecXd out = enforce_min_member(mesh, rho, 0.5, {}, {size}, r);
  const VecXd after = crisp(mesh, out);
  std::cout << "before " << r.smallest_before << " mm, after " << r.smallest_after << " mm, " << r.volume_added
            << " mm3 added in " << r.rounds << " rounds; face plate "
            << smallest_in(mesh, after, cell, 0, 7) << " mm, middle " << smallest_in(mesh, after, cell, 7, 16)
            << " mm\n";
  // the size less a mesh size, the measure's resolution on a staircase of tets (each side of a
  // member within about half a cell of the level set), on both plates: the report and the measure
  EXPECT_TRUE(r.met());
  EXPECT_GE(r.smallest_after, size - cell);
  EXPECT_GE(smallest_in(mesh, after, cell, 0, 7), size - cell);
  EXPECT_GE(smallest_in(mesh, after, cell, 7, 16), size - cell);
  EXPECT_LT(r.smallest_before, 3.0);
  // the volume the report names is what the densities gained, and no more than each thin plate
  // grown to the size plus a cell on either side (8 × 8 mm² sections)
  EXPECT_NEAR(mass(mesh, out) - mass(mesh, rho), r.volume_added, 1e-9 * r.design_volume);
  EXPECT_LE(mass(mesh, out, -1, 7) - mass(mesh, rho, -1, 7), (size - 2 + 2) * 64);
  EXPECT_LE(mass(mesh, out, 7, 16) - mass(mesh, rho, 7, 16), (size - 2 + 2) * 64);
  // the 8 mm plate is thick enough: nothing added next to it
  EXPECT_NEAR(mass(mesh, out, 17, 40), mass(mesh, rho, 17, 40), 1e-12);
  // and the warning names the size, the volume and the box where it went
  const std::string w = member_warning(r);
  EXPECT_NE(w.find("controls.min_member_size 6 mm"), std::string::npos) << w;
  EXPECT_NE(w.find(" mm3 added"), std::string::npos) << w;
  // a design already at the size says nothing
  MemberEnforcement thick;
  const VecXd fat = design_where(mesh, [](const Eigen::Vector3d& c) { return c.x() > 8 && c.x() < 16; });
  EXPECT_EQ((enforce_min_member(mesh, fat, 0.5, {}, {size}, thick) - fat).norm(), 0.0);
  EXPECT_EQ(thick.tets_added, 0);
  EXPECT_EQ(member_warning(thick), "");
}

TEST(MemberEnforce, AttachmentsToNonDesignSolidsAndSupportedFacesAreNotHeldToTheSize) {
  // a non-design slab x 0–2: the design tets whose centre lies within a mesh size of a slab tet's
  // (most of the first cell row against it) are not held to the size, none beyond two mesh sizes;
  // nor is a supported face's layer (the tets with a node flagged as an anchor)
  mesh::StructuredBoxParams box;
  box.size = {20, 10, 10};
  box.cells = {20, 10, 10};
  box.nondesign = {{0, 0, 0, 2, 10, 10}};
  const TetMesh mesh = mesh::structured_box_mesh(box);
  const double cell = member_cell(mesh);
  const std::vector<char> attached = member_attachments(mesh, {}, cell);
  std::vector<Eigen::Vector3d> slab;
  for (long n = 0; n < mesh.T.rows(); ++n)
    if (mesh.domain[n] != 0) slab.push_back(tet_centre(mesh, n));
  long first_row = 0, first_row_attached = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    const Eigen::Vector3d c = tet_centre(mesh, t);
    double nearest = 1e300;  // to a non-design tet's centre, by brute force
    for (const Eigen::Vector3d& n : slab) nearest = std::min(nearest, (n - c).norm());
    EXPECT_EQ(static_cast<bool>(attached[t]), mesh.domain[t] == 0 && nearest <= cell) << c.transpose();
    if (mesh.domain[t] == 0 && c.x() < 3) ++first_row, first_row_attached += attached[t];
    if (c.x() > 2 + 2 * cell) {
      EXPECT_FALSE(attached[t]) << c.x();
    }
  }
  EXPECT_GT(first_row_attached, first_row / 2);  // most of the row against the slab
  std::vector<char> anchors(mesh.V.rows(), 0);
  for (long v = 0; v < mesh.V.rows(); ++v) anchors[v] = mesh.V(v, 0) > 20 - 1e-9 ? kAnchorSupport : 0;
  const std::vector<char> with = member_attachments(mesh, anchors, cell);
  for (long t = 0; t < mesh.T.rows(); ++t) {
    bool on_face = false;
    for (int a = 0; a < 4; ++a) on_face |= anchors[mesh.T(t, a)] != 0;
    EXPECT_EQ(static_cast<bool>(with[t]), attached[t] || on_face);
  }
}

}  // namespace
}  // namespace topopt::result
