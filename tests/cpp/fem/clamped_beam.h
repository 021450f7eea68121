// Test fixture of the FEM solver tests: a beam 40 x 8 x 8 clamped at x = 0, its free-dof
// stiffness assembled directly from the element formula (independent of Elasticity).
#pragma once
#include <Eigen/Sparse>
#include <array>
#include <vector>

#include "fem/amg.h"
#include "fem/elasticity.h"
#include "fem/linear_solver.h"
#include "mesh/core/structured_box.h"

namespace topopt::fem {

inline TetMesh beam(std::array<int, 3> cells) {
  mesh::StructuredBoxParams p;
  p.size = {40, 8, 8};
  p.cells = cells;
  return mesh::structured_box_mesh(p);
}

/// Assembled free-dof stiffness of a clamped beam (x = 0 fixed) in full CSR with its node
/// blocks (what a LinearSolver sees, with the free dofs), the node ranges and rigid modes the
/// multigrid needs, and as the lower triangle (for Eigen's own Cholesky); built directly so the
/// tests do not depend on Elasticity's internals.
struct System {
  CsrMatrix A;
  std::vector<int> node_ptr;
  std::vector<double> modes;
  SparseLower lower;
  std::vector<int> free_dofs;
};

inline System clamped_beam_system(const TetMesh& m, const VecXd& scale) {
  Material mat;
  const double lambda = mat.young * mat.poisson / ((1 + mat.poisson) * (1 - 2 * mat.poisson));
  const double mu = mat.young / (2 * (1 + mat.poisson));
  const int nv = static_cast<int>(m.V.rows());
  std::vector<int> index(3 * nv, -1);
  int nf = 0;
  std::vector<int> node_ptr{0};
  for (int n = 0; n < nv; ++n) {
    if (m.V(n, 0) < 1e-12) continue;  // clamped
    for (int c = 0; c < 3; ++c) index[3 * n + c] = nf++;
    node_ptr.push_back(nf);
  }
  std::vector<Eigen::Triplet<double>> trip;
  for (long t = 0; t < m.T.rows(); ++t) {
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) J.col(k) = (m.V.row(m.T(t, k + 1)) - m.V.row(m.T(t, 0))).transpose();
    const double vol = J.determinant() / 6;
    Eigen::Matrix3d Ji = J.inverse();
    Eigen::Matrix<double, 4, 3> g;
    g.row(0) = -Ji.colwise().sum();
    g.bottomRows(3) = Ji;
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            int r = index[3 * m.T(t, a) + i], c = index[3 * m.T(t, b) + j];
            if (r < 0 || c < 0) continue;
            double v = vol * (lambda * g(a, i) * g(b, j) + mu * g(a, j) * g(b, i) +
                              (i == j ? mu * g.row(a).dot(g.row(b)) : 0.0));
            trip.emplace_back(r, c, scale[t] * v);
          }
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> S(nf, nf);
  S.setFromTriplets(trip.begin(), trip.end());
  S.makeCompressed();
  System sys;
  sys.A.rows = sys.A.cols = nf;
  sys.A.ptr.assign(S.outerIndexPtr(), S.outerIndexPtr() + nf + 1);
  sys.A.col.assign(S.innerIndexPtr(), S.innerIndexPtr() + S.nonZeros());
  sys.A.val.assign(S.valuePtr(), S.valuePtr() + S.nonZeros());
  sys.lower = SparseLower(S.triangularView<Eigen::Lower>());
  for (int d = 0; d < 3 * nv; ++d)
    if (index[d] >= 0) sys.free_dofs.push_back(d);
  sys.node_ptr = node_ptr;
  sys.A.blocks = node_ptr;  // every free node has its three dofs, coupled to the same nodes
  sys.modes.assign(6 * nf, 0.0);
  int k = 0;
  for (int n = 0; n < nv; ++n) {
    if (index[3 * n] < 0) continue;
    Eigen::Vector3d x = (m.V.row(n).transpose() - Eigen::Vector3d(20, 4, 4)) / 40;
    for (int c = 0; c < 3; ++c, ++k) {
      sys.modes[6 * k + c] = 1;
      for (int a = 0; a < 3; ++a) sys.modes[6 * k + 3 + a] = Eigen::Vector3d::Unit(a).cross(x)(c);
    }
  }
  return sys;
}

}  // namespace topopt::fem
