// The free-form region coarsened for the CAD solid: fewer triangles, every point of the surface
// given within the tolerance of the new one, Ω's and the non-design faces untouched, still a
// valid result surface by the product's exact check.
#include "result/step_coarsen.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "result/result_check.h"
#include "result/smoothing.h"
#include "testing/bar_field.h"

namespace topopt::result {
namespace {

/// The bar fixture's iso-surface (step_export_test's), smoothed as the product does so that
/// the free-form region is smooth enough to coarsen.
TriSurface smooth_bar() {
  const testing::BarField bar = testing::bar_field(6, testing::wavy_radius);
  TriSurface s = extract_iso_surface(bar.mesh, node_densities(bar.mesh, bar.density), 0.5);
  smooth_surface(s, SmoothParams{});
  return s;
}

/// The triangles of s that are not free-form, as (tag, sorted corners).
std::multiset<std::array<int, 4>> face_triangles(const TriSurface& s) {
  std::multiset<std::array<int, 4>> out;
  for (long q = 0; q < s.F.rows(); ++q) {
    if (s.tag[q] == 0) continue;
    std::array<int, 3> c{s.F(q, 0), s.F(q, 1), s.F(q, 2)};
    std::sort(c.begin(), c.end());
    out.insert({s.tag[q], c[0], c[1], c[2]});
  }
  return out;
}

/// The largest distance from a point used by `from` to the nearest triangle of `to`.
double farthest_point(const TriSurface& from, const TriSurface& to) {
  std::set<int> used(from.F.data(), from.F.data() + from.F.size());
  double worst = 0;
  for (int p : used) {
    double nearest = 1e300;
    for (long q = 0; q < to.F.rows(); ++q)
      nearest = std::min(nearest,
                         point_triangle_distance(from.V.row(p).transpose(), to.V.row(to.F(q, 0)).transpose(),
                                                 to.V.row(to.F(q, 1)).transpose(), to.V.row(to.F(q, 2)).transpose()));
    worst = std::max(worst, nearest);
  }
  return worst;
}

TEST(StepCoarsen, PointTriangleDistanceByRegion) {
  const Eigen::Vector3d a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
  EXPECT_NEAR(point_triangle_distance({0.5, 0.5, 3}, a, b, c), 3, 1e-12);           // above the inside
  EXPECT_NEAR(point_triangle_distance({-3, -4, 0}, a, b, c), 5, 1e-12);             // past corner a
  EXPECT_NEAR(point_triangle_distance({1, -2, 0}, a, b, c), 2, 1e-12);              // beside edge ab
  EXPECT_NEAR(point_triangle_distance({2, 2, 0}, a, b, c), std::sqrt(2.0), 1e-12);  // beside edge bc
  EXPECT_NEAR(point_triangle_distance({5, 0, 4}, a, b, c), 5, 1e-12);               // past corner b
}

TEST(StepCoarsen, FewerFreeFormTrianglesWithinTheToleranceFacesUntouched) {
  const TriSurface s = smooth_bar();
  ASSERT_TRUE(check_result(s).valid());
  CoarsenReport r;
  const TriSurface c = coarsen_free_form(s, {}, &r);
  EXPECT_FALSE(r.reverted);
  EXPECT_GT(r.tolerance, 0);
  EXPECT_EQ(r.triangles_before, s.F.rows());
  EXPECT_EQ(r.triangles_after, c.F.rows());
  EXPECT_LT(c.F.rows(), 0.8 * s.F.rows());
  const ResultCheck check = check_result(c);
  EXPECT_TRUE(check.valid());
  EXPECT_GE(check.min_angle_free, std::min(CoarsenParams{}.min_angle, check_result(s).min_angle_free));
  // Ω's faces and the non-design solids' faces: the same triangles on the same points
  EXPECT_EQ(face_triangles(c), face_triangles(s));
  EXPECT_EQ(c.V, s.V);
  // no point of the surface given farther than the tolerance from the new one: the volume
  // moves by at most the tolerance times the area
  EXPECT_LE(farthest_point(s, c), r.tolerance * (1 + 1e-9));
  double area = 0;
  for (long q = 0; q < s.F.rows(); ++q)
    area += (s.V.row(s.F(q, 1)) - s.V.row(s.F(q, 0))).cross(s.V.row(s.F(q, 2)) - s.V.row(s.F(q, 0))).norm() / 2;
  EXPECT_LE(std::abs(check.closed.volume - check_result(s).closed.volume), r.tolerance * area);
}

TEST(StepCoarsen, NoToleranceNoChange) {
  const TriSurface s = smooth_bar();
  CoarsenReport r;
  const TriSurface c = coarsen_free_form(s, {.tolerance = 0}, &r);
  EXPECT_EQ(c.F, s.F);
  EXPECT_EQ(r.triangles_after, s.F.rows());
  // a tighter tolerance removes fewer points than a looser one
  const long tight = coarsen_free_form(s, {.tolerance = 0.01}).F.rows();
  const long loose = coarsen_free_form(s, {.tolerance = 0.1}).F.rows();
  EXPECT_LE(loose, tight);
  EXPECT_LE(tight, s.F.rows());
}

}  // namespace
}  // namespace topopt::result
