// The overhang property of a surface (see overhang_measure.h).
#include "simp/controls/overhang_measure.h"

#include <algorithm>
#include <cmath>

namespace topopt::simp {

OverhangShare overhang_share(const MatX3d& V, const MatX3i& F, const Eigen::Vector3d& d,
                             const OverhangMeasureParams& params, const VecXi* tag, const VecXi* lock) {
  const Eigen::Vector3d up = d.normalized();
  const double limit = std::max(0.0, params.angle - params.tolerance);
  const double cos_limit = std::cos(limit * 3.14159265358979323846 / 180);
  const double plate = params.plate, eps = params.plate_tolerance;
  OverhangShare out;
  for (long f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = V.row(F(f, 0)), b = V.row(F(f, 1)), c = V.row(F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    const double area = n.norm() / 2;
    if (!(area > 0) || n.dot(up) >= 0) continue;
    const double lowest = std::min({a.dot(up), b.dot(up), c.dot(up)}),
                 highest = std::max({a.dot(up), b.dot(up), c.dot(up)});
    if (lowest >= plate - eps && highest <= plate + eps) continue;  // on the plate
    const int kind = tag ? (*tag)[f] : 0;
    const bool given = kind > 0 && lock && (*lock)[F(f, 0)] == 2 && (*lock)[F(f, 1)] == 2 && (*lock)[F(f, 2)] == 2;
    const bool flat = -n.dot(up) > cos_limit * 2 * area;  // angle(n, -d) < limit
    if (given) {  // a non-design solid's face on Ω's boundary: the user's shape
      out.given_downward_area += area;
      if (flat) out.given_overhang_area += area;
      continue;
    }
    out.downward_area += area;
    if (!flat) continue;
    out.overhang_area += area;
    (kind == 0 ? out.design_overhang : kind < 0 ? out.nondesign_overhang : out.omega_overhang) += area;
  }
  return out;
}

}  // namespace topopt::simp
