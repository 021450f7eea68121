// 2D advancing front on partially meshed faces: the result and the pre-placed triangles tile
// the region exactly (area, and every directed edge matched by its opposite except on the
// boundary), pre-placed triangles, isolated segments and isolated nodes are kept, and the
// triangles are well shaped.
#include "mesh/surface/face_front.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "common/error.h"

namespace topopt::mesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Builder {
  std::vector<std::array<double, 2>> pts;
  std::vector<std::array<int, 2>> boundary, segments;
  std::vector<std::array<int, 3>> tris;
  std::vector<int> isolated;
  std::map<std::pair<long, long>, int> index;  // exact points on a fine lattice -> node
  int node(double x, double y) {
    auto key = std::make_pair(std::lround(x * 1e6), std::lround(y * 1e6));
    auto it = index.find(key);
    if (it != index.end()) return it->second;
    pts.push_back({x, y});
    return index[key] = static_cast<int>(pts.size()) - 1;
  }
  /// A polyline loop through the corners, each side split into pieces of about h.
  void loop(const std::vector<std::array<double, 2>>& corners, double h) {
    for (size_t k = 0; k < corners.size(); ++k) {
      auto p = corners[k], q = corners[(k + 1) % corners.size()];
      const int n = std::max(1, static_cast<int>(std::lround(std::hypot(q[0] - p[0], q[1] - p[1]) / h)));
      for (int i = 0; i < n; ++i) {
        const double t0 = double(i) / n, t1 = double(i + 1) / n;
        boundary.push_back({node(p[0] + t0 * (q[0] - p[0]), p[1] + t0 * (q[1] - p[1])),
                            node(p[0] + t1 * (q[0] - p[0]), p[1] + t1 * (q[1] - p[1]))});
      }
    }
  }
  FaceFrontInput input() const {
    FaceFrontInput in;
    in.P.resize(pts.size(), 2);
    for (size_t i = 0; i < pts.size(); ++i) in.P.row(i) << pts[i][0], pts[i][1];
    in.boundary.resize(boundary.size(), 2);
    for (size_t i = 0; i < boundary.size(); ++i) in.boundary.row(i) << boundary[i][0], boundary[i][1];
    in.segments.resize(segments.size(), 2);
    for (size_t i = 0; i < segments.size(); ++i) in.segments.row(i) << segments[i][0], segments[i][1];
    in.triangles.resize(tris.size(), 3);
    for (size_t i = 0; i < tris.size(); ++i) in.triangles.row(i) << tris[i][0], tris[i][1], tris[i][2];
    in.isolated = isolated;
    return in;
  }
};

double area(const MatX2d& P, int a, int b, int c) {
  return 0.5 * ((P(b, 0) - P(a, 0)) * (P(c, 1) - P(a, 1)) - (P(b, 1) - P(a, 1)) * (P(c, 0) - P(a, 0)));
}

double min_angle_deg(const MatX2d& P, const Eigen::RowVector3i& t) {
  double m = 180;
  for (int k = 0; k < 3; ++k) {
    Eigen::RowVector2d u = P.row(t[(k + 1) % 3]) - P.row(t[k]), v = P.row(t[(k + 2) % 3]) - P.row(t[k]);
    m = std::min(m, std::acos(std::clamp(u.dot(v) / (u.norm() * v.norm()), -1.0, 1.0)) * 180 / kPi);
  }
  return m;
}

/// Checks the tiling and returns the smallest angle of the new triangles.
double check(const FaceFrontInput& in, const FaceFrontResult& out, double region_area) {
  // the input points are unchanged
  EXPECT_EQ((out.P.topRows(in.P.rows()) - in.P).cwiseAbs().maxCoeff(), 0.0);
  std::map<std::pair<int, int>, int> used;
  double sum = 0, worst = 180;
  for (long t = 0; t < out.T.rows(); ++t) {
    double A = area(out.P, out.T(t, 0), out.T(t, 1), out.T(t, 2));
    EXPECT_GT(A, 0) << "triangle " << t;
    sum += A;
    worst = std::min(worst, min_angle_deg(out.P, out.T.row(t)));
    for (int k = 0; k < 3; ++k) ++used[{out.T(t, k), out.T(t, (k + 1) % 3)}];
  }
  for (long t = 0; t < in.triangles.rows(); ++t) {
    sum += area(out.P, in.triangles(t, 0), in.triangles(t, 1), in.triangles(t, 2));
    for (int k = 0; k < 3; ++k) ++used[{in.triangles(t, k), in.triangles(t, (k + 1) % 3)}];
  }
  EXPECT_NEAR(sum, region_area, 1e-12 * region_area);
  std::map<std::pair<int, int>, int> bnd;
  for (long k = 0; k < in.boundary.rows(); ++k) ++bnd[{in.boundary(k, 0), in.boundary(k, 1)}];
  for (const auto& [e, n] : used) {
    EXPECT_EQ(n, 1) << "directed edge " << e.first << "->" << e.second << " used " << n << " times";
    const bool reverse = used.count({e.second, e.first}) > 0;
    if (bnd.count(e))
      EXPECT_FALSE(reverse) << "a boundary edge is used from outside";
    else
      EXPECT_TRUE(reverse) << "edge " << e.first << "->" << e.second << " is unmatched";
  }
  for (const auto& [e, n] : bnd) EXPECT_TRUE(used.count(e)) << "boundary edge missing";
  for (long k = 0; k < in.segments.rows(); ++k) {
    EXPECT_TRUE(used.count({in.segments(k, 0), in.segments(k, 1)}));
    EXPECT_TRUE(used.count({in.segments(k, 1), in.segments(k, 0)}));
  }
  for (int n : in.isolated) {
    bool found = false;
    for (const auto& [e, c] : used) found |= e.first == n;
    EXPECT_TRUE(found) << "isolated node " << n << " is not a vertex";
  }
  return worst;
}

