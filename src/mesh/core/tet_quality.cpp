// Tet quality measures (see tet_quality.h).
#include "mesh/core/tet_quality.h"

#include <algorithm>
#include <cmath>

namespace topopt::mesh {

double radius_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    const Eigen::Vector3d& d) {
  Eigen::Vector3d u = b - a, v = c - a, w = d - a;
  double six_vol = std::abs(u.dot(v.cross(w)));
  if (six_vol == 0) return 0;
  double area = 0.5 * (v.cross(w).norm() + u.cross(w).norm() + u.cross(v).norm() + (c - b).cross(d - b).norm());
  double r_in = 0.5 * six_vol / area;  // 3V / A
  // circumradius: |u|² (v×w) + |v|² (w×u) + |w|² (u×v) over 2·6V
  Eigen::Vector3d num = u.squaredNorm() * v.cross(w) + v.squaredNorm() * w.cross(u) + w.squaredNorm() * u.cross(v);
  double R = num.norm() / (2 * six_vol);
  return 3 * r_in / R;
}

std::pair<double, double> dihedral_range(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                         const Eigen::Vector3d& d) {
  const Eigen::Vector3d p[4] = {a, b, c, d};
  double lo = 180, hi = 0;
  // the dihedral angle at edge (i, j) is between the faces that contain it
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      int k = 0;
      while (k == i || k == j) ++k;
      int l = 6 - i - j - k;
      Eigen::Vector3d e = (p[j] - p[i]).normalized();
      Eigen::Vector3d x = p[k] - p[i], y = p[l] - p[i];
      x -= x.dot(e) * e, y -= y.dot(e) * e;
      double nx = x.norm(), ny = y.norm();
      double ang = (nx == 0 || ny == 0) ? 0 : std::acos(std::clamp(x.dot(y) / (nx * ny), -1.0, 1.0)) * 180 / M_PI;
      lo = std::min(lo, ang), hi = std::max(hi, ang);
    }
  return {lo, hi};
}

QualityReport tet_quality(const TetMesh& m) {
  QualityReport q;
  q.tets = m.T.rows();
  if (!q.tets) return q;
  q.min_radius_ratio = 1, q.min_dihedral = 180;
  long low_rho = 0, low_dih = 0;
  double sum = 0;
  for (long t = 0; t < q.tets; ++t) {
    Eigen::Vector3d a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)), d = m.V.row(m.T(t, 3));
    double r = radius_ratio(a, b, c, d);
    auto [lo, hi] = dihedral_range(a, b, c, d);
    sum += r;
    q.min_radius_ratio = std::min(q.min_radius_ratio, r);
    q.min_dihedral = std::min(q.min_dihedral, lo);
    q.max_dihedral = std::max(q.max_dihedral, hi);
    low_rho += r < 0.1;
    low_dih += lo < 10;
  }
  q.mean_radius_ratio = sum / q.tets;
  q.share_radius_ratio_below_01 = static_cast<double>(low_rho) / q.tets;
  q.share_dihedral_below_10 = static_cast<double>(low_dih) / q.tets;
  return q;
}

nlohmann::json QualityReport::to_json() const {
  return {
      {"tets", tets},
      {"radius_ratio",
       {{"min", min_radius_ratio}, {"mean", mean_radius_ratio}, {"share_below_0.1", share_radius_ratio_below_01}}},
      {"dihedral_deg", {{"min", min_dihedral}, {"max", max_dihedral}, {"share_below_10", share_dihedral_below_10}}}};
}

}  // namespace topopt::mesh
