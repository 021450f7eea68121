// Density filter on tet centroids with a uniform-grid neighbour search (see density_filter.h).
#include "simp/density_filter.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "common/error.h"
#include "common/parallel.h"

namespace topopt::simp {

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
                             const FilterParams& params) {
  const int num_design = static_cast<int>(design.size());
  MatX3d cent = tet_centroids(mesh);
  const double r = params.radius;
  std::vector<std::vector<std::pair<int, double>>> rows(num_design);
  if (r <= 0) {
    for (int i = 0; i < num_design; ++i) rows[i].push_back({i, 1.0});
  } else {
    // Uniform grid of cell r over the design centroids; neighbours within r.
    Eigen::RowVector3d lo = Eigen::RowVector3d::Constant(1e300);
    for (int i = 0; i < num_design; ++i) lo = lo.cwiseMin(cent.row(design[i]));
    auto cell = [&](const Eigen::RowVector3d& p) {
      return std::array<long, 3>{static_cast<long>(std::floor((p[0] - lo[0]) / r)),
                                 static_cast<long>(std::floor((p[1] - lo[1]) / r)),
                                 static_cast<long>(std::floor((p[2] - lo[2]) / r))};
    };
    auto key = [](long x, long y, long z) { return (x * 73856093L) ^ (y * 19349663L) ^ (z * 83492791L); };
    std::unordered_map<long, std::vector<int>> grid;
    grid.reserve(num_design);
    for (int i = 0; i < num_design; ++i) {
      auto c = cell(cent.row(design[i]));
      grid[key(c[0], c[1], c[2])].push_back(i);
    }
    const double sigma = r / 3.0;
    parallel_for(num_design, thread_count(params.threads), [&](long b, long e) {
      for (long i = b; i < e; ++i) {
        Eigen::RowVector3d p = cent.row(design[i]);
        auto c = cell(p);
        for (long dx = -1; dx <= 1; ++dx)
          for (long dy = -1; dy <= 1; ++dy)
            for (long dz = -1; dz <= 1; ++dz) {
              auto it = grid.find(key(c[0] + dx, c[1] + dy, c[2] + dz));
              if (it == grid.end()) continue;
              for (int j : it->second) {
                auto cj = cell(cent.row(design[j]));
                if (cj[0] != c[0] + dx || cj[1] != c[1] + dy || cj[2] != c[2] + dz) continue;  // hash clash
                double d = (cent.row(design[j]) - p).norm();
                if (d >= r) continue;
                double w = params.kind == FilterKind::Cone ? r - d : std::exp(-d * d / (2 * sigma * sigma));
                rows[i].push_back({j, w});
              }
            }
      }
    });
  }
  std::vector<Eigen::Triplet<double>> th, tw;
  for (int i = 0; i < num_design; ++i) {
    double s = 0;
    for (auto [j, w] : rows[i]) s += w * volume[design[j]];
    for (auto [j, w] : rows[i]) {
      th.emplace_back(i, j, w * volume[design[j]] / s);
      tw.emplace_back(i, j, w);
    }
  }
  H_.resize(num_design, num_design);
  H_.setFromTriplets(th.begin(), th.end());
  W_.resize(num_design, num_design);
  W_.setFromTriplets(tw.begin(), tw.end());
}

VecXd DensityFilter::apply(const VecXd& x) const { return H_ * x; }
VecXd DensityFilter::apply_transpose(const VecXd& g) const { return H_.transpose() * g; }

VecXd DensityFilter::filter_sensitivity(const VecXd& x, const VecXd& g) const {
  VecXd num = W_ * x.cwiseProduct(g);
  VecXd den = W_ * VecXd::Ones(x.size());
  return num.cwiseQuotient(den.cwiseProduct(x.cwiseMax(1e-3)));
}

double DensityFilter::mean_neighbours() const {
  return H_.rows() ? static_cast<double>(H_.nonZeros()) / H_.rows() : 0.0;
}

}  // namespace topopt::simp
