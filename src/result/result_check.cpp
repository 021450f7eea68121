// The result surface's validity and the repair of crossings (see result_check.h).
#include "result/result_check.h"

#include <algorithm>
#include <cmath>

#include "mesh/surface/surface_check.h"

namespace topopt::result {

double min_triangle_angle(const MatX3d& V, int a, int b, int c) {
  const int v[3] = {a, b, c};
  double smallest = 180;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d p = V.row(v[k]), q = V.row(v[(k + 1) % 3]), r = V.row(v[(k + 2) % 3]);
    const Eigen::Vector3d u = q - p, w = r - p;
    const double nu = u.norm(), nw = w.norm();
    if (nu == 0 || nw == 0) return 0;
    const double angle = std::atan2(u.cross(w).norm(), u.dot(w)) * 180 / M_PI;
    smallest = std::min(smallest, angle);
  }
  return smallest;
}

ResultCheck check_result(const TriSurface& s, long max_crossings) {
  ResultCheck c;
  c.closed = check_surface(s.V, s.F);
  c.crossings = mesh::self_intersections(s.V, s.F, max_crossings);
  for (long t = 0; t < s.F.rows(); ++t) {
    const double a = min_triangle_angle(s.V, s.F(t, 0), s.F(t, 1), s.F(t, 2));
    const int tag = s.tag.size() == s.F.rows() ? s.tag[t] : 0;
    double& region = tag == 0 ? c.min_angle_free : tag > 0 ? c.min_angle_faces : c.min_angle_nondesign;
    region = std::min(region, a);
  }
  return c;
}

namespace {

/// The points of the crossing triangles and, `ring` times, their neighbours through F.
std::vector<char> around_crossings(const TriSurface& s, const std::vector<std::pair<int, int>>& crossings, int ring) {
  std::vector<char> mark(s.V.rows(), 0);
  for (const auto& [a, b] : crossings)
    for (int t : {a, b})
      for (int k = 0; k < 3; ++k) mark[s.F(t, k)] = 1;
  for (int r = 0; r < ring; ++r) {
    std::vector<char> grown = mark;
    for (long t = 0; t < s.F.rows(); ++t) {
      const bool touched = mark[s.F(t, 0)] || mark[s.F(t, 1)] || mark[s.F(t, 2)];
      if (touched)
        for (int k = 0; k < 3; ++k) grown[s.F(t, k)] = 1;
    }
    mark.swap(grown);
  }
  return mark;
}

}  // namespace

std::vector<std::pair<int, int>> untangle(TriSurface& s, const MatX3d& before, const UntangleParams& params) {
  constexpr long kAll = 1L << 40;
  for (int round = 0; round < 2 * params.rounds; ++round) {
    const std::vector<std::pair<int, int>> crossings = mesh::self_intersections(s.V, s.F, kAll);
    if (crossings.empty()) return crossings;
    const std::vector<char> mark = around_crossings(s, crossings, params.ring);
    const double keep = round < params.rounds ? 0.5 : 0.0;  // share of the smoothing displacement kept
    for (long i = 0; i < s.V.rows(); ++i)
      if (mark[i]) s.V.row(i) = before.row(i) + keep * (s.V.row(i) - before.row(i));
  }
  return mesh::self_intersections(s.V, s.F, kAll);
}

}  // namespace topopt::result
