// Bridges for the non-design solids the design leaves apart (result/join_bridges.h), on a beam
// between a supported and a loaded non-design block with an unloaded pad above it, built in
// code: with the option on the result is one piece, the bridge is at least its set size across
// beyond a cell, adds little material and says how much, follows grey material where there is
// some, and the as-built compliance does not rise; with it off the pad stays apart, named.
#include "result/join_bridges.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "mesh/core/structured_box.h"
#include "pipeline/optimize_job.h"
#include "result/iso_surface.h"
#include "result/overhang_lift.h"
#include "result/result_check.h"
#include "result/verification.h"
#include "simp/controls/overhang_measure.h"
#include "simp/density_filter.h"
#include "testing/bar_field.h"

namespace topopt::result {
namespace {

constexpr double kCell = 1.0;  // mm, the structured mesh's cell
constexpr double kSize = 3.0;  // mm, the bridges' diameter

/// 24 x 12 x 12 mm in 1 mm cells (20 736 tets); non-design solid 1 at x = 0 (supported on Ω's
/// Face1), solid 2 at x = 24 (loaded on its end face, NonDesign:Face8), solid 3 a pad on top
/// (x 10..18, z 9..12) that no support or load touches. Design densities: 1 in the beam
/// (y 4..8, z 1..5) between the blocks, `background` elsewhere, `grey` in x 16..18, z 5..9
/// (a column from the beam to the pad) when given.
struct PadFixture {
  TetMesh mesh;
  VecXd density;
  std::vector<char> anchors;
  VerificationProblem problem;
};

bool in(const Eigen::Vector3d& c, std::array<double, 6> b) {
  return c[0] > b[0] && c[1] > b[1] && c[2] > b[2] && c[0] < b[3] && c[1] < b[4] && c[2] < b[5];
}

/// A box of 1 mm cells with the given non-design boxes: the non-design tets at density 1, the
/// design's given by `density` of the tet's centroid; no anchors yet.
template <class Density>
PadFixture box_fixture(std::array<double, 3> size, std::vector<std::array<double, 6>> nondesign,
                       const Density& density) {
  mesh::StructuredBoxParams p;
  p.size = size;
  for (int a = 0; a < 3; ++a) p.cells[a] = static_cast<int>(size[a]);
  p.nondesign = std::move(nondesign);
  PadFixture f;
  f.mesh = mesh::structured_box_mesh(p);
  const MatX3d c = simp::tet_centroids(f.mesh);
  f.density.resize(f.mesh.T.rows());
  for (long t = 0; t < f.mesh.T.rows(); ++t)
    f.density[t] = f.mesh.domain[t] != 0 ? 1.0 : density(Eigen::Vector3d(c.row(t).transpose()));
  f.anchors.assign(f.mesh.V.rows(), 0);
  return f;
}

PadFixture pad_fixture(double background = 0.02, double grey = -1) {
  PadFixture f = box_fixture(
      {24, 12, 12}, {{0, 3, 0, 3, 9, 6}, {21, 3, 0, 24, 9, 6}, {10, 3, 9, 18, 9, 12}}, [&](const Eigen::Vector3d& x) {
        return in(x, {0, 4, 1, 24, 8, 5}) ? 1.0 : grey >= 0 && in(x, {16, 3, 5, 18, 9, 9}) ? grey : background;
      });
  for (long v = 0; v < f.mesh.V.rows(); ++v) {
    const Eigen::Vector3d x = f.mesh.V.row(v).transpose();
    if (x[0] < 1e-9) f.anchors[v] |= kAnchorSupport;
    if (x[0] > 24 - 1e-9 && x[1] > 3 - 1e-9 && x[1] < 9 + 1e-9 && x[2] < 6 + 1e-9) f.anchors[v] |= kAnchorLoad;
  }
  f.problem = testing::fixed_at_face1_pulled_down_on(8);
  return f;
}

HygieneParams joining(bool on) {
  HygieneParams h;
  h.join_non_design = on;
  h.bridge_size = kSize;
  return h;
}

double volume_of(const TetMesh& m, long t) {
  const Eigen::Vector3d a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)), d = m.V.row(m.T(t, 3));
  return std::abs((b - a).cross(c - a).dot(d - a)) / 6;
}

