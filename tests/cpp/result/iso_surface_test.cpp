// The result surface: closed, manifold and oriented; the volume at the chosen threshold; the
// non-design solids kept whole and unmoved by smoothing.
#include "result/iso_surface.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
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

}  // namespace
}  // namespace topopt::result
