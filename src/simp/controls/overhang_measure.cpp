// The overhang property of a surface (see overhang_measure.h).
#include "simp/controls/overhang_measure.h"

#include <algorithm>
#include <cmath>

namespace topopt::simp {

OverhangShare overhang_share(const MatX3d& V, const MatX3i& F, const Eigen::Vector3d& d, double angle, double plate,
                             double plate_tolerance) {
  const Eigen::Vector3d up = d.normalized();
  const double cos_limit = std::cos(angle * 3.14159265358979323846 / 180);
  OverhangShare out;
  for (long f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double area = n.norm() / 2;
    if (!(area > 0) || n.dot(up) >= 0) continue;
    const double lowest = std::min({a.dot(up), b.dot(up), c.dot(up)}),
                 highest = std::max({a.dot(up), b.dot(up), c.dot(up)});
    if (lowest >= plate - plate_tolerance && highest <= plate + plate_tolerance) continue;  // on the plate
    out.downward_area += area;
    if (-n.dot(up) > cos_limit * 2 * area) out.overhang_area += area;  // angle(n, -d) < angle
  }
  return out;
}

}  // namespace topopt::simp
