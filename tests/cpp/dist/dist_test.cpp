// The distributed path against the serial one, on 2 ranks (ctest runs this binary under
// mpirun -np 2): the partition is balanced, the ghost layer holds the owners' data, and the
// distributed solve, Helmholtz filter and SIMP give the serial answers.
#include <gtest/gtest.h>
#include <petscsys.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "dist/dist_elasticity.h"
#include "dist/dist_helmholtz.h"
#include "dist/dist_mesh.h"
#include "dist/dist_run.h"
#include "dist/partition.h"
#include "dist_test_session.h"
#include "fem/boundary_conditions.h"
#include "mesh/core/structured_box.h"
#include "simp/density_filter.h"
#include "simp/helmholtz_filter.h"

namespace topopt::dist {
namespace {

const MpiSession& session() { return *testing::g_session; }
bool root() { return session().rank() == 0; }

/// A cantilever box 24 × 6 × 6 mm (12 × 3 × 3 cells, 648 tets) on rank 0, empty elsewhere,
/// fixed at x = 0 and pulled down at x = 24, with a non-design pad at the loaded end.
struct Beam {
  TetMesh mesh;
  fem::Material material{200000, 0.3};
  fem::Supports supports;
  Eigen::MatrixXd loads;
};

Beam make_beam() {
  Beam b;
  if (!root()) return b;
  mesh::StructuredBoxParams p;
  p.size = {24, 6, 6};
  p.cells = {12, 3, 3};
  p.nondesign = {{22, 0, 0, 24, 6, 6}};
  b.mesh = mesh::structured_box_mesh(p);
  b.supports = fem::make_supports(b.mesh, {fem::support_on(fem::SupportSpec::Kind::Fixed, {1})});
  b.loads =
      fem::make_loads(b.mesh, b.material,
                      {fem::LoadCase{"tip", {fem::LoadSpec{fem::LoadSpec::Kind::Force, {2}, {0, 0, -100}, 0, {}}}, 1}});
  return b;
}

DistMesh distribute(const Beam& b) {
  return distribute_mesh(session(), b.mesh, partition_tets(session(), b.mesh.T), b.supports, b.loads);
}

TEST(DistMesh, PartitionIsBalancedAndGhostsHoldTheOwnersData) {
  ASSERT_EQ(session().size(), 2) << "run under mpirun -np 2";
  const Beam b = make_beam();
  const DistMesh d = distribute(b);
  long tets[2] = {d.local.T.rows(), 0};
  MPI_Allgather(&tets[0], 1, MPI_LONG, tets, 1, MPI_LONG, session().comm());
  EXPECT_EQ(tets[0] + tets[1], d.total_tets);
  // PT-Scotch balances the tets to a few per cent
  EXPECT_LT(std::abs(tets[0] - tets[1]), 0.1 * d.total_tets) << tets[0] << " and " << tets[1];
  // a shared node is owned by one rank (node_owners) and a ghost on the other
  long ghosts = d.local.V.rows() - d.owned_nodes;
  MPI_Allreduce(MPI_IN_PLACE, &ghosts, 1, MPI_LONG, MPI_SUM, session().comm());
  EXPECT_GT(ghosts, 0) << "two parts of one beam share nodes";
  // every global node owned once; every ghost's coordinates are its owner's
  MatX3d all(d.total_nodes, 3);
  std::vector<int> counts(2), offsets(2, 0);
  const int mine = 3 * d.owned_nodes;
  MPI_Allgather(&mine, 1, MPI_INT, counts.data(), 1, MPI_INT, session().comm());
  offsets[1] = counts[0];
  EXPECT_EQ(counts[0] + counts[1], 3 * d.total_nodes);
  MPI_Allgatherv(d.local.V.data(), mine, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE,
                 session().comm());
  for (long i = 0; i < d.local.V.rows(); ++i)
    EXPECT_EQ((all.row(d.node_global[i]) - d.local.V.row(i)).norm(), 0.0) << "local node " << i;
  // each local tet is its serial tet: the same corners (through the global numbering)
  const VecXd serial_of = gather_tets(
      session(), d, Eigen::Map<const Eigen::Matrix<long, -1, 1>>(d.tet_serial.data(), d.local.T.rows()).cast<double>());
  if (root()) {
    for (long t = 0; t < b.mesh.T.rows(); ++t) EXPECT_EQ(serial_of[t], t);
    std::set<int> owned(d.serial_node.begin(), d.serial_node.end());
    EXPECT_EQ(static_cast<long>(owned.size()), b.mesh.V.rows());
    for (long t = 0; t < d.local.T.rows(); ++t)
      for (int a = 0; a < 4; ++a)
        EXPECT_EQ(d.serial_node[d.node_global[d.local.T(t, a)]], b.mesh.T(d.tet_serial[t], a));
  }
}

/// node_owners on a box of 20 × 10 × 10 cells cut at x = cut into rank 0 (x < cut) and rank 1:
/// checks that nodes off the cut belong to their side and returns how many of the 11 × 11
/// nodes on the cut each rank owns.
std::array<long, 2> owners_on_cut(double cut) {
  mesh::StructuredBoxParams p;
  p.size = {20, 10, 10};
  p.cells = {20, 10, 10};
  const TetMesh m = mesh::structured_box_mesh(p);
  std::vector<int> part(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) {
    double x = 0;
    for (int a = 0; a < 4; ++a) x += m.V(m.T(t, a), 0) / 4;
    part[t] = x < cut ? 0 : 1;
  }
  const std::vector<int> owner = node_owners(m.T, m.V.rows(), part, 2);
  std::array<long, 2> on_cut{0, 0};
  for (long n = 0; n < m.V.rows(); ++n) {
    const double x = m.V(n, 0);
    if (std::abs(x - cut) < 1e-9) {
      ++on_cut[owner[n]];
    } else {
      EXPECT_EQ(owner[n], x < cut ? 0 : 1) << "node " << n << " at x = " << x << " lies in one rank's tets only";
    }
  }
  EXPECT_EQ(on_cut[0] + on_cut[1], 121);
  return on_cut;
}

TEST(DistMesh, SharedNodesGoToTheLessLoadedRank) {
  // cut in the middle: both sides own 10 × 121 nodes of their own, the cut's split evenly
  const std::array<long, 2> middle = owners_on_cut(10);
  EXPECT_LE(std::abs(middle[0] - middle[1]), 1) << middle[0] << " and " << middle[1];
  // cut at x = 6: rank 0 owns 6 × 121 nodes of its own, rank 1 14 × 121: the cut goes to rank 0
  const std::array<long, 2> off = owners_on_cut(6);
  EXPECT_EQ(off[0], 121) << off[1] << " shared nodes on the more loaded rank 1";
}

TEST(DistElasticity, DisplacementsEqualTheSerialSolve) {
  const Beam b = make_beam();
  DistSolverParams params;
  params.tolerance = 1e-10;
  Eigen::MatrixXd U;
  std::vector<VecXd> von_mises;
  std::vector<RankStats> stats;
  if (!root()) return serve_ranks(session());
  solve_on_ranks(session(), b.mesh, b.material, b.supports, b.loads, params, U, von_mises, &stats);
  release_ranks(session());
  fem::SolverParams direct;
  direct.kind = fem::SolverKind::Direct;
  fem::Elasticity fe(b.mesh, b.material, b.supports, direct);
  const Eigen::MatrixXd reference = fe.solve(b.loads);
  EXPECT_LT((U - reference).norm(), 1e-6 * reference.norm());
  EXPECT_LT((von_mises[0] - fe.von_mises(reference.col(0))).norm(), 1e-6 * von_mises[0].norm());
  ASSERT_EQ(stats.size(), 2u);
  EXPECT_GT(stats[1].tets, 0);
  EXPECT_GT(stats[1].peak_bytes, 0);
}

/// Element factors of this rank's tets: 1 + amplitude · sin of the centroid's x (a smooth
/// change of stiffness, as one SIMP step makes), floored at `floor`.
VecXd wavy_scale(const DistMesh& d, double amplitude, double floor) {
  VecXd s(d.local.T.rows());
  for (long t = 0; t < s.size(); ++t) {
    double x = 0;
    for (int a = 0; a < 4; ++a) x += 0.25 * d.local.V(d.local.T(t, a), 0);
    s[t] = std::max(floor, 1 + amplitude * std::sin(x / 4));
  }
  return s;
}

/// SIMP's next matrix solves on the multigrid set up for the previous one (no new set-up) and
/// still meets the tolerance: its displacements equal those of a solver set up for it. A
/// large change solves as accurately (on a kept or a new set-up, the reuse rule's choice);
/// with reuse off every new matrix gets its own set-up.
TEST(DistElasticity, AKeptMultigridSolvesTheNextMatrixToTheTolerance) {
  const Beam b = make_beam();
  const DistMesh d = distribute(b);
  DistSolverParams params;
  params.tolerance = 1e-10;
  DistElasticity kept(session(), d, b.material, params);
  params.reuse = false;
  DistElasticity fresh(session(), d, b.material, params);
  for (DistElasticity* fe : {&kept, &fresh}) fe->solve(d.loads);
  const int first = kept.last_iterations();
  for (double amplitude : {0.2, 0.999}) {
    const VecXd scale = wavy_scale(d, amplitude, 1e-3);
    kept.set_scale(scale);
    fresh.set_scale(scale);
    const Eigen::MatrixXd Uk = kept.solve(d.loads), Uf = fresh.solve(d.loads);
    double diff = (Uk - Uf).squaredNorm(), norm = Uf.squaredNorm();
    MPI_Allreduce(MPI_IN_PLACE, &diff, 1, MPI_DOUBLE, MPI_SUM, session().comm());
    MPI_Allreduce(MPI_IN_PLACE, &norm, 1, MPI_DOUBLE, MPI_SUM, session().comm());
    EXPECT_LT(std::sqrt(diff), 1e-6 * std::sqrt(norm)) << "amplitude " << amplitude;
    if (amplitude == 0.2) {
      EXPECT_EQ(kept.setups(), 1) << "a small change keeps the set-up";
      EXPECT_LE(kept.last_iterations(), static_cast<int>(1.5 * first) + 4);
    }
  }
  EXPECT_EQ(fresh.setups(), 3);
}

/// A user's smoother setting that makes Chebyshev amplify the highest modes (it aims at a fifth
/// of the largest eigenvalue) breaks CG; the solve is run again with SOR smoothing and still
/// gives the direct solver's displacements, and says so.
TEST(DistElasticity, AFailedMultigridSolveIsSolvedAgainWithSorSmoothing) {
  const Beam b = make_beam();
  DistSolverParams params;
  params.tolerance = 1e-10;
  ASSERT_EQ(PetscOptionsSetValue(nullptr, "-mg_levels_ksp_chebyshev_esteig", "0,0.02,0,0.2"), 0);
  Eigen::MatrixXd U;
  std::vector<VecXd> von_mises;
  if (!root()) {
    serve_ranks(session());
  } else {
    ::testing::internal::CaptureStderr();
    solve_on_ranks(session(), b.mesh, b.material, b.supports, b.loads, params, U, von_mises, nullptr);
    const std::string said = ::testing::internal::GetCapturedStderr();
    release_ranks(session());
    EXPECT_NE(said.find("solving again with SOR smoothing"), std::string::npos) << said;
    fem::SolverParams direct;
    direct.kind = fem::SolverKind::Direct;
    fem::Elasticity fe(b.mesh, b.material, b.supports, direct);
    const Eigen::MatrixXd reference = fe.solve(b.loads);
    EXPECT_LT((U - reference).norm(), 1e-6 * reference.norm());
  }
  for (const char* name : {"-mg_levels_ksp_chebyshev_esteig", "-mg_levels_ksp_type", "-mg_levels_pc_type"})
    PetscOptionsClearValue(nullptr, name);
}

TEST(DistHelmholtz, FiltersAsTheSerialFilter) {
  const Beam b = make_beam();
  const DistMesh d = distribute(b);
  std::vector<int> design;
  VecXd x_local;
  for (long t = 0; t < d.local.T.rows(); ++t)
    if (d.local.domain[t] == 0) {
      design.push_back(static_cast<int>(t));
      const Eigen::RowVector3d c = d.local.V.row(d.local.T(t, 0));
      x_local.conservativeResize(x_local.size() + 1);
      x_local[x_local.size() - 1] = 0.5 + 0.4 * std::sin(c[0] / 3) * std::cos(c[2] / 2);
    }
  const double length = simp::helmholtz_length(4.0, false);
  DistHelmholtz filter(session(), d, design, length);
  // spread the local answers over the tets to gather them in the serial order
  auto gathered = [&](const VecXd& per_design) {
    VecXd per_tet = VecXd::Constant(d.local.T.rows(), -1.0);
    for (size_t i = 0; i < design.size(); ++i) per_tet[design[i]] = per_design[static_cast<long>(i)];
    return gather_tets(session(), d, per_tet);
  };
  const VecXd x = gathered(x_local), fx = gathered(filter.apply(x_local)),
              ftx = gathered(filter.apply_transpose(x_local));
  if (!root()) return;
  std::vector<int> serial_design;
  for (long t = 0; t < b.mesh.T.rows(); ++t)
    if (b.mesh.domain[t] == 0) serial_design.push_back(static_cast<int>(t));
  VecXd xs(static_cast<long>(serial_design.size()));
  for (size_t i = 0; i < serial_design.size(); ++i) xs[static_cast<long>(i)] = x[serial_design[i]];
  simp::HelmholtzFilter serial(b.mesh, serial_design, simp::tet_volumes(b.mesh),
                               {simp::FilterKind::Helmholtz, 4.0, 1, false});
  const VecXd f = serial.apply(xs), ft = serial.apply_transpose(xs);
  ASSERT_GT((f - xs).norm(), 1e-2 * xs.norm()) << "the filter must change this field";
  for (size_t i = 0; i < serial_design.size(); ++i) {
    EXPECT_NEAR(fx[serial_design[i]], f[static_cast<long>(i)], 1e-9);
    EXPECT_NEAR(ftx[serial_design[i]], ft[static_cast<long>(i)], 1e-9 * ft.cwiseAbs().maxCoeff());
  }
}

TEST(DistSimp, OptimizeEqualsTheSerialRun) {
  const Beam b = make_beam();
  simp::SimpParams params;
  params.volume_fraction = 0.4;
  params.filter = {simp::FilterKind::Helmholtz, 3.0, 1, false};
  params.max_iterations = 20;
  params.solver.tolerance = 1e-9;
  if (!root()) return serve_ranks(session());
  const simp::SimpResult distributed =
      optimize_on_ranks(session(), b.mesh, b.material, b.supports, b.loads, {}, params, {}, {}, {}, Amg::GAMG);
  release_ranks(session());
  params.solver.kind = fem::SolverKind::Direct;
  const simp::SimpResult serial = simp::optimize(b.mesh, b.material, b.supports, b.loads, {}, params);
  ASSERT_FALSE(serial.history.empty());
  const double c_serial = serial.history.back().compliance, c_dist = distributed.history.back().compliance;
  EXPECT_NEAR(c_dist, c_serial, 1e-3 * c_serial);
  EXPECT_LE(std::abs(static_cast<int>(serial.history.size()) - static_cast<int>(distributed.history.size())), 2);
  EXPECT_LT(serial.history.back().compliance, 0.8 * serial.history.front().compliance)
      << "the case must optimise something";
  ASSERT_EQ(distributed.density.size(), serial.density.size());
  EXPECT_EQ(distributed.design, serial.design);
  EXPECT_LT((distributed.density - serial.density).cwiseAbs().maxCoeff(), 0.05);
}

}  // namespace
}  // namespace topopt::dist
