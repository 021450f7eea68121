// The hashed grid of boxes against brute force: boxes of sizes graded over four orders of
// magnitude in space, queried by small boxes (cells visited one by one) and by large ones
// (occupied blocks), with items removed through keep(); points in the plane by the const visit.
#include "mesh/core/spatial_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace topopt::mesh {
namespace {

struct Box3 {
  std::array<double, 3> lo, hi;
};

bool overlap(const Box3& a, const Box3& b) {
  for (int d = 0; d < 3; ++d)
    if (a.hi[d] < b.lo[d] || b.hi[d] < a.lo[d]) return false;
  return true;
}

/// Boxes with edges from 1e-3 to 10 in [0, 20]³ (log-uniform), from a fixed seed.
std::vector<Box3> graded_boxes(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> where(0, 20), scale(-3, 1);
  std::vector<Box3> boxes(n);
  for (Box3& b : boxes) {
    const double e = std::pow(10.0, scale(rng));
    for (int d = 0; d < 3; ++d) b.lo[d] = where(rng), b.hi[d] = b.lo[d] + e * (0.5 + 0.5 * (d + 1) / 3.0);
  }
  return boxes;
}

TEST(SpatialGrid, QueriesReturnEveryOverlappingBoxOnceAndDropTheDeadOnes) {
  std::mt19937 rng(7);
  const std::vector<Box3> boxes = graded_boxes(3000, rng);
  const double origin[3] = {0, 0, 0};
  SpatialGrid<3> grid(origin, 0.01);
  for (size_t i = 0; i < boxes.size(); ++i) grid.insert(static_cast<int>(i), boxes[i].lo.data(), boxes[i].hi.data());
  std::vector<char> alive(boxes.size(), 1);
  std::uniform_real_distribution<double> where(0, 20), half(0.01, 3);
  long large = 0, found_total = 0;
  for (int q = 0; q < 400; ++q) {
    if (q == 200)  // half the items die: queries must no longer return them
      for (size_t i = 0; i < alive.size(); i += 2) alive[i] = 0;
    Box3 box;
    const double r = q % 4 == 0 ? half(rng) : 0.02 * half(rng);
    large += r > 1;
    for (int d = 0; d < 3; ++d) {
      const double c = where(rng);
      box.lo[d] = c - r, box.hi[d] = c + r;
    }
    std::vector<int> out{-7};  // appended to, not cleared
    grid.query(box.lo.data(), box.hi.data(), out, [&](int id) { return alive[id] != 0; });
    ASSERT_EQ(out.front(), -7);
    const std::set<int> got(out.begin() + 1, out.end());
    ASSERT_EQ(got.size(), out.size() - 1) << "an id came back twice";
    for (int id : got) EXPECT_TRUE(alive[id]) << "dead item " << id << " returned";
    for (size_t i = 0; i < boxes.size(); ++i)
      if (alive[i] && overlap(boxes[i], box)) {
        EXPECT_TRUE(got.count(static_cast<int>(i))) << "box " << i << " overlaps query " << q << " but was missed";
        ++found_total;
      }
  }
  EXPECT_GT(large, 30);          // the block path ran (over 64 cells of level 0)
  EXPECT_GT(found_total, 1000);  // and the queries met many boxes
}

TEST(SpatialGrid, CandidatesStayNearTheQueryBox) {
  // items land on the level of their size: a query returns only items from cells within one
  // cell of that level of the box, so a tiny box among large and tiny items gets few answers
  const double origin[3] = {0, 0, 0};
  SpatialGrid<3> grid(origin, 0.1);
  int id = 0;
  for (int x = 0; x < 50; ++x)
    for (int y = 0; y < 50; ++y) {
      const double p[3] = {x * 0.1 + 0.05, y * 0.1 + 0.05, 0.05};
      grid.insert(id++, p, p);  // points: level 0, one cell each
    }
  const double big_lo[3] = {2, 2, 2}, big_hi[3] = {2.5, 2.5, 2.5};
  grid.insert(id++, big_lo, big_hi);  // one box of 0.5: level 3 (cells of 0.8)
  const double lo[3] = {1.01, 1.01, 0.01}, hi[3] = {1.09, 1.09, 0.09};
  std::vector<int> out;
  grid.query(lo, hi, out, [](int) { return true; });
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0], 10 * 50 + 10);
  // a size larger than the box puts a point on a coarse level: found from farther away
  const double far[3] = {3.3, 3.3, 0.05};
  grid.insert(id, far, far, 1.6);  // level 4: cells of 1.6, [3.2, 4.8) in x and y
  const double near_lo[3] = {4.7, 4.7, 0.5}, near_hi[3] = {4.75, 4.75, 0.6};  // no point's cell
  out.clear();
  grid.query(near_lo, near_hi, out, [](int) { return true; });
  EXPECT_EQ(out, std::vector<int>{id});
}