int level_pieces(const TetMesh& m, const VecXd& density) {
  int count = 0;
  level_components(m, node_densities(m, density), 0.5, count);
  return count;
}

TEST(JoinBridges, ThePenaltyIsOneInSolidAndGrowsAsTheDensityFalls) {
  EXPECT_DOUBLE_EQ(bridge_penalty(1), 1);
  EXPECT_DOUBLE_EQ(bridge_penalty(0), kVoidPenalty);
  EXPECT_DOUBLE_EQ(bridge_penalty(-0.5), kVoidPenalty);
  for (double r = 0; r < 1; r += 0.1) EXPECT_GT(bridge_penalty(r), bridge_penalty(r + 0.1)) << r;
}

TEST(JoinBridges, ADetachedPadIsJoinedByABridgeOfTheSetSizeThatAddsLittle) {
  const PadFixture f = pad_fixture();
  ASSERT_EQ(level_pieces(f.mesh, f.density), 2);  // the beam with its blocks, and the pad
  HygieneReport rep;
  const VecXd clean = clean_design(f.mesh, f.density, 0.5, f.anchors, joining(true), rep);
  // one piece, nothing named apart
  EXPECT_EQ(level_pieces(f.mesh, clean), 1);
  EXPECT_EQ(rep.pieces, 1);
  EXPECT_TRUE(rep.apart.empty());
  ASSERT_EQ(rep.bridges.size(), 1u);
  const Bridge& b = rep.bridges[0];
  EXPECT_TRUE(b.joined);
  EXPECT_EQ(b.nondesign, std::vector<int>{3});
  EXPECT_DOUBLE_EQ(b.size, kSize);
  // from the pad (z = 9) down to the beam (z = 5): the 4 mm gap, give or take a cell each end
  EXPECT_GE(b.length, 4 - 2 * kCell);
  EXPECT_LE(b.length, 4 + 2 * kCell * std::sqrt(3.0));
  // the material added is what the densities gained, all of it in the gap, and small: within
  // the tube of the tets reaching within size / 2 of the path
  double gained = 0, design = 0;
  for (long t = 0; t < f.mesh.T.rows(); ++t) {
    if (f.mesh.domain[t] != 0) continue;
    design += volume_of(f.mesh, t);
    EXPECT_GE(clean[t], f.density[t]) << t;  // bridges only add
    gained += volume_of(f.mesh, t) * (clean[t] - f.density[t]);
  }
  EXPECT_NEAR(b.volume, gained, 1e-9 * gained);
  const double reach = kSize / 2 + kCell * std::sqrt(3.0);
  EXPECT_GT(b.volume, M_PI * kSize * kSize / 4 * 4 * 0.9);  // at least the set size across the gap
  EXPECT_LT(b.volume, M_PI * reach * reach * (b.length + 2 * reach));
  EXPECT_LT(b.volume, 0.1 * design);
  // its thickness: the crisp design's cross-section halfway across the gap (z 6.5 .. 7.5, only
  // the bridge there): as wide in x and in y as the set size less a cell, and as large as a
  // disc of that diameter
  const std::vector<char> crisp = crisp_tets(f.mesh, node_densities(f.mesh, clean), 0.5);
  const MatX3d cc = simp::tet_centroids(f.mesh);
  double area = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (long t = 0; t < f.mesh.T.rows(); ++t) {
    if (!crisp[t] || cc(t, 2) < 6.5 || cc(t, 2) > 7.5) continue;
    area += volume_of(f.mesh, t);
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d x = f.mesh.V.row(f.mesh.T(t, k)).transpose();
      lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
    }
  }
  EXPECT_GE(std::sqrt(4 * area / M_PI), kSize - kCell) << area;
  EXPECT_GE(hi[0] - lo[0], kSize - kCell);
  EXPECT_GE(hi[1] - lo[1], kSize - kCell);
  // the warning names the solid, the material, the length and the key
  ASSERT_FALSE(rep.warnings.empty());
  const std::string& w = rep.warnings.back();
  EXPECT_NE(w.find("joined non-design solid 3"), std::string::npos) << w;
  EXPECT_NE(w.find("mm³ of material added"), std::string::npos) << w;
  EXPECT_NE(w.find("long"), std::string::npos) << w;
  EXPECT_NE(w.find("join_non_design"), std::string::npos) << w;
  // cleaned once, clean for good: no second bridge
  HygieneReport again;
  clean_design(f.mesh, clean, 0.5, f.anchors, joining(true), again);
  EXPECT_TRUE(again.bridges.empty());
  EXPECT_TRUE(again.warnings.empty());
}

