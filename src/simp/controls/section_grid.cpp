// The extrusion's section field (see section_grid.h).
#include "simp/controls/section_grid.h"

#include <algorithm>
#include <cmath>

#include "simp/controls/design_map.h"
#include "simp/controls/tying.h"
#include "simp/density_filter.h"

namespace topopt::simp {

SectionGrid::SectionGrid(const Eigen::MatrixX3d& points, const Eigen::Vector3d& d, double h) : d_(d), h_(h) {
  cross_section_basis(d, u_, v_);
  const Eigen::Vector3d axis[2] = {u_, v_};
  for (int a = 0; a < 2; ++a) {
    const VecXd s = points * axis[a];
    lo_[a] = s.size() ? s.minCoeff() : 0;
    const double span = s.size() ? s.maxCoeff() - lo_[a] : 0;
    n_[a] = static_cast<int>(std::floor(span / h)) + 2;  // the last cell reaches past the highest point
  }
}

Eigen::SparseMatrix<double> SectionGrid::interpolation(const Eigen::MatrixX3d& points) const {
  std::vector<Eigen::Triplet<double>> w;
  w.reserve(4 * points.rows());
  for (long p = 0; p < points.rows(); ++p) {
    int i[2];
    double f[2];
    locate(points.row(p).transpose(), i, f);
    for (int di = 0; di < 2; ++di)
      for (int dj = 0; dj < 2; ++dj) {
        const double weight = (di ? f[0] : 1 - f[0]) * (dj ? f[1] : 1 - f[1]);
        if (weight > 0) w.emplace_back(p, (i[0] + di) * n_[1] + i[1] + dj, weight);
      }
  }
  Eigen::SparseMatrix<double> out(points.rows(), num_nodes());
  out.setFromTriplets(w.begin(), w.end());
  return out;
}

Eigen::Vector3d SectionGrid::node_point(int k, double s) const {
  return (lo_[0] + h_ * (k / n_[1])) * u_ + (lo_[1] + h_ * (k % n_[1])) * v_ + s * d_;
}

std::vector<int> SectionGrid::neighbours(int k) const {
  const int i = k / n_[1], j = k % n_[1];
  std::vector<int> out;
  if (i > 0) out.push_back(k - n_[1]);
  if (i + 1 < n_[0]) out.push_back(k + n_[1]);
  if (j > 0) out.push_back(k - 1);
  if (j + 1 < n_[1]) out.push_back(k + 1);
  return out;
}

void SectionGrid::locate(const Eigen::Vector3d& p, int i[2], double f[2]) const {
  const Eigen::Vector3d axis[2] = {u_, v_};
  for (int a = 0; a < 2; ++a) {
    const double s = (p.dot(axis[a]) - lo_[a]) / h_;
    i[a] = std::clamp(static_cast<int>(std::floor(s)), 0, n_[a] - 2);
    f[a] = std::clamp(s - i[a], 0.0, 1.0);
  }
}

double SectionGrid::value(const VecXd& g, const Eigen::Vector3d& p, Eigen::Vector3d* gradient) const {
  int i[2];
  double f[2];
  locate(p, i, f);
  const int k = i[0] * n_[1] + i[1];
  const double g00 = g[k], g10 = g[k + n_[1]], g01 = g[k + 1], g11 = g[k + n_[1] + 1];
  if (gradient) {
    const double du = ((1 - f[1]) * (g10 - g00) + f[1] * (g11 - g01)) / h_;
    const double dv = ((1 - f[0]) * (g01 - g00) + f[0] * (g11 - g10)) / h_;
    *gradient = du * u_ + dv * v_;
  }
  return (1 - f[0]) * ((1 - f[1]) * g00 + f[1] * g01) + f[0] * ((1 - f[1]) * g10 + f[1] * g11);
}

namespace {

/// The design tets (domain 0, or every tet without domains) of mesh.
std::vector<int> design_of(const TetMesh& mesh) {
  std::vector<int> design;
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (mesh.domain.size() != mesh.T.rows() || mesh.domain[t] == 0) design.push_back(static_cast<int>(t));
  return design;
}

/// #G: the grid field fitted to values (#D) at points weighted by w (#D by #G interpolation
/// weights times the volumes): each node the weighted mean; nodes without weight are filled,
/// front by front, with the mean of their filled neighbours.
VecXd fit_on_grid(const SectionGrid& grid, const Eigen::SparseMatrix<double>& w, const VecXd& values) {
  const VecXd mass = w.transpose() * VecXd::Ones(w.rows());
  VecXd g = (w.transpose() * values).cwiseQuotient(mass.cwiseMax(1e-300));
  std::vector<char> known(grid.num_nodes());
  for (int k = 0; k < grid.num_nodes(); ++k) known[k] = mass[k] > 0;
  for (bool grew = true; grew;) {
    grew = false;
    std::vector<char> next = known;
    for (int k = 0; k < grid.num_nodes(); ++k) {
      if (known[k]) continue;
      double sum = 0;
      int n = 0;
      for (int m : grid.neighbours(k))
        if (known[m]) sum += g[m], ++n;
      if (n) g[k] = sum / n, next[k] = 1, grew = true;
    }
    known.swap(next);
  }
  return g;
}

/// The design tets' nodes of mesh, in increasing order.
std::vector<int> design_nodes(const TetMesh& mesh, const std::vector<int>& design) {
  std::vector<char> mark(mesh.V.rows(), 0);
  for (int t : design)
    for (int a = 0; a < 4; ++a) mark[mesh.T(t, a)] = 1;
  std::vector<int> nodes;
  for (long n = 0; n < mesh.V.rows(); ++n)
    if (mark[n]) nodes.push_back(static_cast<int>(n));
  return nodes;
}

/// #nodes by 3: the points of the given nodes.
Eigen::MatrixX3d points_of(const TetMesh& mesh, const std::vector<int>& nodes) {
  Eigen::MatrixX3d at(nodes.size(), 3);
  for (size_t k = 0; k < nodes.size(); ++k) at.row(k) = mesh.V.row(nodes[k]);
  return at;
}

}  // namespace

SectionField fit_section_field(const TetMesh& mesh, const VecXd& density, const Eigen::Vector3d& d, double h) {
  const std::vector<int> design = design_of(mesh);
  SectionField out{SectionGrid(points_of(mesh, design_nodes(mesh, design)), d, h), {}};
  const VecXd all = tet_volumes(mesh);
  VecXd volume(design.size()), rho(design.size());
  for (size_t i = 0; i < design.size(); ++i) volume[i] = all[design[i]], rho[i] = density[design[i]];
  const Eigen::SparseMatrix<double> w = volume.asDiagonal() * out.grid.interpolation(design_centroids(mesh, design));
  out.g = fit_on_grid(out.grid, w, rho);
  return out;
}

VecXd section_node_densities(const TetMesh& mesh, const SectionField& field, const VecXd& base) {
  const std::vector<int> nodes = design_nodes(mesh, design_of(mesh));
  const VecXd value = field.grid.interpolation(points_of(mesh, nodes)) * field.g;
  VecXd out = base;
  for (size_t k = 0; k < nodes.size(); ++k) out[nodes[k]] = value[k];
  return out;
}

void snap_to_section_level(const SectionField& field, double t, MatX3d& V, const VecXi& lock) {
  const double step_cap = field.grid.spacing();
  for (long p = 0; p < V.rows(); ++p) {
    if (lock[p] != 0) continue;
    Eigen::Vector3d q = V.row(p).transpose();
    for (int it = 0; it < 3; ++it) {
      Eigen::Vector3d grad;
      const double f = field.grid.value(field.g, q, &grad) - t;
      const double g2 = grad.squaredNorm();
      if (std::abs(f) < 1e-9 || g2 < 1e-12) break;
      Eigen::Vector3d step = -f / g2 * grad;
      if (step.norm() > step_cap) step *= step_cap / step.norm();
      q += step;
    }
    V.row(p) = q.transpose();
  }
}

}  // namespace topopt::simp
