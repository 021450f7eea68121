// Self-intersection and angle figures of triangle meshes (see surface_check.h).
#include "mesh/surface/surface_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "mesh/core/predicates.h"

namespace topopt::mesh {
namespace {

using predicates::orient2d;
using predicates::orient3d;

/// Closed 2D point-in-triangle.
bool inside_2d(const double* x, const double* a, const double* b, const double* c) {
  const int o1 = orient2d(a, b, x), o2 = orient2d(b, c, x), o3 = orient2d(c, a, x);
  return (o1 >= 0 && o2 >= 0 && o3 >= 0) || (o1 <= 0 && o2 <= 0 && o3 <= 0);
}

/// Drops the coordinate along which the (non-degenerate) triangle abc is largest in normal.
int drop_axis(const double* a, const double* b, const double* c) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double n[3] = {std::abs(u[1] * v[2] - u[2] * v[1]), std::abs(u[2] * v[0] - u[0] * v[2]),
                       std::abs(u[0] * v[1] - u[1] * v[0])};
  return n[0] >= n[1] && n[0] >= n[2] ? 0 : (n[1] >= n[2] ? 1 : 2);
}

void project(const double* x, int drop, double* out) {
  int k = 0;
  for (int i = 0; i < 3; ++i)
    if (i != drop) out[k++] = x[i];
}

/// Closed segment pq meets closed triangle abc (exact; coplanar handled in a projection that
/// keeps the triangle non-degenerate, which preserves incidence of coplanar points).
bool segment_meets_triangle(const double* p, const double* q, const double* a, const double* b, const double* c) {
  const int op = orient3d(a, b, c, p), oq = orient3d(a, b, c, q);
  if (op * oq > 0) return false;
  if (op != 0 || oq != 0) {
    const int s1 = orient3d(p, q, a, b), s2 = orient3d(p, q, b, c), s3 = orient3d(p, q, c, a);
    return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
  }
  const int drop = drop_axis(a, b, c);
  double P[2], Q[2], A[2], B[2], C[2];
  project(p, drop, P), project(q, drop, Q), project(a, drop, A), project(b, drop, B), project(c, drop, C);
  return inside_2d(P, A, B, C) || inside_2d(Q, A, B, C) || predicates::segments_meet(P, Q, A, B) ||
         predicates::segments_meet(P, Q, B, C) || predicates::segments_meet(P, Q, C, A);
}

bool degenerate(const double* a, const double* b, const double* c) {
  // zero area iff every coordinate projection is collinear
  double A[2], B[2], C[2];
  for (int drop = 0; drop < 3; ++drop) {
    project(a, drop, A), project(b, drop, B), project(c, drop, C);
    if (orient2d(A, B, C) != 0) return false;
  }
  return true;
}

/// Whether the non-degenerate triangles with points x and y (ids xi, yi: equal ids are one point)
/// intersect improperly; see the header.
bool improper(const double* const x[3], const int xi[3], const double* const y[3], const int yi[3]) {
  int shared = 0, si[3], ti[3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (xi[i] == yi[j]) si[shared] = i, ti[shared] = j, ++shared;
  if (shared == 3) return true;  // the same triangle twice
  if (shared == 0) {
    for (int i = 0; i < 3; ++i)
      if (segment_meets_triangle(x[i], x[(i + 1) % 3], y[0], y[1], y[2]) ||
          segment_meets_triangle(y[i], y[(i + 1) % 3], x[0], x[1], x[2]))
        return true;
    return false;
  }
  if (shared == 1) {  // improper iff an edge opposite the common node meets the other triangle
    const int i = si[0], j = ti[0];
    return segment_meets_triangle(x[(i + 1) % 3], x[(i + 2) % 3], y[0], y[1], y[2]) ||
           segment_meets_triangle(y[(j + 1) % 3], y[(j + 2) % 3], x[0], x[1], x[2]);
  }
  // a common edge: improper iff the far nodes are coplanar with it and on the same side
  const int a = 3 - si[0] - si[1], b = 3 - ti[0] - ti[1];
  const double *v = x[si[0]], *w = x[si[1]];
  if (orient3d(v, w, x[a], y[b]) != 0) return false;
  const int drop = drop_axis(v, w, x[a]);
  double P[2], Q[2], A[2], B[2];
  project(v, drop, P), project(w, drop, Q), project(x[a], drop, A), project(y[b], drop, B);
  return orient2d(P, Q, A) == orient2d(P, Q, B);
}

/// Whether triangles s and t of (V, F) (non-degenerate) intersect improperly.
bool improper(const MatX3d& V, const MatX3i& F, int s, int t) {
  const double* x[3] = {V.row(F(s, 0)).data(), V.row(F(s, 1)).data(), V.row(F(s, 2)).data()};
  const double* y[3] = {V.row(F(t, 0)).data(), V.row(F(t, 1)).data(), V.row(F(t, 2)).data()};
  const int xi[3] = {F(s, 0), F(s, 1), F(s, 2)}, yi[3] = {F(t, 0), F(t, 1), F(t, 2)};
  return improper(x, xi, y, yi);
}

}  // namespace

bool triangle_degenerate(const double* const x[3]) { return degenerate(x[0], x[1], x[2]); }

bool triangles_cross(const double* const x[3], const int xi[3], const double* const y[3], const int yi[3]) {
  return degenerate(x[0], x[1], x[2]) || degenerate(y[0], y[1], y[2]) || improper(x, xi, y, yi);
}

std::vector<std::pair<int, int>> self_intersections(const MatX3d& V, const MatX3i& F, long max_pairs) {
  std::vector<std::pair<int, int>> out;
  const long nf = F.rows();
  if (nf == 0) return out;
  // uniform grid with about one triangle per cell; each triangle in every cell its box overlaps
  Eigen::RowVector3d lo = V.colwise().minCoeff(), hi = V.colwise().maxCoeff();
  double mean_edge = 0;
  for (long t = 0; t < nf; ++t) mean_edge += (V.row(F(t, 0)) - V.row(F(t, 1))).norm();
  mean_edge /= static_cast<double>(nf);
  const double cell = std::max(2 * mean_edge, 1e-12 + (hi - lo).maxCoeff() / 1024);
  auto key = [](long i, long j, long k) {
    return (static_cast<uint64_t>(i) << 42) ^ (static_cast<uint64_t>(j) << 21) ^ static_cast<uint64_t>(k);
  };
  std::unordered_map<uint64_t, std::vector<int>> cells;
  std::vector<std::array<long, 6>> range(nf);
  for (long t = 0; t < nf; ++t) {
    const double *a = V.row(F(t, 0)).data(), *b = V.row(F(t, 1)).data(), *c = V.row(F(t, 2)).data();
    if (degenerate(a, b, c)) {
      out.emplace_back(static_cast<int>(t), static_cast<int>(t));
      if (static_cast<long>(out.size()) >= max_pairs) return out;
      range[t][0] = 1, range[t][3] = 0;  // empty: skipped below
      continue;
    }
    for (int d = 0; d < 3; ++d) {
      range[t][d] = static_cast<long>(std::floor((std::min({a[d], b[d], c[d]}) - lo[d]) / cell));
      range[t][d + 3] = static_cast<long>(std::floor((std::max({a[d], b[d], c[d]}) - lo[d]) / cell));
    }
    for (long i = range[t][0]; i <= range[t][3]; ++i)
      for (long j = range[t][1]; j <= range[t][4]; ++j)
        for (long k = range[t][2]; k <= range[t][5]; ++k) cells[key(i, j, k)].push_back(static_cast<int>(t));
  }
  std::vector<int> seen(nf, -1);
  for (long s = 0; s < nf; ++s) {
    for (long i = range[s][0]; i <= range[s][3]; ++i)
      for (long j = range[s][1]; j <= range[s][4]; ++j)
        for (long k = range[s][2]; k <= range[s][5]; ++k) {
          auto it = cells.find(key(i, j, k));
          if (it == cells.end()) continue;
          for (int t : it->second) {
            if (t <= s || seen[t] == s) continue;
            seen[t] = static_cast<int>(s);
            bool overlap = true;  // boxes first
            for (int d = 0; d < 3 && overlap; ++d) {
              const double s0 = std::min({V(F(s, 0), d), V(F(s, 1), d), V(F(s, 2), d)});
              const double s1 = std::max({V(F(s, 0), d), V(F(s, 1), d), V(F(s, 2), d)});
              const double t0 = std::min({V(F(t, 0), d), V(F(t, 1), d), V(F(t, 2), d)});
              const double t1 = std::max({V(F(t, 0), d), V(F(t, 1), d), V(F(t, 2), d)});
              overlap = s0 <= t1 && t0 <= s1;
            }
            if (overlap && improper(V, F, static_cast<int>(s), t)) {
              out.emplace_back(static_cast<int>(s), t);
              if (static_cast<long>(out.size()) >= max_pairs) return out;
            }
          }
        }
  }
  return out;
}

SurfaceQuality surface_quality(const MatX3d& V, const MatX3i& F) {
  SurfaceQuality q;
  q.triangles = F.rows();
  if (F.rows() == 0) return q;
  q.min_angle = 180;
  long below = 0;
  for (long t = 0; t < F.rows(); ++t) {
    Eigen::Vector3d p[3] = {V.row(F(t, 0)), V.row(F(t, 1)), V.row(F(t, 2))};
    double smallest = 180, l2 = 0;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
      smallest = std::min(smallest, std::atan2(u.cross(v).norm(), u.dot(v)) * 180 / M_PI);
      l2 += u.squaredNorm();
    }
    const double area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    q.mean_quality += l2 > 0 ? 4 * std::sqrt(3.0) * area / l2 : 0;
    q.min_angle = std::min(q.min_angle, smallest);
    q.mean_min_angle += smallest;
    below += smallest < 20;
  }
  q.mean_min_angle /= static_cast<double>(F.rows());
  q.mean_quality /= static_cast<double>(F.rows());
  q.share_below_20 = static_cast<double>(below) / static_cast<double>(F.rows());
  return q;
}

}  // namespace topopt::mesh