TEST(JoinBridges, TheJunctionsKeepEveryTriangleOfTheResultAt10DegreesOrMore) {
  // issue 19: no triangle below 10°, also where the bridge meets the pad's and the beam's
  // faces (the pad's faces are non-design faces of the result), in void and in a grey background
  for (const double background : {0.02, 0.3}) {
    const PadFixture f = pad_fixture(background);
    HygieneReport rep;
    const TriSurface s =
        pipeline::result_surface(f.mesh, f.density, 0.5, -1, SmoothParams{}, nullptr, f.anchors, joining(true), &rep);
    ASSERT_EQ(rep.bridges.size(), 1u) << background;
    EXPECT_TRUE(rep.bridges[0].joined) << background;
    const ResultCheck c = check_result(s);
    EXPECT_TRUE(c.valid()) << background;
    EXPECT_GE(c.min_angle_free, 10.0) << background;
    EXPECT_GE(c.min_angle_faces, 10.0) << background;
    EXPECT_GE(c.min_angle_nondesign, 10.0) << background;
    EXPECT_LT(c.min_angle_nondesign, 180.0) << background;  // the pad's faces are there
  }
}

TEST(JoinBridges, WithTheOptionOffThePadStaysApartAndNamed) {
  const PadFixture f = pad_fixture();
  HygieneReport rep;
  const VecXd clean = clean_design(f.mesh, f.density, 0.5, f.anchors, joining(false), rep);
  EXPECT_EQ(clean, f.density);
  EXPECT_TRUE(rep.bridges.empty());
  EXPECT_EQ(level_pieces(f.mesh, clean), 2);
  ASSERT_EQ(rep.apart.size(), 1u);
  EXPECT_EQ(rep.apart[0].nondesign, std::vector<int>{3});
  EXPECT_FALSE(rep.apart[0].removed);
  ASSERT_EQ(rep.warnings.size(), 1u);
  EXPECT_NE(rep.warnings[0].find("non-design solid 3 is not connected"), std::string::npos) << rep.warnings[0];
  EXPECT_NE(rep.warnings[0].find("touches no support and no load"), std::string::npos) << rep.warnings[0];
}

TEST(JoinBridges, TheBridgeFollowsGreyMaterialWhereThereIsSome) {
  // a grey column (0.4, below the threshold) under the pad's end x 16..18: the path through it
  // costs less than the void straight below the pad's middle
  const PadFixture f = pad_fixture(0.02, 0.4);
  HygieneReport rep;
  const VecXd clean = clean_design(f.mesh, f.density, 0.5, f.anchors, joining(true), rep);
  ASSERT_EQ(rep.bridges.size(), 1u);
  EXPECT_TRUE(rep.bridges[0].joined);
  const MatX3d c = simp::tet_centroids(f.mesh);
  double x_sum = 0, v_sum = 0;
  for (long t = 0; t < f.mesh.T.rows(); ++t)
    if (f.mesh.domain[t] == 0 && c(t, 2) > 5.5 && c(t, 2) < 8.5 && clean[t] > f.density[t]) {
      x_sum += volume_of(f.mesh, t) * c(t, 0), v_sum += volume_of(f.mesh, t);
    }
  ASSERT_GT(v_sum, 0);
  EXPECT_GT(x_sum / v_sum, 15.0);  // the column's x 16..18, not the pad's middle (14)
  EXPECT_LT(x_sum / v_sum, 19.0);
}

/// mm²: the area of s's triangles with centroid z in (lo, hi) and x in (3.5, 20.5) (apart from
/// the end blocks, whose given faces at y = 3 face down) that face against `up`, do not rest on
/// the plate (up · x = 0) and rise less than 45° from it.
double too_flat_between(const TriSurface& s, const Eigen::Vector3d& up, double lo, double hi) {
  double area = 0;
  for (long f = 0; f < s.F.rows(); ++f) {
    const Eigen::Vector3d a = s.V.row(s.F(f, 0)), b = s.V.row(s.F(f, 1)), c = s.V.row(s.F(f, 2));
    const double z = (a[2] + b[2] + c[2]) / 3;
    const double x = (a[0] + b[0] + c[0]) / 3;
    if (z <= lo || z >= hi || x <= 3.5 || x >= 20.5) continue;
    if (std::max({a.dot(up), b.dot(up), c.dot(up)}) < 1e-6) continue;  // on the plate
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (-n.dot(up) > std::cos(M_PI / 4) * n.norm()) area += n.norm() / 2;
  }
  return area;
}