TEST(FaceFront, SquareAndSquareWithHole) {
  {
    Builder b;
    b.loop({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, 0.1);
    FaceFrontInput in = b.input();
    FaceFrontResult out = fill_face(in);
    EXPECT_GT(check(in, out, 1.0), 35.0);  // 40.6° measured
    EXPECT_GT(out.T.rows(), 150);
    EXPECT_LT(out.T.rows(), 320);
  }
  {
    Builder b;
    b.loop({{0, 0}, {4, 0}, {4, 4}, {0, 4}}, 0.25);
    std::vector<std::array<double, 2>> hole;
    const int n = 24;
    double hole_area = 0;
    for (int k = 0; k < n; ++k) {  // clockwise: the region is on the left
      const double t = -2 * kPi * k / n;
      hole.push_back({2 + std::cos(t), 2 + std::sin(t)});
    }
    for (int k = 0; k < n; ++k)
      hole_area += 0.5 * (hole[k][0] * hole[(k + 1) % n][1] - hole[(k + 1) % n][0] * hole[k][1]);
    b.loop(hole, 1.0);  // one segment a side
    FaceFrontInput in = b.input();
    FaceFrontParams p;
    p.size = [](const double*) { return 0.25; };
    FaceFrontResult out = fill_face(in, p);
    EXPECT_GT(check(in, out, 16.0 + hole_area), 25.0);  // hole_area < 0 (clockwise); 30.2° measured
  }
}

TEST(FaceFront, ACancelStopsTheFront) {
  // the front checks for a cancel (and so the native mesher's time budget) every 1024 steps,
  // counted whether or not a step made a triangle, so a front retrying edges is stopped too
  Builder b;
  b.loop({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, 0.01);  // about 20 000 triangles to make
  const FaceFrontInput in = b.input();
  long asked = 0;
  Progress cancel;
  cancel.cancelled = [&asked] { return ++asked > 0; };
  try {
    fill_face(in, {}, cancel);
    FAIL() << "the front ran to its end through a cancel";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Cancelled) << e.what();
  }
  EXPECT_EQ(asked, 1) << "asked once and stopped";
}

TEST(FaceFront, PrePlacedTrianglesAreKept) {
  // A strip of triangles along the bottom of a 2 x 2 square, and a lone triangle touching the
  // top side at a single node: the front starts from their free edges.
  Builder b;
  b.loop({{0, 0}, {2, 0}, {2, 2}, {0, 2}}, 0.1);
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 3; ++j) {
      const double x0 = 0.1 * i, y0 = 0.1 * j;
      int p00 = b.node(x0, y0), p10 = b.node(x0 + 0.1, y0), p01 = b.node(x0, y0 + 0.1),
          p11 = b.node(x0 + 0.1, y0 + 0.1);
      b.tris.push_back({p00, p10, p11});
      b.tris.push_back({p00, p11, p01});
    }
  b.tris.push_back({b.node(1.0, 2.0), b.node(0.95, 1.85), b.node(1.05, 1.85)});
  FaceFrontInput in = b.input();
  FaceFrontResult out = fill_face(in);
  EXPECT_GT(check(in, out, 4.0), 22.0);  // 26.3° measured
}

TEST(FaceFront, IsolatedSegmentAndNodes) {
  Builder b;
  b.loop({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, 0.1);
  for (int i = 0; i < 4; ++i) b.segments.push_back({b.node(0.3 + 0.1 * i, 0.5), b.node(0.4 + 0.1 * i, 0.5)});
  b.isolated = {b.node(0.2, 0.2), b.node(0.77, 0.31), b.node(0.5, 0.8), b.node(0.52, 0.8)};
  FaceFrontInput in = b.input();
  FaceFrontResult out = fill_face(in);
  EXPECT_GT(check(in, out, 1.0), 8.0);  // 10.9°: two isolated nodes 0.02 apart force it
}

TEST(FaceFront, GradedSizeLShapeWithRandomIsolatedNodes) {
  // Robustness: an L-shaped face with a square hole, the size growing 8x across it, and random
  // isolated nodes, over several seeds.
  for (unsigned seed = 1; seed <= 6; ++seed) {
    Builder b;
    b.loop({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}}, 0.05);
    b.loop({{0.3, 0.3}, {0.3, 0.6}, {0.6, 0.6}, {0.6, 0.3}}, 0.05);  // clockwise hole
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> U(0.05, 1.95);
    while (b.isolated.size() < 25) {
      double x = U(rng), y = U(rng);
      if ((x > 0.95 && y > 0.95) || (x > 0.25 && x < 0.65 && y > 0.25 && y < 0.65)) continue;
      b.isolated.push_back(b.node(x, y));
    }
    FaceFrontInput in = b.input();
    FaceFrontParams p;
    p.size = [](const double* q) { return 0.05 + 0.2 * q[0] * q[1]; };
    FaceFrontResult out = fill_face(in, p);
    check(in, out, 3.0 - 0.09);
  }
}

TEST(FaceFront, OpenBoundaryIsRejected) {
  Builder b;
  b.loop({{0, 0}, {1, 0}, {1, 1}, {0, 1}}, 0.25);
  b.boundary.pop_back();
  FaceFrontInput in = b.input();
  EXPECT_THROW(fill_face(in), Error);
}

}  // namespace
}  // namespace topopt::mesh
