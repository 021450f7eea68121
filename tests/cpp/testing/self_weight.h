// The loads SIMP is handed with self-weight, shared by the SIMP tests: the given loads plus
// each case's full weight, as fem::make_loads gives it.
#pragma once
#include "common/types.h"
#include "fem/boundary_conditions.h"

namespace topopt::testing {

/// loads ((3*#V) by #cases) plus, per case k, the weight of every tet of `mesh` under the
/// acceleration gravity.col(k) (3 by #cases, mm/s²; no columns: none): what ComplianceProblem
/// and optimize() are given together with `gravity` (they scale the design tets' share by ρ̄).
inline Eigen::MatrixXd with_self_weight(const TetMesh& mesh, const fem::Material& material, Eigen::MatrixXd loads,
                                        const Eigen::Matrix3Xd& gravity) {
  for (long k = 0; k < gravity.cols(); ++k) {
    const fem::LoadSpec weight{fem::LoadSpec::Kind::Gravity, {}, {gravity(0, k), gravity(1, k), gravity(2, k)}, 0, {}};
    loads.col(k) += fem::make_loads(mesh, material, {fem::LoadCase{"g", {weight}, 1}}).col(0);
  }
  return loads;
}

}  // namespace topopt::testing
