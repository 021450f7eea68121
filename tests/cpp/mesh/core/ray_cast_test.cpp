// Rays against a triangle soup: distances inside a box against the closed form, the skipped
// triangle, and the cut-off.
#include "mesh/core/ray_cast.h"

#include <gtest/gtest.h>

#include <random>

namespace topopt::mesh {
namespace {

TEST(TriangleRays, DistancesInsideABoxMatchTheClosedForm) {
  // the box [0,4] x [0,2] x [0,1] as 12 triangles, plus many small ones on a far plane so the
  // hierarchy has depth
  const double L[3] = {4, 2, 1};
  std::vector<Eigen::RowVector3d> v;
  std::vector<Eigen::RowVector3i> f;
  for (int c = 0; c < 8; ++c) v.emplace_back(c & 1 ? L[0] : 0, c & 2 ? L[1] : 0, c & 4 ? L[2] : 0);
  const int quads[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
  for (const auto& q : quads) f.emplace_back(q[0], q[1], q[2]), f.emplace_back(q[0], q[2], q[3]);
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j) {
      const int b = static_cast<int>(v.size());
      v.emplace_back(100 + i, j, 50), v.emplace_back(101 + i, j, 50), v.emplace_back(100 + i, j + 1, 50);
      f.emplace_back(b, b + 1, b + 2);
    }
  MatX3d V(v.size(), 3);
  MatX3i F(f.size(), 3);
  for (size_t i = 0; i < v.size(); ++i) V.row(i) = v[i];
  for (size_t i = 0; i < f.size(); ++i) F.row(i) = f[i];
  const TriangleRays rays(V, F);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.05, 0.95), g(-1, 1);
  for (int k = 0; k < 500; ++k) {
    const double o[3] = {u(rng) * L[0], u(rng) * L[1], u(rng) * L[2]};
    Eigen::Vector3d d(g(rng), g(rng), g(rng));
    d.normalize();
    double expect = 1e300;
    for (int a = 0; a < 3; ++a)
      if (d[a] != 0) expect = std::min(expect, ((d[a] > 0 ? L[a] : 0) - o[a]) / d[a]);
    EXPECT_NEAR(rays.first_hit(o, d.data(), -1, 1e9), expect, 1e-9 * expect) << "ray " << k;
    EXPECT_EQ(rays.first_hit(o, d.data(), -1, 0.5 * expect), 0.5 * expect);  // beyond the cut-off
  }
  // from the middle of the bottom face straight up: the top at 1; skipping the bottom's own
  // triangle changes nothing, and a ray along an axis (zero components) works
  const double o[3] = {1, 0.5, 0}, up[3] = {0, 0, 1};
  EXPECT_DOUBLE_EQ(rays.first_hit(o, up, 8, 10), 1.0);
}

}  // namespace
}  // namespace topopt::mesh
