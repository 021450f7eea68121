// The point of a triangle (or of a segment) nearest to a point: the distance transforms of the
// design (hygiene's thinnest member, the member-size measure), the STEP coarsening's tolerance,
// the planar faces' straight runs and the bridges' tubes use them.
#pragma once
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>

namespace topopt {

/// The parameter t in [0, 1] of the point a + t (b − a) of segment a-b nearest to p (0 for a
/// degenerate segment).
inline double segment_parameter(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  return len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
}

/// The point of segment a-b nearest to p (a for a degenerate segment).
inline Eigen::Vector3d closest_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b) {
  return a + segment_parameter(p, a, b) * (b - a);
}

/// The distance from p to segment a-b.
inline double distance_to_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return (p - closest_on_segment(p, a, b)).norm();
}

/// The point of triangle (a, b, c) nearest to p (all in mm), by the Voronoi region of p: a
/// corner, an edge or the inside (Ericson, Real-Time Collision Detection, 5.1.5). A degenerate
/// triangle gives the nearest point of its edges.
inline Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                           const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

/// Where the ray p + s u (s > 0, u a unit vector) meets the triangle (a, b, c): s, or +inf
/// when it misses (Möller–Trumbore).
inline double ray_triangle_hit(const Eigen::Vector3d& p, const Eigen::Vector3d& u, const Eigen::Vector3d& a,
                               const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, h = u.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-14 * e1.norm() * e2.norm()) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d s = p - a, q = s.cross(e1);
  const double bu = s.dot(h) / det, bv = u.dot(q) / det, t = e2.dot(q) / det;
  if (bu < 0 || bv < 0 || bu + bv > 1 || t <= 0) return std::numeric_limits<double>::infinity();
  return t;
}

}  // namespace topopt
