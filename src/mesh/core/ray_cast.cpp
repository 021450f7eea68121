// Rays against a triangle soup (see ray_cast.h).
#include "mesh/core/ray_cast.h"

#include <algorithm>
#include <cmath>

namespace topopt::mesh {

TriangleRays::TriangleRays(const MatX3d& V, const MatX3i& F) : V_(V), F_(F) {
  items_.resize(F.rows());
  for (long t = 0; t < F.rows(); ++t) items_[t] = static_cast<int>(t);
  nodes_.reserve(2 * F.rows() / 2 + 1);
  if (F.rows()) build(0, static_cast<int>(F.rows()), 0);
}

int TriangleRays::build(int first, int count, int depth) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Node nd;
  for (int k = 0; k < 3; ++k) nd.lo[k] = 1e300, nd.hi[k] = -1e300;
  double clo[3] = {1e300, 1e300, 1e300}, chi[3] = {-1e300, -1e300, -1e300};
  for (int i = first; i < first + count; ++i)
    for (int k = 0; k < 3; ++k) {
      double c = 0;
      for (int j = 0; j < 3; ++j) {
        const double x = V_(F_(items_[i], j), k);
        nd.lo[k] = std::min(nd.lo[k], x), nd.hi[k] = std::max(nd.hi[k], x);
        c += x / 3;
      }
      clo[k] = std::min(clo[k], c), chi[k] = std::max(chi[k], c);
    }
  if (count <= 4 || depth > 60) {
    nd.first = first, nd.count = count;
    nodes_[id] = nd;
    return id;
  }
  // split at the median centroid along the widest extent of the centroids
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (chi[k] - clo[k] > chi[axis] - clo[axis]) axis = k;
  auto centroid = [&](int t) { return V_(F_(t, 0), axis) + V_(F_(t, 1), axis) + V_(F_(t, 2), axis); };
  const int half = count / 2;
  std::nth_element(items_.begin() + first, items_.begin() + first + half, items_.begin() + first + count,
                   [&](int a, int b) { return centroid(a) < centroid(b); });
  nd.left = build(first, half, depth + 1);
  nd.right = build(first + half, count - half, depth + 1);
  nodes_[id] = nd;
  return id;
}

double TriangleRays::first_hit(const double* o, const double* d, long skip, double tmax) const {
  if (nodes_.empty()) return tmax;
  const double inv[3] = {1 / d[0], 1 / d[1], 1 / d[2]};  // ±inf where d is 0: the slab test copes
  double best = tmax;
  // entry distance of the ray into node n's box within [0, best], or -1 if it misses
  auto enter = [&](int n) {
    const Node& nd = nodes_[n];
    double t0 = 0, t1 = best;
    for (int k = 0; k < 3; ++k) {
      double a = (nd.lo[k] - o[k]) * inv[k], b = (nd.hi[k] - o[k]) * inv[k];
      if (std::isnan(a) || std::isnan(b)) {  // the ray lies in the slab's plane
        if (o[k] < nd.lo[k] || o[k] > nd.hi[k]) return -1.0;
        continue;
      }
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a), t1 = std::min(t1, b);
      if (t0 > t1) return -1.0;
    }
    return t0;
  };
  std::pair<double, int> stack[128];  // (entry distance, node), nearer children on top
  int top = 0;
  if (enter(0) >= 0) stack[top++] = {0.0, 0};
  while (top) {
    const auto [entry, id] = stack[--top];
    if (entry > best) continue;
    const Node& nd = nodes_[id];
    if (nd.left >= 0) {
      const double tl = enter(nd.left), tr = enter(nd.right);
      if (top + 2 > 128) continue;  // deeper than any tree built here
      if (tl >= 0 && tr >= 0) {
        if (tl <= tr)
          stack[top++] = {tr, nd.right}, stack[top++] = {tl, nd.left};
        else
          stack[top++] = {tl, nd.left}, stack[top++] = {tr, nd.right};
      } else if (tl >= 0) {
        stack[top++] = {tl, nd.left};
      } else if (tr >= 0) {
        stack[top++] = {tr, nd.right};
      }
      continue;
    }
    for (int i = nd.first; i < nd.first + nd.count; ++i) {
      const int t = items_[i];
      if (t == skip) continue;
      // Möller–Trumbore
      const double* p0 = &V_(F_(t, 0), 0);
      double e1[3], e2[3], s[3], pv[3], qv[3];
      for (int k = 0; k < 3; ++k) e1[k] = V_(F_(t, 1), k) - p0[k], e2[k] = V_(F_(t, 2), k) - p0[k], s[k] = o[k] - p0[k];
      pv[0] = d[1] * e2[2] - d[2] * e2[1], pv[1] = d[2] * e2[0] - d[0] * e2[2], pv[2] = d[0] * e2[1] - d[1] * e2[0];
      const double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
      if (std::abs(det) < 1e-300) continue;
      const double u = (s[0] * pv[0] + s[1] * pv[1] + s[2] * pv[2]) / det;
      if (u < 0 || u > 1) continue;
      qv[0] = s[1] * e1[2] - s[2] * e1[1], qv[1] = s[2] * e1[0] - s[0] * e1[2], qv[2] = s[0] * e1[1] - s[1] * e1[0];
      const double v = (d[0] * qv[0] + d[1] * qv[1] + d[2] * qv[2]) / det;
      if (v < 0 || u + v > 1) continue;
      const double dist = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) / det;
      if (dist > 0 && dist < best) best = dist;
    }
  }
  return best;
}

}  // namespace topopt::mesh
