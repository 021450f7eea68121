// Tets ↔ structured lattice (see lattice_transfer.h).
#include "simp/controls/lattice_transfer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace topopt::simp {

namespace {

/// The lattice index along each axis of the node nearest to p (lattice coordinates), clamped.
std::array<int, 3> nearest_node(const Eigen::Vector3d& p, const Eigen::Vector3d& spacing, const std::array<int, 3>& n) {
  std::array<int, 3> ijk;
  for (int a = 0; a < 3; ++a) ijk[a] = std::clamp(static_cast<int>(std::lround(p[a] / spacing[a])), 0, n[a] - 1);
  return ijk;
}

long node_id(const std::array<int, 3>& ijk, const std::array<int, 3>& n) {
  return (static_cast<long>(ijk[2]) * n[1] + ijk[1]) * n[0] + ijk[0];
}

}  // namespace

LatticeTransfer::LatticeTransfer(const Eigen::MatrixX3d& local, const VecXd& volumes, const std::vector<int>& variable,
                                 int num_variables, const Eigen::Vector3d& spacing, const std::array<int, 3>& n)
    : n_(n) {
  build_to_grid(local, volumes, variable, num_variables, spacing);
  build_to_elements(local, variable, num_variables, spacing);
}

void LatticeTransfer::build_to_grid(const Eigen::MatrixX3d& local, const VecXd& volumes,
                                    const std::vector<int>& variable, int num_variables,
                                    const Eigen::Vector3d& spacing) {
  const long num_elements = local.rows(), G = num_nodes();
  std::vector<long> start(G + 1, 0), node_of(num_elements);
  for (long e = 0; e < num_elements; ++e)
    ++start[(node_of[e] = node_id(nearest_node(local.row(e), spacing, n_), n_)) + 1];
  for (long q = 0; q < G; ++q) start[q + 1] += start[q];
  std::vector<long> members(num_elements), fill(start.begin(), start.end() - 1);
  for (long e = 0; e < num_elements; ++e) members[fill[node_of[e]]++] = e;
  fixed_ = VecXd::Zero(G);
  offset_ = Eigen::MatrixX3d::Zero(G, 3);
  active_.assign(G, 0);
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(num_elements + G);
  auto take = [&](long q, long e, double weight) {
    if (variable[e] >= 0)
      w.emplace_back(q, variable[e], weight);
    else
      fixed_[q] += weight;
    active_[q] = 1;
  };
  for (int k = 0; k < n_[2]; ++k)
    for (int j = 0; j < n_[1]; ++j)
      for (int i = 0; i < n_[0]; ++i) {
        const long q = node_id({i, j, k}, n_);
        if (start[q + 1] > start[q]) {  // the mean over the dual cell
          double vol = 0, kind_vol[2] = {0, 0};
          Eigen::Vector3d kind_sum[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
          for (long m = start[q]; m < start[q + 1]; ++m) {
            const long e = members[m];
            vol += volumes[e];
            kind_vol[variable[e] >= 0] += volumes[e];
            kind_sum[variable[e] >= 0] += volumes[e] * local.row(e).transpose();
          }
          for (long m = start[q]; m < start[q + 1]; ++m) take(q, members[m], volumes[members[m]] / vol);
          if (kind_vol[0] > 0 && kind_vol[1] > 0)
            offset_.row(q) = (kind_sum[1] / kind_vol[1] - kind_sum[0] / kind_vol[0]).transpose();
          continue;
        }
        const Eigen::Vector3d x(i * spacing[0], j * spacing[1], k * spacing[2]);
        long best = -1;
        double best_d = std::numeric_limits<double>::infinity();
        for (int dk = std::max(0, k - 1); dk <= std::min(n_[2] - 1, k + 1); ++dk)
          for (int dj = std::max(0, j - 1); dj <= std::min(n_[1] - 1, j + 1); ++dj)
            for (int di = std::max(0, i - 1); di <= std::min(n_[0] - 1, i + 1); ++di) {
              const long r = node_id({di, dj, dk}, n_);
              for (long m = start[r]; m < start[r + 1]; ++m) {
                const double d = (local.row(members[m]).transpose() - x).squaredNorm();
                if (d < best_d) best_d = d, best = members[m];
              }
            }
        if (best >= 0) take(q, best, 1.0);
      }
  to_grid_.resize(G, num_variables);
  to_grid_.setFromTriplets(w.begin(), w.end());
}

void LatticeTransfer::build_to_elements(const Eigen::MatrixX3d& local, const std::vector<int>& variable,
                                        int num_variables, const Eigen::Vector3d& spacing) {
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(8L * num_variables);
  for (long e = 0; e < local.rows(); ++e) {
    if (variable[e] < 0) continue;
    std::array<int, 3> cell;
    Eigen::Vector3d t;
    for (int a = 0; a < 3; ++a) {
      const double s = local(e, a) / spacing[a];
      cell[a] = std::clamp(static_cast<int>(std::floor(s)), 0, n_[a] - 2);
      t[a] = std::clamp(s - cell[a], 0.0, 1.0);
    }
    long corner[8];
    double weight[8], sum = 0;
    for (int c = 0; c < 8; ++c) {
      const std::array<int, 3> ijk{cell[0] + (c & 1), cell[1] + ((c >> 1) & 1), cell[2] + ((c >> 2) & 1)};
      corner[c] = node_id(ijk, n_);
      weight[c] = active_[corner[c]]
                      ? ((c & 1) ? t[0] : 1 - t[0]) * ((c & 2) ? t[1] : 1 - t[1]) * ((c & 4) ? t[2] : 1 - t[2])
                      : 0.0;
      sum += weight[c];
    }
    if (sum < 1e-12) {  // only at inactive corners' side: the node that holds the element
      w.emplace_back(variable[e], node_id(nearest_node(local.row(e), spacing, n_), n_), 1.0);
      continue;
    }
    for (int c = 0; c < 8; ++c)
      if (weight[c] > 0) w.emplace_back(variable[e], corner[c], weight[c] / sum);
  }
  to_elements_.resize(num_variables, num_nodes());
  to_elements_.setFromTriplets(w.begin(), w.end());
}

}  // namespace topopt::simp
