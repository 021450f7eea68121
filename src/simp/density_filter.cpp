// The explicit density filter: neighbours by a uniform grid of cell r over the design
// centroids, weights written once in compressed rows (see density_filter.h).
#include "simp/density_filter.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>

#include "common/parallel.h"

namespace topopt::simp {
namespace {

/// The design centroids in cells of size r: each element's cell, and per occupied cell the
/// range of its elements in `order`.
class CentroidGrid {
 public:
  CentroidGrid(const MatX3d& centre, double r) : centre_(centre), r_(r) {
    lo_ = centre.colwise().minCoeff();
    const long n = centre.rows();
    std::vector<std::pair<std::uint64_t, int>> keyed(static_cast<size_t>(n));
    for (long i = 0; i < n; ++i) keyed[i] = {key(cell(i)), static_cast<int>(i)};
    std::sort(keyed.begin(), keyed.end());
    order_.resize(keyed.size());
    for (size_t k = 0; k < keyed.size(); ++k) {
      order_[k] = keyed[k].second;
      auto& range = cells_[keyed[k].first];
      if (k == 0 || keyed[k - 1].first != keyed[k].first) range.first = static_cast<int>(k);
      range.second = static_cast<int>(k + 1);
    }
  }

  /// Calls fn(j, d) for every element j whose centroid lies within r of element i's (i itself
  /// included, d = 0), in increasing j.
  template <class Fn>
  void for_each_neighbour(long i, std::vector<std::pair<int, double>>& scratch, Fn&& fn) const {
    scratch.clear();
    const std::array<long, 3> c = cell(i);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy)
        for (long dz = -1; dz <= 1; ++dz) {
          auto it = cells_.find(key({c[0] + dx, c[1] + dy, c[2] + dz}));
          if (it == cells_.end()) continue;
          for (int k = it->second.first; k < it->second.second; ++k) {
            const int j = order_[k];
            const double d = (centre_.row(j) - centre_.row(i)).norm();
            if (d < r_) scratch.push_back({j, d});
          }
        }
    std::sort(scratch.begin(), scratch.end());
    for (const auto& [j, d] : scratch) fn(j, d);
  }

 private:
  std::array<long, 3> cell(long i) const {
    std::array<long, 3> c;
    for (int a = 0; a < 3; ++a) c[a] = static_cast<long>(std::floor((centre_(i, a) - lo_[a]) / r_));
    return c;
  }
  /// A cell's exact key: 21 bits an axis (cells −1 .. 2²¹−2, far beyond any mesh/radius ratio).
  static std::uint64_t key(const std::array<long, 3>& c) {
    auto bits = [](long v) { return static_cast<std::uint64_t>(v + 1) & ((1u << 21) - 1); };
    return bits(c[0]) | bits(c[1]) << 21 | bits(c[2]) << 42;
  }

  const MatX3d& centre_;
  double r_;
  Eigen::RowVector3d lo_;
  std::vector<int> order_;
  std::unordered_map<std::uint64_t, std::pair<int, int>> cells_;
};

/// The weight of a neighbour at distance d (d < r).
double weight(FilterKind kind, double r, double d) {
  const double sigma = r / 3.0;
  return kind == FilterKind::Cone ? r - d : std::exp(-d * d / (2 * sigma * sigma));
}

}  // namespace

VecXd tet_volumes(const TetMesh& mesh) {
  VecXd v(mesh.T.rows());
  for (long t = 0; t < mesh.T.rows(); ++t) {
    Eigen::RowVector3d p0 = mesh.V.row(mesh.T(t, 0));
    Eigen::Matrix3d J;
    for (int a = 0; a < 3; ++a) J.row(a) = mesh.V.row(mesh.T(t, a + 1)) - p0;
    v[t] = J.determinant() / 6.0;
  }
  return v;
}

MatX3d tet_centroids(const TetMesh& mesh) {
  MatX3d c(mesh.T.rows(), 3);
  for (long t = 0; t < mesh.T.rows(); ++t)
    c.row(t) = 0.25 * (mesh.V.row(mesh.T(t, 0)) + mesh.V.row(mesh.T(t, 1)) + mesh.V.row(mesh.T(t, 2)) +
                       mesh.V.row(mesh.T(t, 3)));
  return c;
}

DensityFilter::DensityFilter(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volume,
                             const FilterParams& params)
    : kind_(params.kind == FilterKind::Cone ? "cone" : "Gaussian"), radius_(params.radius) {
  const long nd = static_cast<long>(design.size());
  volume_.resize(nd);
  MatX3d centre(nd, 3);
  const MatX3d all = tet_centroids(mesh);
  for (long i = 0; i < nd; ++i) volume_[i] = volume[design[i]], centre.row(i) = all.row(design[i]);
  W_.resize(nd, nd);
  const double r = params.radius;
  if (!(r > 0) || nd == 0) {
    W_.setIdentity();
  } else {
    // two passes over the neighbours (count, then write) so that the pairs are held once
    const CentroidGrid grid(centre, r);
    const int threads = thread_count(params.threads);
    std::vector<int> count(static_cast<size_t>(nd) + 1, 0);
    parallel_for(nd, threads, [&](long b, long e) {
      std::vector<std::pair<int, double>> scratch;
      for (long i = b; i < e; ++i) grid.for_each_neighbour(i, scratch, [&](int, double) { ++count[i + 1]; });
    });
    for (long i = 0; i < nd; ++i) count[i + 1] += count[i];
    W_.resizeNonZeros(count[nd]);
    std::copy(count.begin(), count.end(), W_.outerIndexPtr());
    parallel_for(nd, threads, [&](long b, long e) {
      std::vector<std::pair<int, double>> scratch;
      for (long i = b; i < e; ++i) {
        int k = count[i];
        grid.for_each_neighbour(i, scratch, [&](int j, double d) {
          W_.innerIndexPtr()[k] = j;
          W_.valuePtr()[k++] = weight(params.kind, r, d);
        });
      }
    });
  }
  weighted_sum_ = W_ * volume_;
  plain_sum_ = W_ * VecXd::Ones(nd);
}

VecXd DensityFilter::apply(const VecXd& x) const { return (W_ * volume_.cwiseProduct(x)).cwiseQuotient(weighted_sum_); }

VecXd DensityFilter::apply_transpose(const VecXd& g) const {
  return (W_ * g.cwiseQuotient(weighted_sum_)).cwiseProduct(volume_);
}

VecXd DensityFilter::filter_sensitivity(const VecXd& x, const VecXd& g) const {
  return (W_ * x.cwiseProduct(g)).cwiseQuotient(plain_sum_.cwiseProduct(x.cwiseMax(1e-3)));
}

double DensityFilter::mean_neighbours() const {
  return W_.rows() ? static_cast<double>(W_.nonZeros()) / W_.rows() : 0.0;
}

std::string DensityFilter::describe() const {
  std::ostringstream s;
  s << kind_ << " filter, radius " << radius_ << " mm, " << mean_neighbours() << " neighbours per element";
  return s.str();
}

}  // namespace topopt::simp
