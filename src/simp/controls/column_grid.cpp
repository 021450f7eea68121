// The draw direction's structured grid (see column_grid.h).
#include "simp/controls/column_grid.h"

#include <algorithm>
#include <cmath>

#include "simp/controls/tying.h"

namespace topopt::simp {

ColumnGrid::ColumnGrid(const Eigen::MatrixX3d& centroids, const VecXd& volumes, const Eigen::Vector3d& d, double h,
                       const Eigen::Vector3d& origin, bool origin_set)
    : h_(h) {
  Eigen::Vector3d u, v;
  cross_section_basis(d, u, v);
  Eigen::Matrix3d frame;
  frame << u.transpose(), v.transpose(), d.transpose();
  const Eigen::MatrixX3d local = centroids * frame.transpose();  // #D by 3: (u, v, s)
  Eigen::Vector3d lo = local.colwise().minCoeff().transpose();
  const Eigen::Vector3d hi = local.colwise().maxCoeff().transpose();
  if (origin_set) {  // cell faces through the origin: move the lower corner down onto them
    const Eigen::Vector3d o = frame * origin;
    for (int a = 0; a < 3; ++a) lo[a] = o[a] + std::floor((lo[a] - o[a]) / h) * h;
  }
  int n[3];
  for (int a = 0; a < 3; ++a) n[a] = std::max(1, static_cast<int>(std::floor((hi[a] - lo[a]) / h)) + 1);
  num_columns_ = n[0] * n[1];
  num_layers_ = n[2];
  start_ = lo[2];
  const long num_cells = static_cast<long>(num_columns_) * num_layers_;
  const long nd = centroids.rows();
  std::vector<long> cell_of(nd);
  VecXd cell_volume = VecXd::Zero(num_cells);
  for (long i = 0; i < nd; ++i) {
    int ijk[3];
    for (int a = 0; a < 3; ++a)
      ijk[a] = std::clamp(static_cast<int>(std::floor((local(i, a) - lo[a]) / h)), 0, n[a] - 1);
    cell_of[i] = (static_cast<long>(ijk[0]) * n[1] + ijk[1]) * num_layers_ + ijk[2];
    cell_volume[cell_of[i]] += volumes[i];
  }
  std::vector<Eigen::Triplet<double>> in, out;
  in.reserve(nd), out.reserve(nd);
  for (long i = 0; i < nd; ++i) {
    in.emplace_back(cell_of[i], i, volumes[i] / cell_volume[cell_of[i]]);
    out.emplace_back(i, cell_of[i], 1.0);
  }
  to_grid_.resize(num_cells, nd);
  to_grid_.setFromTriplets(in.begin(), in.end());
  to_elements_.resize(nd, num_cells);
  to_elements_.setFromTriplets(out.begin(), out.end());
  occupied_.assign(num_cells, 0);
  for (long i = 0; i < nd; ++i) occupied_[cell_of[i]] = 1;
}

int ColumnGrid::layer_of(double s) const {
  return std::clamp(static_cast<int>(std::floor((s - start_) / h_)), 0, num_layers_ - 1);
}

}  // namespace topopt::simp