TEST(SpatialGrid, AWideQueryOverATinyLevelLooksOnlyAtItsOccupiedBlocks) {
  // the volume front's grid starts at the shortest boundary edge: a result surface with one
  // tiny triangle (1e-6 of the part) put its nodes on a level whose blocks a query of the
  // usual size spans ~10^17 of; walking them all hung the verification (TetFront::nodes_near).
  // Only the level's few occupied blocks may be looked at: this query must return at once.
  const double origin[3] = {0, 0, 0};
  SpatialGrid<3> grid(origin, 1e-6);
  const double tiny_lo[3] = {5, 5, 5}, tiny_hi[3] = {5 + 5e-7, 5 + 5e-7, 5 + 5e-7};
  grid.insert(0, tiny_lo, tiny_hi);  // level 0
  const double p1[3] = {1, 2, 3}, p2[3] = {9, 9, 9};
  grid.insert(1, p1, p1), grid.insert(2, p2, p2);  // level 0 too, far apart
  const double mid_lo[3] = {4, 4, 4}, mid_hi[3] = {4.5, 4.5, 4.5};
  grid.insert(3, mid_lo, mid_hi);                     // a coarse level
  const double lo[3] = {0, 0, 0}, hi[3] = {8, 8, 8};  // 8e6 cells of level 0 a side
  std::vector<int> out;
  grid.query(lo, hi, out, [](int) { return true; });
  std::sort(out.begin(), out.end());
  EXPECT_EQ(out, (std::vector<int>{0, 1, 3}));
  std::vector<int> visited;  // once per cell an item spans: the coarse item 3 spans 8
  grid.for_each(lo, hi, [&](int id) { visited.push_back(id); });
  std::sort(visited.begin(), visited.end());
  visited.erase(std::unique(visited.begin(), visited.end()), visited.end());
  EXPECT_EQ(visited, (std::vector<int>{0, 1, 3}));
}

TEST(SpatialGrid, PointsInThePlaneByTheConstVisit) {
  // a size field as the surface mesher builds one: min over points of s_i + g·distance, where
  // only points within the reach (h − min s) / g can win; the grid's answer equals brute force
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> where(-5, 5), size(0.05, 0.5);
  std::vector<std::array<double, 3>> pts(500);
  for (auto& p : pts) p = {where(rng), where(rng), size(rng)};
  const double h = 1.0, g = 0.3, reach = (h - 0.05) / g;
  const double origin[2] = {-5, -5};
  SpatialGrid<2> grid(origin, reach / 2);
  for (size_t i = 0; i < pts.size(); ++i) grid.insert(static_cast<int>(i), pts[i].data(), pts[i].data());
  const SpatialGrid<2>& fixed = grid;
  for (int q = 0; q < 200; ++q) {
    const double x[2] = {2 * where(rng), 2 * where(rng)};  // also outside the points' box
    const double lo[2] = {x[0] - reach, x[1] - reach}, hi[2] = {x[0] + reach, x[1] + reach};
    double by_grid = h, brute = h;
    long visits = 0;
    fixed.for_each(lo, hi, [&](int i) {
      by_grid = std::min(by_grid, pts[i][2] + g * std::hypot(x[0] - pts[i][0], x[1] - pts[i][1]));
      ++visits;
    });
    for (const auto& p : pts) brute = std::min(brute, p[2] + g * std::hypot(x[0] - p[0], x[1] - p[1]));
    EXPECT_EQ(by_grid, brute) << "at (" << x[0] << ", " << x[1] << ")";
    EXPECT_LE(visits, static_cast<long>(pts.size()));  // a point is in one cell: visited once at most
  }
}

}  // namespace
}  // namespace topopt::mesh
