// Member sizes of a crisp design by a distance transform on the tet mesh (see member_measure.h).
#include "simp/controls/member_measure.h"

#include <algorithm>
#include <numeric>
#include <unordered_set>

#include "common/face_key.h"
#include "common/tet_boundary.h"

namespace topopt::simp {
namespace {

/// Distance from p to the segment [a, b].
double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double s = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + s * ab)).norm();
}

/// Distance from p to the triangle (a, b, c): to its plane where p projects inside it, else to
/// the nearest of its edges.
double triangle_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c) {
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double n2 = n.squaredNorm();
  if (n2 > 0) {
    const Eigen::Vector3d q = p - n * ((p - a).dot(n) / n2);  // p's projection on the plane
    const double u = (b - q).cross(c - q).dot(n), v = (c - q).cross(a - q).dot(n), w = (a - q).cross(b - q).dot(n);
    if (u >= 0 && v >= 0 && w >= 0) return (p - q).norm();
  }
  return std::min({segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
}

/// The boundary triangles of the solid tets (#B by 3), without the part's own boundary unless
/// `part_boundary`.
MatX3i solid_boundary(const TetMesh& mesh, const std::vector<int>& solid, bool part_boundary) {
  MatX4i T(static_cast<long>(solid.size()), 4);
  for (size_t k = 0; k < solid.size(); ++k) T.row(static_cast<long>(k)) = mesh.T.row(solid[k]);
  const MatX3i all = boundary_triangles(T);
  if (part_boundary) return all;
  std::unordered_set<FaceKey, FaceKeyHash> outer;
  const MatX3i part = boundary_triangles(mesh.T);
  for (long f = 0; f < part.rows(); ++f) outer.insert(face_key(part(f, 0), part(f, 1), part(f, 2)));
  std::vector<long> keep;
  for (long f = 0; f < all.rows(); ++f)
    if (!outer.count(face_key(all(f, 0), all(f, 1), all(f, 2)))) keep.push_back(f);
  MatX3i out(static_cast<long>(keep.size()), 3);
  for (size_t k = 0; k < keep.size(); ++k) out.row(static_cast<long>(k)) = all.row(keep[k]);
  return out;
}

/// Distance from each point (rows of P) to the nearest triangle of F; `none` where F is empty.
/// Triangles are skipped when the distance to their centre less their reach cannot beat the best.
VecXd distance_to_triangles(const MatX3d& V, const MatX3i& F, const MatX3d& P, double none) {
  const long nf = F.rows();
  MatX3d centre(nf, 3);
  VecXd reach(nf);
  for (long f = 0; f < nf; ++f) {
    centre.row(f) = (V.row(F(f, 0)) + V.row(F(f, 1)) + V.row(F(f, 2))) / 3;
    reach[f] = 0;
    for (int a = 0; a < 3; ++a) reach[f] = std::max(reach[f], (V.row(F(f, a)) - centre.row(f)).norm());
  }
  VecXd d = VecXd::Constant(P.rows(), none);
  for (long i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    for (long f = 0; f < nf; ++f) {
      if ((P.row(i) - centre.row(f)).norm() - reach[f] >= d[i]) continue;
      d[i] = std::min(d[i], triangle_distance(p, V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(),
                                              V.row(F(f, 2)).transpose()));
    }
  }
  return d;
}

/// The local thickness of each point: 2 max r_f over the balls (centre C_f, radius r_f) that
/// hold it within `reach`. Points sorted by x, so each ball visits the points within its x range only.
VecXd local_thickness(const MatX3d& C, const VecXd& r, double reach) {
  const long n = C.rows();
  std::vector<long> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), 0L);
  std::sort(order.begin(), order.end(), [&](long a, long b) { return C(a, 0) < C(b, 0); });
  std::vector<double> xs(static_cast<size_t>(n));
  for (long k = 0; k < n; ++k) xs[k] = C(order[k], 0);
  VecXd t = VecXd::Zero(n);
  for (long f = 0; f < n; ++f) {
    auto k = std::lower_bound(xs.begin(), xs.end(), C(f, 0) - r[f] - reach) - xs.begin();
    for (; k < n && xs[k] <= C(f, 0) + r[f] + reach; ++k) {
      const long e = order[k];
      if ((C.row(e) - C.row(f)).norm() <= r[f] + reach) t[e] = std::max(t[e], 2 * r[f]);
    }
  }
  return t;
}

}  // namespace

MemberMeasure measure_members(const TetMesh& mesh, const VecXd& density, const MemberMeasureParams& params) {
  const long nt = mesh.T.rows();
  std::vector<int> solid;
  for (long t = 0; t < nt; ++t)
    if (density[t] >= params.threshold) solid.push_back(static_cast<int>(t));
  const long ns = static_cast<long>(solid.size());
  MatX3d C(ns, 3);
  for (long k = 0; k < ns; ++k) {
    C.row(k).setZero();
    for (int a = 0; a < 4; ++a) C.row(k) += mesh.V.row(mesh.T(solid[k], a)) / 4;
  }
  const double diagonal = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  const VecXd r = distance_to_triangles(mesh.V, solid_boundary(mesh, solid, params.part_boundary), C, diagonal);
  const VecXd thick = local_thickness(C, r, params.reach);
  MemberMeasure m;
  m.inscribed = VecXd::Zero(nt);
  m.thickness = VecXd::Zero(nt);
  m.smallest_member = ns ? diagonal : 0;
  for (long k = 0; k < ns; ++k) {
    const int t = solid[k];
    m.inscribed[t] = r[k], m.thickness[t] = thick[k];
    if (mesh.domain.size() == nt && mesh.domain[t] != 0) continue;
    ++m.solid_design;
    m.smallest_member = std::min(m.smallest_member, thick[k]);
    m.largest_ball = std::max(m.largest_ball, 2 * r[k]);
  }
  if (m.solid_design == 0) m.smallest_member = 0;
  return m;
}

}  // namespace topopt::simp
