// Edit-by-edit self-intersection check for the remesher (see crossing_guard.h).
#include "result/crossing_guard.h"

#include <algorithm>
#include <cmath>

#include "mesh/surface/surface_check.h"

namespace topopt::result {

CrossingGuard::CrossingGuard(const MatX3d& V, const EditableSurface& m) : V_(V), m_(m) {
  double edges = 0;
  long n = 0;
  origin_ = V.rows() ? Eigen::RowVector3d(V.colwise().minCoeff()) : Eigen::RowVector3d::Zero();
  for (int t = 0; t < m.triangles(); ++t)
    if (m.alive(t)) edges += (V.row(m.tri(t)[0]) - V.row(m.tri(t)[1])).norm(), ++n;
  const double extent = V.rows() ? (V.colwise().maxCoeff() - V.colwise().minCoeff()).maxCoeff() : 1.0;
  cell_ = std::max(n ? 2 * edges / static_cast<double>(n) : 1.0, 1e-12 + extent / 1024);
  for (int t = 0; t < m.triangles(); ++t)
    if (m.alive(t)) add(t);
}

uint64_t CrossingGuard::key(long i, long j, long k) const {
  return (static_cast<uint64_t>(i) << 42) ^ (static_cast<uint64_t>(j) << 21) ^ static_cast<uint64_t>(k);
}

void CrossingGuard::cells_of(const Tri& t, long lo[3], long hi[3]) const {
  for (int d = 0; d < 3; ++d) {
    const double a = V_(t[0], d), b = V_(t[1], d), c = V_(t[2], d);
    lo[d] = static_cast<long>(std::floor((std::min({a, b, c}) - origin_[d]) / cell_));
    hi[d] = static_cast<long>(std::floor((std::max({a, b, c}) - origin_[d]) / cell_));
  }
}

void CrossingGuard::add(int t) {
  long lo[3], hi[3];
  cells_of(m_.tri(t), lo, hi);
  for (long i = lo[0]; i <= hi[0]; ++i)
    for (long j = lo[1]; j <= hi[1]; ++j)
      for (long k = lo[2]; k <= hi[2]; ++k) {
        std::vector<int>& c = cells_[key(i, j, k)];
        if (std::find(c.begin(), c.end(), t) == c.end()) c.push_back(t);
      }
}

namespace {

/// Whether the boxes of triangles p and q of V overlap (closed boxes: touching counts).
bool boxes_meet(const MatX3d& V, const EditableSurface::Tri& p, const EditableSurface::Tri& q) {
  for (int d = 0; d < 3; ++d) {
    const double p0 = std::min({V(p[0], d), V(p[1], d), V(p[2], d)}), p1 = std::max({V(p[0], d), V(p[1], d), V(p[2], d)});
    const double q0 = std::min({V(q[0], d), V(q[1], d), V(q[2], d)}), q1 = std::max({V(q[0], d), V(q[1], d), V(q[2], d)});
    if (p1 < q0 || q1 < p0) return false;
  }
  return true;
}

bool cross(const MatX3d& V, const EditableSurface::Tri& p, const EditableSurface::Tri& q) {
  const double* x[3] = {V.row(p[0]).data(), V.row(p[1]).data(), V.row(p[2]).data()};
  const double* y[3] = {V.row(q[0]).data(), V.row(q[1]).data(), V.row(q[2]).data()};
  return mesh::triangles_cross(x, p.data(), y, q.data());
}

}  // namespace

bool CrossingGuard::crosses(const std::vector<Tri>& tris, const std::vector<int>& replaced) const {
  for (size_t i = 0; i < tris.size(); ++i)
    for (size_t j = i + 1; j < tris.size(); ++j)
      if (boxes_meet(V_, tris[i], tris[j]) && cross(V_, tris[i], tris[j])) return true;
  if (seen_.size() < static_cast<size_t>(m_.triangles())) seen_.resize(m_.triangles(), -1);
  for (const Tri& p : tris) {
    const double* x[3] = {V_.row(p[0]).data(), V_.row(p[1]).data(), V_.row(p[2]).data()};
    if (mesh::triangle_degenerate(x)) return true;
    ++query_;
    for (int t : replaced)
      if (t < static_cast<int>(seen_.size())) seen_[t] = query_;
    long lo[3], hi[3];
    cells_of(p, lo, hi);
    for (long i = lo[0]; i <= hi[0]; ++i)
      for (long j = lo[1]; j <= hi[1]; ++j)
        for (long k = lo[2]; k <= hi[2]; ++k) {
          const auto it = cells_.find(key(i, j, k));
          if (it == cells_.end()) continue;
          for (int t : it->second) {
            if (t >= static_cast<int>(seen_.size()) || seen_[t] == query_ || !m_.alive(t)) continue;
            seen_[t] = query_;
            if (boxes_meet(V_, p, m_.tri(t)) && cross(V_, p, m_.tri(t))) return true;
          }
        }
  }
  return false;
}

}  // namespace topopt::result
