// Solver choice and the problem data every solver may need (see linear_solver.h).
#include "fem/linear_solver.h"

#include <algorithm>

namespace topopt::fem {

SolverKind choose_solver(SolverKind kind, int free_dofs) {
  if (kind != SolverKind::Auto) return kind;
  return free_dofs <= kDirectDofLimit ? SolverKind::Direct : SolverKind::Iterative;
}

std::unique_ptr<LinearSolver> make_linear_solver(const FreeSystem& system, const SolverParams& params) {
  if (choose_solver(params.kind, system.K->rows) == SolverKind::Direct) return make_direct_solver(system, params);
  return make_multigrid_solver(system, params);
}

std::vector<int> node_blocks(const std::vector<int>& free_dofs) {
  const int nf = static_cast<int>(free_dofs.size());
  std::vector<int> blocks(1, 0);
  for (int k = 1; k < nf; ++k)
    if (free_dofs[k] / 3 != free_dofs[k - 1] / 3) blocks.push_back(k);
  if (nf > 0) blocks.push_back(nf);
  return blocks;
}

void rigid_modes_at(const Eigen::Vector3d& x, int c, double row[6]) {
  for (int a = 0; a < 3; ++a) row[a] = a == c ? 1 : 0;
  // rotations about x, y, z: e_a × x, component c
  const double rot[3][3] = {{0, -x[2], x[1]}, {x[2], 0, -x[0]}, {-x[1], x[0], 0}};
  for (int a = 0; a < 3; ++a) row[3 + a] = rot[a][c];
}

std::vector<double> near_null_space(const MatX3d& nodes, const std::vector<int>& free_dofs) {
  const int nf = static_cast<int>(free_dofs.size());
  const Eigen::RowVector3d lo = nodes.colwise().minCoeff(), hi = nodes.colwise().maxCoeff();
  const Eigen::RowVector3d centre = 0.5 * (lo + hi);
  const double size = std::max(1e-300, (hi - lo).norm());
  std::vector<double> modes(6 * static_cast<size_t>(nf), 0.0);
  for (int k = 0; k < nf; ++k) {
    const int n = free_dofs[k] / 3, c = free_dofs[k] % 3;
    const Eigen::Vector3d x = ((nodes.row(n) - centre) / size).transpose();
    rigid_modes_at(x, c, &modes[6 * static_cast<size_t>(k)]);
  }
  return modes;
}

}  // namespace topopt::fem
