// The result surface: closed, manifold and oriented; the volume at the chosen threshold; the
// non-design solids kept whole and unmoved by smoothing.
#include "result/iso_surface.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <map>

#include "common/error.h"
#include "mesh/core/structured_box.h"
#include "result/result_check.h"
#include "result/smoothing.h"
#include "simp/density_filter.h"
#include "testing/bar_field.h"

namespace topopt::result {
namespace {

using Fixture = testing::BarField;

/// A 40x20x10 box with a non-design block at each end and a smooth density field: a
/// bar of material along the x axis whose thickness varies, void elsewhere.
Fixture bar_fixture() { return testing::bar_field(4, testing::wavy_radius); }

TEST(IsoSurface, ClosedManifoldOrientedWithTheTargetVolume) {
  Fixture f = bar_fixture();
  VecXd nd = node_densities(f.mesh, f.density);
  const double vf = 0.15;
  double t = threshold_for_volume(f.mesh, nd, vf);
  EXPECT_GT(t, 0.0);
  EXPECT_LT(t, 1.0);
  VecXd vol = simp::tet_volumes(f.mesh);
  double design = 0, nondesign = 0;
  for (long k = 0; k < f.mesh.T.rows(); ++k) (f.mesh.domain[k] ? nondesign : design) += vol[k];
  EXPECT_NEAR(kept_design_volume(f.mesh, nd, t), vf * design, 1e-6 * design);
  TriSurface s = extract_iso_surface(f.mesh, nd, t);
  SurfaceCheck c = check_surface(s.V, s.F);
  EXPECT_TRUE(c.closed_manifold()) << c.open_edges << " open, " << c.overshared_edges << " overshared, "
                                   << c.misoriented_edges << " misoriented";
  // the enclosed volume is the kept design volume plus the non-design blocks, exactly
  EXPECT_NEAR(c.volume, vf * design + nondesign, 1e-6 * design);
  // it touches Ω's end faces (x = 0 and x = 40) where the non-design blocks are
  bool face1 = false, face2 = false;
  for (long k = 0; k < s.F.rows(); ++k) face1 |= s.tag[k] == 1, face2 |= s.tag[k] == 2;
  EXPECT_TRUE(face1 && face2);
}

TEST(IsoSurface, TheThresholdForAVolumeStepsOffAPlateauOfEqualDensities) {
  // the nodes of a slab across the bar (x in [15, 25]) all at 0.4 (plus round-off either side,
  // as a filter leaves it), and a volume fraction inside the jump the plateau makes: the
  // bisection ends on 0.4, where each plateau node's side would be its round-off's
  Fixture f = bar_fixture();
  VecXd nd = node_densities(f.mesh, f.density);
  long plateau = 0;
  for (long i = 0; i < nd.size(); ++i)
    if (f.mesh.V(i, 0) >= 15 && f.mesh.V(i, 0) <= 25) nd[i] = 0.4 + ((i % 3) - 1) * 1e-16, ++plateau;
  ASSERT_GT(plateau, 20);
  const double design = kept_design_volume(f.mesh, nd, -1.0);
  const double below = kept_design_volume(f.mesh, nd, 0.4 - 1e-7), above = kept_design_volume(f.mesh, nd, 0.4 + 1e-7);
  ASSERT_GT(below - above, 0.05 * design);
  const double t = threshold_for_volume(f.mesh, nd, (0.4 * below + 0.6 * above) / design);
  for (long i = 0; i < nd.size(); ++i) ASSERT_GT(std::abs(nd[i] - t), 1e-9) << "node " << i << " on the threshold";
  EXPECT_GT(t, 0.4);  // the nearer side: above the plateau (60 % of the jump), all its nodes out
  EXPECT_NEAR(kept_design_volume(f.mesh, nd, t), above, 1e-5 * design);
  // and the surface at that threshold is closed and crossing-free
  const TriSurface s = extract_iso_surface(f.mesh, nd, t, 0.2);
  EXPECT_TRUE(check_surface(s.V, s.F).closed_manifold());
}

TEST(IsoSurface, SmoothingKeepsItClosedAndNonDesignInPlace) {
  Fixture f = bar_fixture();
  VecXd nd = node_densities(f.mesh, f.density);
  double t = threshold_for_volume(f.mesh, nd, 0.15);
  TriSurface s = extract_iso_surface(f.mesh, nd, t);
  MatX3d before = s.V;
  double v0 = check_surface(s.V, s.F).volume;
  smooth_surface(s);
  SurfaceCheck c = check_surface(s.V, s.F);
  EXPECT_TRUE(c.closed_manifold());
  EXPECT_NEAR(c.volume, v0, 0.02 * v0);  // Taubin: no shrinking
  double moved_free = 0;
  for (long i = 0; i < s.V.rows(); ++i) {
    double d = (s.V.row(i) - before.row(i)).norm();
    if (s.lock[i] == 2) {
      EXPECT_EQ(d, 0.0) << "non-design point " << i << " moved";
    }
    if (s.lock[i] == 1) {
      // on Ω's planar faces: still on the box
      bool on_box = false;
      for (int k = 0; k < 3; ++k) {
        double lo = 0, hi = k == 0 ? 40 : k == 1 ? 20 : 10;
        on_box |= std::abs(s.V(i, k) - lo) < 1e-9 || std::abs(s.V(i, k) - hi) < 1e-9;
      }
      EXPECT_TRUE(on_box) << "point " << i << " left Ω's face";
    }
    if (s.lock[i] == 0) moved_free = std::max(moved_free, d);
  }
  EXPECT_GT(moved_free, 0.05);  // the staircase was actually smoothed
}

TEST(IsoSurface, NonDesignSolidsInsideArePresentWhenDesignIsVoid) {
  // everything void except the non-design blocks: the surface is exactly their boundary
  Fixture f = bar_fixture();
  for (long t = 0; t < f.mesh.T.rows(); ++t)
    if (f.mesh.domain[t] == 0) f.density[t] = 0;
  VecXd nd = node_densities(f.mesh, f.density);
  TriSurface s = extract_iso_surface(f.mesh, nd, 0.5);
  SurfaceCheck c = check_surface(s.V, s.F);
  EXPECT_TRUE(c.closed_manifold());
  EXPECT_NEAR(c.volume, 2 * 4 * 8 * 6, 1e-9);
  for (long i = 0; i < s.V.rows(); ++i) EXPECT_EQ(s.lock[i], 2);
}

/// A design field at the threshold over a whole region, as an extruded, symmetric study
/// leaves it after a few OC iterations: the 24 x 12 x 8 box in 2 mm cells with its interior
/// nodes shifted (so edges run in many directions), one layer of tets on the face x = 0 held
/// solid (keep_loaded_faces: density 1), and the other tets' densities a function of the
/// cell's (x, y) column only (extrusion along z, mirrored about y = 6): void (0.05) and solid
/// (0.9) columns with, between them, columns exactly at `level`, each tet's value off it by
/// a few units in the last place (what a filter's rounding leaves in a uniform region).
struct LevelPlateau {
  TetMesh mesh;
  VecXd density;  ///< #T
};

LevelPlateau level_plateau(double level, std::uint32_t seed) {
  mesh::StructuredBoxParams p;
  p.size = {24, 12, 8};
  p.cells = {12, 6, 4};
  LevelPlateau r;
  r.mesh = mesh::structured_box_mesh(p);
  std::uint32_t state = seed * 2654435761u + 1;
  auto next = [&state]() { return state = state * 1664525u + 1013904223u; };
  for (long i = 0; i < r.mesh.V.rows(); ++i) {
    bool inside = true;
    for (int d = 0; d < 3; ++d) inside &= r.mesh.V(i, d) > 0 && r.mesh.V(i, d) < p.size[d];
    if (inside)
      for (int d = 0; d < 3; ++d) r.mesh.V(i, d) += 0.5 * ((next() % 1000) / 1000.0 - 0.5);
  }
  const MatX3d c = simp::tet_centroids(r.mesh);
  r.density.resize(r.mesh.T.rows());
  for (long t = 0; t < r.mesh.T.rows(); ++t) {
    bool held = false;
    for (int a = 0; a < 4; ++a) held |= r.mesh.V(r.mesh.T(t, a), 0) == 0;
    const int column = static_cast<int>(c(t, 0) / 2) + 13 * static_cast<int>(std::min(c(t, 1), 12 - c(t, 1)) / 2);
    const int kind = (column * 7 + static_cast<int>(seed)) % 3;  // 0 void, 1 at the level, 2 solid
    double rho = kind == 0 ? 0.05 : kind == 2 ? 0.9 : level;
    if (kind == 1)
      for (int ulps = static_cast<int>(next() % 7) - 3; ulps != 0; ulps += ulps > 0 ? -1 : 1)
        rho = std::nextafter(rho, ulps > 0 ? 2.0 : -1.0);
    r.density[t] = held ? 1.0 : rho;
  }
  return r;
}

TEST(IsoSurface, NoCrossingsWhereTheThresholdMeetsARegionOfEqualDensities) {
  // the threshold at the region's density, or 1e-9 off it: the nodes there lie on both sides
  // of the level by rounding only; every triangle must still be placed apart (exact check)
  const double level = 0.3771133557414479;
  for (std::uint32_t seed = 0; seed < 6; ++seed) {
    const LevelPlateau f = level_plateau(level, seed);
    const VecXd nd = node_densities(f.mesh, f.density);
    for (double t : {level, level + 1e-9, level - 1e-9})
      for (double margin : {0.0, 0.2}) {
        const TriSurface s = extract_iso_surface(f.mesh, nd, t, margin);
        const ResultCheck c = check_result(s);
        EXPECT_TRUE(c.closed.closed_manifold()) << "seed " << seed << ", threshold " << t << ", margin " << margin;
        EXPECT_GT(c.closed.volume, 0.0);
        EXPECT_TRUE(c.crossings.empty()) << c.crossings.size() << " crossing pairs; seed " << seed << ", threshold "
                                         << t - level << " off the region's density, margin " << margin;
      }
  }
}

TEST(IsoSurface, EveryCrossingKeepsTheMarginFromBothNodesOfItsEdge) {
  // two nodes just off the level next to each other, each beside nodes far from it: the
  // margin holds for the values as finally adjusted, on every crossed edge
  const double level = 0.3771133557414479;
  const LevelPlateau f = level_plateau(level, 1);
  const VecXd nd = node_densities(f.mesh, f.density);
  const double margin = 0.2;
  const TriSurface s = extract_iso_surface(f.mesh, nd, level, margin);
  // each point that is no mesh node lies on a design-tet edge (x, y): margin × |xy| from both
  long checked = 0;
  for (long p = 0; p < s.V.rows(); ++p) {
    const Eigen::Vector3d q = s.V.row(p);
    double share = -1;
    for (long t = 0; t < f.mesh.T.rows() && share < 0; ++t)
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
          const Eigen::Vector3d x = f.mesh.V.row(f.mesh.T(t, a)), y = f.mesh.V.row(f.mesh.T(t, b));
          const double len = (y - x).norm(), along = (q - x).dot(y - x) / (len * len);
          if (q != x && q != y && (x + along * (y - x) - q).norm() < 1e-12 * len && along > 0 && along < 1)
            share = std::min(along, 1 - along);
        }
    if (share < 0) continue;  // a mesh node (see below)
    EXPECT_GE(share, margin - 1e-9) << "point " << p;
    ++checked;
  }
  EXPECT_GT(checked, 100);
  // and no crossing fell onto a node: each node's position is one point of the surface
  std::map<std::array<double, 3>, int> at;
  for (long p = 0; p < s.V.rows(); ++p) ++at[{s.V(p, 0), s.V(p, 1), s.V(p, 2)}];
  for (const auto& [x, n] : at) EXPECT_EQ(n, 1) << "a point at (" << x[0] << ", " << x[1] << ", " << x[2] << ")";
}

}  // namespace
}  // namespace topopt::result