TEST(JoinBridges, UnderAnOverhangControlTheBridgeStandsOnAWallInsteadOfHanging) {
  // issue 22: built along +y, the bridge from the pad down to the beam (along z) lies flat; its
  // underside faced straight down, a ceiling the overhang pass (which only restores slopes)
  // cannot lift — on the bracket lying, 95 mm² of 2700 facing down. With the build direction
  // the tube is carried down to the plate (y = 0) by a wall along y: in the gap (z 5.5..8.5,
  // only the bridge there, the end blocks apart) no facet is left too flat but the few the
  // tet staircase tilts.
  const PadFixture f = pad_fixture();
  const Eigen::Vector3d up(0, 1, 0);
  SmoothParams smooth;
  smooth.build.direction = up;  // the overhang pass in both runs; the plate at y = 0
  double flat[2], added[2];
  for (const bool wall : {false, true}) {
    HygieneParams h = joining(true);
    if (wall) h.build_direction = up;
    HygieneReport rep;
    const TriSurface s = pipeline::result_surface(f.mesh, f.density, 0.5, -1, smooth, nullptr, f.anchors, h, &rep);
    ASSERT_EQ(rep.bridges.size(), 1u) << wall;
    EXPECT_TRUE(rep.bridges[0].joined) << wall;
    EXPECT_TRUE(check_result(s).valid()) << wall;
    flat[wall] = too_flat_between(s, up, 5.5, 8.5);
    added[wall] = rep.bridges[0].volume;
  }
  EXPECT_GT(flat[0], 2.0);  // the hanging tube: a quarter of its 3 mm round over the 3 mm slice ~ 7 mm²
  EXPECT_LT(flat[1], 0.1 * flat[0]) << flat[0] << " -> " << flat[1];
  // the wall's material: at most the tube's reach across (size + 2 cells) from y = 0 to its top
  // over the gap with a reach either end
  const double reach = kSize / 2 + kCell * std::sqrt(3.0);
  EXPECT_GT(added[1], added[0]);
  EXPECT_LT(added[1], 2 * reach * (6 + reach) * (4 + 2 * reach) + added[0]);
}

/// Under the slab: y 8..10 (its centroid) below the slab's underside z = 4 + 2 (y − 8).
bool under_slab(const Eigen::Vector3d& c) { return c[1] > 8 && c[1] < 10 && c[2] < 4 + 2 * (c[1] - 8); }

/// A bridge high above the plate with material under it (build +z, the plate at z = 0): 24 x 16 x 22
/// mm in 1 mm cells; a wall of design material (density 1; y 4..8, z 0..20) between a supported
/// non-design block at x = 0 and a loaded one at x = 24 (both y 4..8, z 0..20); an unloaded
/// non-design column (x 10..16, y 14..16, z 0..20) standing on the plate 6 mm beside the wall; and
/// a slab of design material leaning out of the wall under the gap (x 8..18, y 8..10, z from
/// 4 + 2 (y − 8) to 8 + 2 (y − 8): its underside rises at 63°, it prints). A grey strip (0.49,
/// below the threshold) from the wall to the column at z 16..19 is the bridge's cheapest way.
PadFixture slab_fixture() {
  PadFixture f = box_fixture(
      {24, 16, 22}, {{0, 4, 0, 3, 8, 20}, {21, 4, 0, 24, 8, 20}, {10, 14, 0, 16, 16, 20}},
      [](const Eigen::Vector3d& x) {
        const bool slab = x[0] > 8 && x[0] < 18 && x[1] > 8 && x[1] < 10 && !under_slab(x) && x[2] < 8 + 2 * (x[1] - 8);
        return in(x, {0, 4, 0, 24, 8, 20}) || slab ? 1.0 : in(x, {12, 8, 16, 14, 14, 19}) ? 0.49 : 0.02;
      });
  for (long v = 0; v < f.mesh.V.rows(); ++v) {
    const Eigen::Vector3d x = f.mesh.V.row(v).transpose();
    const bool end = x[1] > 4 - 1e-9 && x[1] < 8 + 1e-9 && x[2] < 20 + 1e-9;
    if (x[0] < 1e-9 && end) f.anchors[v] |= kAnchorSupport;
    if (x[0] > 24 - 1e-9 && end) f.anchors[v] |= kAnchorLoad;
  }
  return f;
}

