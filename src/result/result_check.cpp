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

/// The points of the triangles `tris` and, `ring` times, their neighbours through F.
std::vector<char> around_triangles(const TriSurface& s, const std::vector<int>& tris, int ring) {
  std::vector<char> mark(s.V.rows(), 0);
  for (int t : tris)
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

/// The triangles of both sides of every crossing.
std::vector<int> crossing_triangles(const std::vector<std::pair<int, int>>& crossings) {
  std::vector<int> tris;
  for (const auto& [a, b] : crossings) tris.push_back(a), tris.push_back(b);
  return tris;
}

/// Free-form triangles sharper than `floor` degrees in s and sharper than they were in `before`.
std::vector<int> sharpened(const TriSurface& s, const MatX3d& before, double floor) {
  std::vector<int> tris;
  for (long t = 0; t < s.F.rows(); ++t) {
    if (s.tag.size() == s.F.rows() && s.tag[t] != 0) continue;
    const double now = min_triangle_angle(s.V, s.F(t, 0), s.F(t, 1), s.F(t, 2));
    if (now < floor && now < min_triangle_angle(before, s.F(t, 0), s.F(t, 1), s.F(t, 2)) - 1e-9)
      tris.push_back(static_cast<int>(t));
  }
  return tris;
}

/// Moves the points marked back towards `before`, keeping `keep` of their displacement.
void pull_back(TriSurface& s, const MatX3d& before, const std::vector<char>& mark, double keep) {
  for (long i = 0; i < s.V.rows(); ++i)
    if (mark[i]) s.V.row(i) = before.row(i) + keep * (s.V.row(i) - before.row(i));
}

}  // namespace

long unsharpen(TriSurface& s, const MatX3d& before, double floor, const UntangleParams& params) {
  for (int round = 0; round < 2 * params.rounds; ++round) {
    const std::vector<int> tris = sharpened(s, before, floor);
    if (tris.empty()) return 0;
    pull_back(s, before, around_triangles(s, tris, params.ring), round < params.rounds ? 0.5 : 0.0);
  }
  return static_cast<long>(sharpened(s, before, floor).size());
}

std::vector<std::pair<int, int>> untangle(TriSurface& s, const MatX3d& before, const UntangleParams& params) {
  constexpr long kAll = 1L << 40;
  for (int round = 0; round < 2 * params.rounds; ++round) {
    const std::vector<std::pair<int, int>> crossings = mesh::self_intersections(s.V, s.F, kAll);
    if (crossings.empty()) return crossings;
    const double keep = round < params.rounds ? 0.5 : 0.0;  // share of the smoothing displacement kept
    pull_back(s, before, around_triangles(s, crossing_triangles(crossings), params.ring), keep);
  }
  return mesh::self_intersections(s.V, s.F, kAll);
}

}  // namespace topopt::result
