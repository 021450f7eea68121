// Graded size fields: the exact one equals min(h, s_i + grade·d) computed point by point; the
// raster stays within the chamfer transform's error of it, equals the cap beyond every point's
// reach, and is exact enough at the points themselves; fine_points picks the finely split nodes.
#include "mesh/surface/graded_size.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace topopt::mesh {
namespace {

/// min(h, s_i + grade·|q − p_i|) over every point, one by one.
double brute_force(const std::vector<std::array<double, 3>>& pts, const double* q, double h, double grade) {
  double s = h;
  for (const auto& p : pts) s = std::min(s, p[2] + grade * std::hypot(q[0] - p[0], q[1] - p[1]));
  return s;
}

/// 200 points with sizes 0.05..0.5 in [0, 10] x [0, 4].
std::vector<std::array<double, 3>> random_points(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(0, 10), y(0, 4), s(0.05, 0.5);
  std::vector<std::array<double, 3>> pts(200);
  for (auto& p : pts) p = {x(rng), y(rng), s(rng)};
  return pts;
}

TEST(GradedSize, PointFieldIsTheExactMinimum) {
  const double h = 2, grade = 0.3;
  const auto pts = random_points(1);
  const PointSizeField field(pts, h, grade);
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> x(-3, 13), y(-3, 7);
  int graded = 0;
  for (int k = 0; k < 5000; ++k) {
    const double q[2] = {x(rng), y(rng)};
    const double exact = brute_force(pts, q, h, grade);
    EXPECT_EQ(field.size_at(q, h), exact) << q[0] << ", " << q[1];
    graded += exact < h;
    EXPECT_EQ(field.size_at(q, 0.1), std::min(0.1, exact));  // a lower cap
  }
  EXPECT_GT(graded, 1000);  // the queries do see the points
  const PointSizeField none({}, h, grade);
  const double q[2] = {1, 1};
  EXPECT_EQ(none.size_at(q, h), h);
}

TEST(GradedSize, RasterFollowsTheExactFieldWithinTheChamferError) {
  const double cap = 2, grade = 0.3;
  const auto pts = random_points(3);
  const SizeRaster raster(pts, cap, grade);
  ASSERT_FALSE(raster.empty());
  const double cell = 0.05;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> x(-3, 13), y(-3, 7);
  double worst = 0;
  for (int k = 0; k < 5000; ++k) {
    const double q[2] = {x(rng), y(rng)};
    const double exact = brute_force(pts, q, cap, grade);
    // an 8-neighbour chamfer overestimates distances by at most 8 %; read bilinearly, a value
    // may be off by the growth across two cells (at most 0.05 a side here: 23 / 511, the
    // points' spread plus their reach, over 511)
    const double err = std::abs(raster.size_at(q, cap) - exact);
    EXPECT_LE(err, 0.08 * (exact - 0.05) + grade * 2 * cell) << q[0] << ", " << q[1];
    worst = std::max(worst, err);
  }
  EXPECT_GT(worst, 0.0);  // it is a raster, not the exact field
  for (const auto& p : pts)
    EXPECT_NEAR(raster.size_at(p.data(), cap), brute_force(pts, p.data(), cap, grade), grade * 2 * cell);
  const double far[2] = {30, 30};  // beyond every point's reach (cap - 0.05) / grade = 6.5
  EXPECT_EQ(raster.size_at(far, cap), cap);
  EXPECT_EQ(raster.size_at(far, 1.5), 1.5);
  const SizeRaster none;
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(none.size_at(far, 0.7), 0.7);
}

TEST(GradedSize, FinePointsAreTheFinelySplitNodes) {
  // a 4 x 1 rectangle: the bottom side in 8 pieces of 0.5, the others whole; h = 1
  std::vector<std::array<double, 2>> uv;
  std::vector<std::array<int, 2>> segs;
  for (int i = 0; i <= 8; ++i) uv.push_back({0.5 * i, 0});
  uv.push_back({4, 1}), uv.push_back({0, 1});
  for (int i = 0; i < 8; ++i) segs.push_back({i, i + 1});
  segs.push_back({8, 9}), segs.push_back({9, 10}), segs.push_back({10, 0});
  const auto fine = fine_points(uv, segs, 1.0);
  // inner bottom nodes: spacing 0.5; the bottom corners: (0.5 + 1) / 2 = 0.75, not below 0.7
  ASSERT_EQ(fine.size(), 7u);
  for (int i = 0; i < 7; ++i) {
    EXPECT_EQ(fine[i][0], 0.5 * (i + 1));
    EXPECT_EQ(fine[i][1], 0.0);
    EXPECT_EQ(fine[i][2], 0.5);
  }
  EXPECT_EQ(fine_points(uv, segs, 1.1).size(), 9u);  // 0.75 < 0.77: the corners too
}

}  // namespace
}  // namespace topopt::mesh
