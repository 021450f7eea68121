// The distance from a point to the non-design faces of a result surface: a point the remeshing
// adds on a non-design face (a split of an edge between two triangles in one plane) must lie on
// the faces as they were.
#pragma once
#include <algorithm>
#include <cmath>
#include <utility>

#include "result/iso_surface.h"

namespace topopt::testing {

/// The distance from p (mm) to the nearest triangle of s tagged non-design (tag < 0): to its
/// plane when p projects inside it, else to its nearest edge. 1e300 when s has none.
inline double distance_to_nondesign(const result::TriSurface& s, const Eigen::Vector3d& p) {
  double best = 1e300;
  for (long t = 0; t < s.F.rows(); ++t) {
    if (s.tag[t] >= 0) continue;
    const Eigen::Vector3d a = s.V.row(s.F(t, 0)), b = s.V.row(s.F(t, 1)), c = s.V.row(s.F(t, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.squaredNorm() == 0) continue;
    const bool inside =
        (b - a).cross(p - a).dot(n) >= 0 && (c - b).cross(p - b).dot(n) >= 0 && (a - c).cross(p - c).dot(n) >= 0;
    double d = inside ? std::abs((p - a).dot(n.normalized())) : 1e300;
    for (const auto& [u, w] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}}) {
      const double h = std::clamp((p - u).dot(w - u) / (w - u).squaredNorm(), 0.0, 1.0);
      d = std::min(d, (p - (u + h * (w - u))).norm());
    }
    best = std::min(best, d);
  }
  return best;
}

}  // namespace topopt::testing
