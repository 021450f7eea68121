// Graded background size and the tet count a size asks for (see background_size.h).
#include "mesh/volume/background_size.h"

#include <algorithm>
#include <cmath>

namespace topopt::mesh {

namespace {

/// The mean length of the triangles' edges at each of `nodes` nodes (0 where a node has none):
/// corner(t, k) is node k of triangle t, x(i) node i's position (an Eigen vector expression).
template <class Corner, class Point>
std::vector<double> mean_edge_at_nodes(long nodes, long triangles, Corner&& corner, Point&& x) {
  std::vector<double> sum(nodes, 0.0);
  std::vector<int> cnt(nodes, 0);
  for (long t = 0; t < triangles; ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = corner(t, k), b = corner(t, (k + 1) % 3);
      const double l = (x(a) - x(b)).norm();
      sum[a] += l, ++cnt[a], sum[b] += l, ++cnt[b];
    }
  for (long i = 0; i < nodes; ++i) sum[i] = cnt[i] ? sum[i] / cnt[i] : 0.0;
  return sum;
}

}  // namespace

std::vector<double> node_spacing(const MatX3d& V, const MatX3i& F) {
  return mean_edge_at_nodes(
      V.rows(), F.rows(), [&](long t, int k) { return F(t, k); }, [&](int i) { return V.row(i); });
}

std::vector<double> node_spacing(const std::vector<Eigen::Vector3d>& P, const std::vector<std::array<int, 3>>& F) {
  return mean_edge_at_nodes(
      static_cast<long>(P.size()), static_cast<long>(F.size()), [&](long t, int k) { return F[t][k]; },
      [&](int i) -> const Eigen::Vector3d& { return P[i]; });
}

BackgroundSize::BackgroundSize(const MatX3d& V, const MatX3i& F, double h, double g,
                               const std::vector<std::array<double, 4>>& seeds) {
  lo_ = V.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = V.colwise().maxCoeff().transpose();
  cell_ = h / 2;
  auto dims = [&]() {
    for (int d = 0; d < 3; ++d) n_[d] = static_cast<long>((hi[d] - lo_[d]) / cell_) + 2;
    return n_[0] * n_[1] * n_[2];
  };
  while (dims() > 20'000'000) cell_ *= 1.25;  // memory: at most 80 MB of floats
  size_.assign(n_[0] * n_[1] * n_[2], static_cast<float>(h));
  const std::vector<double> spacing = node_spacing(V, F);
  // a node's spacing seeds the cells around it at their centres (s + g·distance), so a
  // tiny edge does not impose its size on a whole cell; then the extra seeds the same way
  for (long i = 0; i < V.rows() + static_cast<long>(seeds.size()); ++i) {
    const bool node = i < V.rows();
    const double s = node ? spacing[i] : seeds[i - V.rows()][3];
    if (s <= 0) continue;
    const Eigen::Vector3d x =
        node ? Eigen::Vector3d(V.row(i).transpose())
             : Eigen::Vector3d(seeds[i - V.rows()][0], seeds[i - V.rows()][1], seeds[i - V.rows()][2]);
    long c[3];
    for (int d = 0; d < 3; ++d)
      c[d] = std::clamp(static_cast<long>(std::floor((x[d] - lo_[d]) / cell_ - 0.5)), 0L, n_[d] - 1);
    for (long di = 0; di < 2; ++di)
      for (long dj = 0; dj < 2; ++dj)
        for (long dk = 0; dk < 2; ++dk) {
          const long ci = std::min(c[0] + di, n_[0] - 1), cj = std::min(c[1] + dj, n_[1] - 1),
                     ck = std::min(c[2] + dk, n_[2] - 1);
          const Eigen::Vector3d centre = lo_ + cell_ * Eigen::Vector3d(ci + 0.5, cj + 0.5, ck + 0.5);
          float& v = size_[(ci * n_[1] + cj) * n_[2] + ck];
          v = std::min(v, static_cast<float>(s + g * (centre - x).norm()));
        }
  }
  const float step = static_cast<float>(g * cell_);
  for (int pass = 0; pass < 2; ++pass) {
    const long dir = pass == 0 ? 1 : -1;
    for (long i = pass == 0 ? 0 : n_[0] - 1; i >= 0 && i < n_[0]; i += dir)
      for (long j = pass == 0 ? 0 : n_[1] - 1; j >= 0 && j < n_[1]; j += dir)
        for (long k = pass == 0 ? 0 : n_[2] - 1; k >= 0 && k < n_[2]; k += dir) {
          float& c = size_[(i * n_[1] + j) * n_[2] + k];
          if (i - dir >= 0 && i - dir < n_[0]) c = std::min(c, size_[((i - dir) * n_[1] + j) * n_[2] + k] + step);
          if (j - dir >= 0 && j - dir < n_[1]) c = std::min(c, size_[(i * n_[1] + j - dir) * n_[2] + k] + step);
          if (k - dir >= 0 && k - dir < n_[2]) c = std::min(c, size_[(i * n_[1] + j) * n_[2] + k - dir] + step);
        }
  }
}

double BackgroundSize::at(const double* x) const {
  double w[3];
  long c[3];
  for (int d = 0; d < 3; ++d) {
    const double u = std::clamp((x[d] - lo_[d]) / cell_ - 0.5, 0.0, static_cast<double>(n_[d] - 1));
    c[d] = std::min(static_cast<long>(u), n_[d] - 2 >= 0 ? n_[d] - 2 : 0);
    w[d] = std::clamp(u - c[d], 0.0, 1.0);
  }
  double s = 0;
  for (int di = 0; di < 2; ++di)
    for (int dj = 0; dj < 2; ++dj)
      for (int dk = 0; dk < 2; ++dk) {
        const long ci = std::min(c[0] + di, n_[0] - 1), cj = std::min(c[1] + dj, n_[1] - 1),
                   ck = std::min(c[2] + dk, n_[2] - 1);
        s += (di ? w[0] : 1 - w[0]) * (dj ? w[1] : 1 - w[1]) * (dk ? w[2] : 1 - w[2]) *
             size_[(ci * n_[1] + cj) * n_[2] + ck];
      }
  return s;
}

double expected_tets(const MatX3d& V, const MatX3i& F, const std::function<double(const double*)>& size, long cells) {
  if (F.rows() == 0 || !size) return 0;
  const Eigen::Vector3d lo = V.colwise().minCoeff().transpose(), hi = V.colwise().maxCoeff().transpose();
  const Eigen::Vector3d ext = (hi - lo).cwiseMax(1e-12 * (hi - lo).norm());
  const double cell = std::cbrt(ext.prod() / static_cast<double>(std::max(1L, cells)));
  const long nx = std::max(1L, static_cast<long>(std::ceil(ext.x() / cell)));
  const long ny = std::max(1L, static_cast<long>(std::ceil(ext.y() / cell)));
  const long nz = std::max(1L, static_cast<long>(std::ceil(ext.z() / cell)));
  // per column, the heights where a triangle crosses its vertical line; the lines sit slightly
  // off the cell centres so that they miss the edges of structured faces (on an edge, both
  // triangles would count the crossing and the parity would flip)
  const double ox = 0.5 + 0.00731, oy = 0.5 + 0.00419;
  std::vector<std::vector<double>> crossings(nx * ny);
  for (long t = 0; t < F.rows(); ++t) {
    const Eigen::Vector3d a = V.row(F(t, 0)).transpose(), b = V.row(F(t, 1)).transpose(),
                          c = V.row(F(t, 2)).transpose();
    const double det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    if (det == 0) continue;  // vertical: no crossing with a vertical line in general position
    const double xlo = std::min({a.x(), b.x(), c.x()}), xhi = std::max({a.x(), b.x(), c.x()});
    const double ylo = std::min({a.y(), b.y(), c.y()}), yhi = std::max({a.y(), b.y(), c.y()});
    const long i0 = std::max(0L, static_cast<long>(std::ceil((xlo - lo.x()) / cell - ox)));
    const long i1 = std::min(nx - 1, static_cast<long>(std::floor((xhi - lo.x()) / cell - ox)));
    const long j0 = std::max(0L, static_cast<long>(std::ceil((ylo - lo.y()) / cell - oy)));
    const long j1 = std::min(ny - 1, static_cast<long>(std::floor((yhi - lo.y()) / cell - oy)));
    for (long i = i0; i <= i1; ++i)
      for (long j = j0; j <= j1; ++j) {
        const double x = lo.x() + (i + ox) * cell, y = lo.y() + (j + oy) * cell;
        // barycentric coordinates of (x, y) in the projected triangle
        const double u = ((x - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (y - a.y())) / det;
        const double v = ((b.x() - a.x()) * (y - a.y()) - (x - a.x()) * (b.y() - a.y())) / det;
        if (u < 0 || v < 0 || u + v > 1) continue;
        crossings[i * ny + j].push_back(a.z() + u * (b.z() - a.z()) + v * (c.z() - a.z()));
      }
  }
  const double per_volume = 6.0 * std::sqrt(2.0);  // tets per h³ of volume (regular tets)
  double total = 0;
  for (long i = 0; i < nx; ++i)
    for (long j = 0; j < ny; ++j) {
      std::vector<double>& z = crossings[i * ny + j];
      std::sort(z.begin(), z.end());
      size_t below = 0;
      for (long k = 0; k < nz; ++k) {
        const double p[3] = {lo.x() + (i + ox) * cell, lo.y() + (j + oy) * cell, lo.z() + (k + 0.5) * cell};
        while (below < z.size() && z[below] < p[2]) ++below;
        if (below % 2 == 0) continue;  // outside
        const double h = size(p);
        if (h > 0) total += cell * cell * cell * per_volume / (h * h * h);
      }
    }
  return total;
}

}  // namespace topopt::mesh