TEST(JoinBridges, UnderAnOverhangControlTheWallStopsOnTheMaterialBelowTheBridge) {
  // issue 22: the wall that carries a bridge goes down to the first material under it, not through
  // it to the plate — here it stands on the slab; what lies under the slab (void, and the slab's own
  // underside rising at 63°) is left alone. Main's wall (overhang7's, to where Ω ends) ran through the
  // slab and filled under it: 21.6 mm³ set solid in the region counted here (BENCHMARKS.md, bridge45).
  const PadFixture f = slab_fixture();
  ASSERT_EQ(level_pieces(f.mesh, f.density), 2);
  const Eigen::Vector3d up(0, 0, 1);
  SmoothParams smooth;
  smooth.build.direction = up;
  HygieneParams h = joining(true);
  h.build_direction = up;
  HygieneReport rep;
  VecXd design;
  const TriSurface s =
      pipeline::result_surface(f.mesh, f.density, 0.5, -1, smooth, nullptr, f.anchors, h, &rep, &design);
  ASSERT_EQ(rep.bridges.size(), 1u);
  EXPECT_TRUE(rep.bridges[0].joined);
  EXPECT_EQ(rep.bridges[0].nondesign, std::vector<int>{3});
  EXPECT_TRUE(check_result(s).valid());
  // the bridge is high: its tube above the slab's top (z 8..12)
  const MatX3d c = simp::tet_centroids(f.mesh);
  double under = 0, above = 0;  // material the bridge added under the slab, and high up in the gap
  for (long t = 0; t < f.mesh.T.rows(); ++t) {
    if (f.mesh.domain[t] != 0 || design[t] <= f.density[t]) continue;
    const Eigen::Vector3d x = c.row(t).transpose();
    const double gained = volume_of(f.mesh, t) * (design[t] - f.density[t]);
    // a cell off the slab's far side, where the wall runs down, and off the plate, where the wall's
    // foot (a gap of one cell under the wall's edge) is filled
    if (under_slab(x) && x[1] < 9 && x[2] > 1) under += gained;
    if (x[1] > 8.5 && x[1] < 13.5 && x[2] > 14) above += gained;
  }
  EXPECT_GT(above, 4 * kSize) << "the bridge runs high in the gap";
  EXPECT_EQ(under, 0) << "mm³ set solid under the slab";
  // and it prints: the share of the result surface too flat (the product's measure) ≤ 1 %
  const simp::OverhangShare o = simp::overhang_share(s.V, s.F, up, {}, &s.tag, &s.lock);
  EXPECT_LE(o.share(), 0.01) << o.overhang_area << " of " << o.downward_area << " mm²";
}

TEST(JoinBridges, TheResultIsOneSolidAndItsAsBuiltComplianceDoesNotRise) {
  const PadFixture f = pad_fixture();
  Verification v[2];
  for (const bool on : {false, true}) {
    VecXd design;
    HygieneReport rep;
    const TriSurface s = pipeline::result_surface(f.mesh, f.density, 0.5, -1, SmoothParams{}, nullptr, f.anchors,
                                                  joining(on), &rep, &design);
    v[on] = verify_result(s, f.mesh, design, 0.5, f.problem);
    // off: the pad is a second solid the as-built analysis leaves out; on: one solid
    EXPECT_EQ(v[on].unheld_volumes.size(), on ? 0u : 1u);
  }
  EXPECT_GT(v[0].as_built.compliance, 0);
  EXPECT_LE(v[1].as_built.compliance, v[0].as_built.compliance * (1 + 1e-6));
  EXPECT_LE(v[1].crisp.compliance, v[0].crisp.compliance * (1 + 1e-9));
}

}  // namespace
}  // namespace topopt::result
