// The surface stage under an overhang control (src/result/overhang_lift): the last pass lifts the
// downward facets that the margin, the remeshing and the smoothing tilted below the critical angle
// back above it on a slope that prints, within its reach, keeping the surface valid and making no
// keel or lowest point; and it cannot make a flat ceiling print (no corrugating it into steep
// facets). The property on an optimised design is in tests/cpp/simp/overhang_test.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <random>

#include "mesh/core/structured_box.h"
#include "result/design_surface.h"
#include "result/overhang_lift.h"

namespace topopt::result {
namespace {

/// A 10 mm cube of 1 mm cells; node densities 0.5 + 0.1 · (signed distance above `level`(x, z)),
/// each node's value scattered by up to ±`noise` (noise seed `seed`): the iso-surface at 0.5 is the
/// surface z = level, rippled as an optimised design's staircase is.
template <class Level>
TriSurface rippled_surface(Level level, double noise, unsigned seed = 7) {
  mesh::StructuredBoxParams box;
  box.size = {10, 10, 10};
  box.cells = {10, 10, 10};
  const TetMesh m = mesh::structured_box_mesh(box);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-noise, noise);
  VecXd nd(m.V.rows());
  for (long i = 0; i < m.V.rows(); ++i) nd[i] = 0.5 + 0.1 * level(m.V(i, 0), m.V(i, 2)) + u(rng);
  return extract_iso_surface(m, nd, 0.5, 0.2);
}

/// The surface finished as the product does, with the build along +z from the cube's bottom (or
/// without a build: the same surface before the last pass).
TriSurface finished(TriSurface s, bool with_build, DesignSurfaceReport* report = nullptr) {
  SmoothParams smooth;
  if (with_build) smooth.build.direction = Eigen::Vector3d::UnitZ();
  const DesignSurfaceReport r = finish_design_surface(s, smooth);
  if (report) *report = r;
  return s;
}

/// One rippled surface finished without the build and with it (+z, 45°), with the area too flat on each.
struct Finished {
  TriSurface plain, lifted;
  DesignSurfaceReport report;  // of the lifted one
  double too_flat_before = 0, too_flat_after = 0;
};

Finished finished_both_ways(const TriSurface& rippled) {
  Finished f;
  f.plain = finished(rippled, false);
  f.lifted = finished(rippled, true, &f.report);
  BuildDirection build;
  build.direction = Eigen::Vector3d::UnitZ();
  f.too_flat_before = too_flat_area(f.plain, build, 45);
  f.too_flat_after = too_flat_area(f.lifted, build, 45);
  return f;
}

/// The mean length of the edges at each point of s (#P).
VecXd mean_edge(const TriSurface& s) {
  VecXd sum = VecXd::Zero(s.V.rows()), count = VecXd::Zero(s.V.rows());
  for (long t = 0; t < s.F.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = s.F(t, k), b = s.F(t, (k + 1) % 3);
      const double l = (s.V.row(a) - s.V.row(b)).norm();
      sum[a] += l, sum[b] += l, count[a] += 1, count[b] += 1;  // each edge twice from its two triangles
    }
  return sum.cwiseQuotient(count.cwiseMax(1));
}

TEST(OverhangLift, LiftsTheFacetsOfAPrintableSlopeBackAboveTheAngle) {
  // the solid above a plane rising 52° along x from (x, z) = (2, 0): its underside faces down at
  // 52°, printable; the ripple and the smoothing scatter its facets, some below 45°
  const double slope = std::tan(52 * M_PI / 180), c = std::cos(52 * M_PI / 180);
  const TriSurface rippled = rippled_surface([&](double x, double z) { return (z - slope * (x - 2)) * c; }, 0.02);
  const Finished both = finished_both_ways(rippled);
  const TriSurface &plain = both.plain, &lifted = both.lifted;
  const DesignSurfaceReport& report = both.report;
  const double before = both.too_flat_before, after = both.too_flat_after;
  std::cout << "too flat: " << before << " mm2 -> " << after << " mm2, " << report.lift.moves << " moves, keels "
            << report.lift.keels_before << " -> " << report.lift.keels_after << " mm\n";
  ASSERT_GT(before, 0.5) << "the ripple should tilt some facets below 45 degrees";
  EXPECT_NEAR(report.lift.before, before, 1e-9);
  EXPECT_LE(after, 0.15 * before);  // measured 10.7 -> 0.93 mm²
  EXPECT_NEAR(report.lift.after, after, 1e-9);
  // the same triangles, each point within its reach, nothing crossing, no worse shapes
  ASSERT_EQ(lifted.V.rows(), plain.V.rows());
  ASSERT_EQ(lifted.F, plain.F);
  const VecXd edge = mean_edge(plain);
  for (long i = 0; i < plain.V.rows(); ++i)
    EXPECT_LE((lifted.V.row(i) - plain.V.row(i)).norm(), OverhangLiftParams{}.reach * edge[i] * (1 + 1e-9)) << i;
  const ResultCheck check = report.check;
  EXPECT_TRUE(check.valid());
  EXPECT_GE(check.min_angle_free, std::min(10.0, check_result(plain).min_angle_free));
  EXPECT_LE(report.lift.keels_after, report.lift.keels_before + 1e-9);
  EXPECT_LE(report.lift.lowest_after, report.lift.lowest_before);
  EXPECT_NEAR(check.closed.volume, check_surface(plain.V, plain.F).volume, 0.005 * check.closed.volume);  // 0.22 %
}

TEST(OverhangLift, CannotMakeAFlatCeilingPrint) {
  // the solid above z = 5: its underside is a ceiling facing straight down. Tilting the small
  // triangles on the ripple's bumps would make some of it read as printable while the ceiling
  // prints on nothing; the figure must hold for every ripple, not one lucky seed (before the lift
  // kept to printable slopes, main lifted 5-16 % of it: 0.838-0.907, 15 of 16 seeds below 0.9)
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const TriSurface rippled = rippled_surface([](double, double z) { return z - 5; }, 0.02, seed);
    const Finished both = finished_both_ways(rippled);
    const DesignSurfaceReport& report = both.report;
    const double before = both.too_flat_before, after = both.too_flat_after;
    std::cout << "seed " << seed << ": ceiling too flat: " << before << " mm2 -> " << after << " mm2 ("
              << after / before << "), " << report.lift.moves << " moves\n";
    EXPECT_GT(before, 90) << seed;  // the 100 mm² ceiling, less what the ripple tilts
    EXPECT_GE(after, 0.9 * before) << seed;
    EXPECT_TRUE(report.check.valid()) << seed;
    EXPECT_LE(report.lift.keels_after, report.lift.keels_before + 1e-9) << seed;
  }
}

TEST(OverhangLift, DoesNothingWithoutABuild) {
  TriSurface s = rippled_surface([](double, double z) { return z - 5; }, 0.02);
  const MatX3d V = s.V;
  const OverhangLiftReport r = lift_overhangs(s, BuildDirection{});
  EXPECT_EQ(r.moves, 0);
  EXPECT_EQ(s.V, V);
}

}  // namespace
}  // namespace topopt::result
