// Member sizes of a crisp design by a distance transform on the tet mesh (see member_measure.h).
#include "simp/controls/member_measure.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <unordered_set>

#include "common/face_key.h"
#include "common/tet_boundary.h"
#include "common/triangle_closest.h"

namespace topopt::simp {
namespace {

/// The rows of F whose node triple is (`keep` true) or is not (false) in `set`.
MatX3i rows_in(const MatX3i& F, const std::unordered_set<FaceKey, FaceKeyHash>& set, bool keep) {
  std::vector<long> rows;
  for (long f = 0; f < F.rows(); ++f)
    if (static_cast<bool>(set.count(face_key(F(f, 0), F(f, 1), F(f, 2)))) == keep) rows.push_back(f);
  MatX3i out(static_cast<long>(rows.size()), 3);
  for (size_t k = 0; k < rows.size(); ++k) out.row(static_cast<long>(k)) = F.row(rows[k]);
  return out;
}

/// The boundary triangles of the tets `phase` (#B by 3): with the part's own boundary
/// (`part_boundary`, the triangles of `part`) or without it.
MatX3i phase_boundary(const TetMesh& mesh, const std::vector<int>& phase, const MatX3i& part, bool part_boundary) {
  MatX4i T(static_cast<long>(phase.size()), 4);
  for (size_t k = 0; k < phase.size(); ++k) T.row(static_cast<long>(k)) = mesh.T.row(phase[k]);
  const MatX3i all = boundary_triangles(T);
  if (part_boundary) return all;
  std::unordered_set<FaceKey, FaceKeyHash> outer;
  for (long f = 0; f < part.rows(); ++f) outer.insert(face_key(part(f, 0), part(f, 1), part(f, 2)));
  return rows_in(all, outer, false);
}

/// The triangles of F (V's rows) as bounding spheres: centres and radii.
struct Spheres {
  MatX3d centre;
  VecXd radius;
  Spheres(const MatX3d& V, const MatX3i& F) : centre(F.rows(), 3), radius(F.rows()) {
    for (long f = 0; f < F.rows(); ++f) {
      centre.row(f) = (V.row(F(f, 0)) + V.row(F(f, 1)) + V.row(F(f, 2))) / 3;
      radius[f] = 0;
      for (int a = 0; a < 3; ++a) radius[f] = std::max(radius[f], (V.row(F(f, a)) - centre.row(f)).norm());
    }
  }
};

/// Distance from each point (rows of P) to the nearest triangle of F; `none` where F is empty.
/// Q (optional): #P by 3, that nearest point (P's own row where F is empty). Triangles are
/// skipped when the distance to their centre less their reach cannot beat the best.
VecXd distance_to_triangles(const MatX3d& V, const MatX3i& F, const MatX3d& P, double none, MatX3d* Q = nullptr) {
  const Spheres sphere(V, F);
  VecXd d = VecXd::Constant(P.rows(), none);
  if (Q) *Q = P;
  for (long i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose();
    for (long f = 0; f < F.rows(); ++f) {
      if ((P.row(i) - sphere.centre.row(f)).norm() - sphere.radius[f] >= d[i]) continue;
      const Eigen::Vector3d q =
          closest_on_triangle(p, V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(), V.row(F(f, 2)).transpose());
      if ((q - p).norm() >= d[i]) continue;
      d[i] = (q - p).norm();
      if (Q) Q->row(i) = q.transpose();
    }
  }
  return d;
}

/// Per point p (rows of P) with its direction u (rows of U, unit or zero) the distance along the
/// ray p + s u to the first triangle of F, at most limit[i] (also where u is zero or the ray
/// misses). Triangles whose bounding sphere lies beyond the limit or off the ray are skipped.
VecXd ray_to_triangles(const MatX3d& V, const MatX3i& F, const MatX3d& P, const MatX3d& U, const VecXd& limit) {
  const Spheres sphere(V, F);
  VecXd s = limit;
  for (long i = 0; i < P.rows(); ++i) {
    const Eigen::Vector3d p = P.row(i).transpose(), u = U.row(i).transpose();
    if (u.squaredNorm() == 0) continue;
    for (long f = 0; f < F.rows(); ++f) {
      const Eigen::Vector3d to = sphere.centre.row(f).transpose() - p;
      if (to.norm() - sphere.radius[f] >= s[i] || (to - to.dot(u) * u).norm() > sphere.radius[f]) continue;
      s[i] = std::min(s[i], ray_triangle_hit(p, u, V.row(F(f, 0)).transpose(), V.row(F(f, 1)).transpose(),
                                             V.row(F(f, 2)).transpose()));
    }
  }
  return s;
}

/// The local thickness of each point: max w_f over the balls (centre C_f, radius r_f, width w_f)
/// that hold it within `reach`. Points sorted by x, so each ball visits the points within its x
/// range only.
VecXd local_thickness(const MatX3d& C, const VecXd& r, const VecXd& w, double reach) {
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
      if ((C.row(e) - C.row(f)).norm() <= r[f] + reach) t[e] = std::max(t[e], w[f]);
    }
  }
  return t;
}

}  // namespace

MemberMeasure measure_members(const TetMesh& mesh, const VecXd& density, const MemberMeasureParams& params) {
  const long nt = mesh.T.rows();
  auto design = [&](long t) { return mesh.domain.size() != nt || mesh.domain[t] == 0; };
  std::vector<int> phase;
  for (long t = 0; t < nt; ++t)
    if (params.gaps ? design(t) && density[t] < params.threshold : density[t] >= params.threshold)
      phase.push_back(static_cast<int>(t));
  const long ns = static_cast<long>(phase.size());
  MatX3d C(ns, 3);
  for (long k = 0; k < ns; ++k) {
    C.row(k).setZero();
    for (int a = 0; a < 4; ++a) C.row(k) += mesh.V.row(mesh.T(phase[k], a)) / 4;
  }
  const double diagonal = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  const MatX3i part = boundary_triangles(mesh.T);
  const bool wall = params.part_faces == PartFaces::Wall;
  MatX3d Q;  // each centroid's nearest point of its phase's boundary
  const VecXd r = distance_to_triangles(mesh.V, phase_boundary(mesh, phase, part, wall), C, diagonal, &Q);
  VecXd width = 2 * r;
  if (!wall) {  // clipped: the ball's width inside the part along the way from that point through its centre
    MatX3d U = C - Q;
    for (long k = 0; k < ns; ++k)
      if (r[k] > 0 && r[k] < diagonal)
        U.row(k) /= r[k];
      else
        U.row(k).setZero();
    width = r + ray_to_triangles(mesh.V, part, C, U, r);
  }
  const VecXd thick = local_thickness(C, r, width, params.reach);
  MemberMeasure m;
  m.inscribed = VecXd::Zero(nt);
  m.thickness = VecXd::Zero(nt);
  m.smallest_member = ns ? 2 * diagonal : 0;
  for (long k = 0; k < ns; ++k) {
    const int t = phase[k];
    m.inscribed[t] = r[k], m.thickness[t] = thick[k];
    if (!design(t)) continue;
    ++m.solid_design;
    m.smallest_member = std::min(m.smallest_member, thick[k]);
    m.largest_ball = std::max(m.largest_ball, 2 * r[k]);
  }
  if (m.solid_design == 0) m.smallest_member = 0;
  return m;
}

}  // namespace topopt::simp
