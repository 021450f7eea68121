// Distributed runs (see dist_run.h).
#include "dist/dist_run.h"

#include <chrono>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <thread>
#include <type_traits>

#include "common/cpu_time.h"
#include "common/error.h"
#include "dist/dist_mesh.h"
#include "dist/dist_simp.h"
#include "dist/partition.h"

namespace topopt::dist {
namespace {

enum class Command : int { Stop = 0, Solve = 1, Optimize = 2 };

/// The part of simp::SimpParams the distributed loop runs with (check_distributable refuses
/// the rest: responses beyond compliance, geometry controls), as plain bytes.
struct SimpCore {
  double volume_fraction = 0.3;
  simp::SimpLaw law;
  simp::FilterParams filter;
  bool sensitivity_filter = false;
  simp::ProjectionParams projection;
  simp::UpdateKind update = simp::UpdateKind::OC;
  double move = 0.2;
  int max_iterations = 100;
  double tol_change = 0.01;
  double tol_objective = 1e-4;
  fem::SolverParams solver;
  double early_solver_tolerance = 1e-2;

  static SimpCore of(const simp::SimpParams& p) {
    return {p.volume_fraction, p.law,           p.filter, p.sensitivity_filter,
            p.projection,      p.update,        p.move,   p.max_iterations,
            p.tol_change,      p.tol_objective, p.solver, p.early_solver_tolerance};
  }
  simp::SimpParams params() const {
    simp::SimpParams p;
    p.volume_fraction = volume_fraction, p.law = law, p.filter = filter, p.sensitivity_filter = sensitivity_filter;
    p.projection = projection, p.update = update, p.move = move, p.max_iterations = max_iterations;
    p.tol_change = tol_change, p.tol_objective = tol_objective, p.solver = solver;
    p.early_solver_tolerance = early_solver_tolerance;
    return p;
  }
};

/// What every rank needs to know of a run, broadcast as bytes.
struct Settings {
  Command command = Command::Stop;
  fem::Material material;
  DistSolverParams solver;
  SimpCore simp;
  int cases = 0;
};
static_assert(std::is_trivially_copyable_v<Settings>, "Settings are broadcast as bytes");

/// What a run gives back on rank 0.
struct Answer {
  Eigen::MatrixXd U;
  std::vector<VecXd> von_mises;
  simp::SimpResult simp;
  std::vector<RankStats> stats;
};

/// Broadcasts the settings from rank 0. Non-blocking, polled with a short sleep: the other ranks
/// wait here while rank 0 reads and meshes the job, and a blocking broadcast would spin a core
/// the whole time (OpenMPI busy-waits).
void share_settings(const MpiSession& s, Settings& settings) {
  MPI_Request request;
  MPI_Ibcast(&settings, sizeof(Settings), MPI_BYTE, 0, s.comm(), &request);
  int done = 0;
  for (MPI_Test(&request, &done, MPI_STATUS_IGNORE); !done; MPI_Test(&request, &done, MPI_STATUS_IGNORE))
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Every rank's figures on rank 0.
std::vector<RankStats> gather_stats(const MpiSession& s, const RankStats& mine) {
  std::vector<RankStats> all(s.rank() == 0 ? s.size() : 0);
  MPI_Gather(&mine, sizeof(RankStats), MPI_BYTE, all.data(), sizeof(RankStats), MPI_BYTE, 0, s.comm());
  return all;
}

/// ServeParams::fail_after_distribution: this rank fails here, after the distribution, as an
/// error on that rank alone would: the other ranks are then inside collective calls.
void test_fault(const MpiSession& s) {
  throw Error(ErrorCode::Internal, "the fault --test-fail-after-distribution asks for, on rank " +
                                       std::to_string(s.rank()) + " only (a test of how errors end every rank)");
}

/// One run on every rank, the settings already shared (broadcast): rank 0 passes the serial
/// problem, the others empty ones.
Answer run_here(const MpiSession& s, const Settings& settings, const TetMesh& mesh, const fem::Supports& supports,
                const Eigen::MatrixXd& loads, std::vector<double> weights, const Progress& progress,
                const std::function<void(const simp::IterationRecord&)>& on_iteration, bool fault) {
  weights.resize(settings.cases);
  MPI_Bcast(weights.data(), settings.cases, MPI_DOUBLE, 0, s.comm());
  RankStats mine;
  mine.rank = s.rank();
  auto t0 = std::chrono::steady_clock::now();
  const DistMesh dm = distribute_mesh(s, mesh, partition_tets(s, mesh.T), supports, loads);
  mine.seconds_distribute = seconds_since(t0);
  if (fault) test_fault(s);
  mine.tets = dm.local.T.rows();
  mine.owned_nodes = dm.owned_nodes;
  mine.ghost_nodes = dm.local.V.rows() - dm.owned_nodes;
  if (s.rank() == 0)
    progress.say("dist", -1,
                 "mesh distributed among " + std::to_string(s.size()) + " ranks (" + std::to_string(mine.tets) +
                     " tets on rank 0)");
  t0 = std::chrono::steady_clock::now();
  Answer a;
  if (settings.command == Command::Solve) {
    DistElasticity fe(s, dm, settings.material, settings.solver);
    const Eigen::MatrixXd U = fe.solve(dm.loads);
    mine.solver_iterations = fe.last_iterations();
    a.U = gather_nodes(s, dm, U.topRows(3 * dm.owned_nodes));
    for (long k = 0; k < U.cols(); ++k) a.von_mises.push_back(gather_tets(s, dm, fe.von_mises(U.col(k))));
  } else {
    a.simp = optimize_mesh(s, dm, settings.material, weights, settings.simp.params(), settings.solver, progress,
                           on_iteration);
  }
  mine.seconds_run = seconds_since(t0);
  mine.peak_bytes = peak_memory_bytes();
  mine.cpu_seconds = process_cpu_seconds();  // a rank's work; wall time also counts its waits
  a.stats = gather_stats(s, mine);
  return a;
}

/// run_here, where an error on any rank ends every rank (MpiSession::end_run) with its message:
/// the failing rank cannot tell the others, which wait for it in a collective call.
Answer run(const MpiSession& s, const Settings& settings, const TetMesh& mesh, const fem::Supports& supports,
           const Eigen::MatrixXd& loads, const std::vector<double>& weights, const Progress& progress,
           const std::function<void(const simp::IterationRecord&)>& on_iteration, bool fault = false) {
  try {
    return run_here(s, settings, mesh, supports, loads, weights, progress, on_iteration, fault);
  } catch (...) {
    s.end_run(std::current_exception());
  }
}

}  // namespace

void solve_on_ranks(const MpiSession& session, const TetMesh& mesh, const fem::Material& material,
                    const fem::Supports& supports, const Eigen::MatrixXd& loads, const DistSolverParams& solver,
                    Eigen::MatrixXd& U, std::vector<VecXd>& von_mises, std::vector<RankStats>* stats) {
  Settings settings;
  settings.command = Command::Solve;
  settings.material = material;
  settings.solver = solver;
  settings.cases = static_cast<int>(loads.cols());
  share_settings(session, settings);
  Answer a = run(session, settings, mesh, supports, loads, std::vector<double>(loads.cols(), 1.0), {}, {});
  U = std::move(a.U);
  von_mises = std::move(a.von_mises);
  if (stats) *stats = std::move(a.stats);
}

simp::SimpResult optimize_on_ranks(const MpiSession& session, const TetMesh& mesh, const fem::Material& material,
                                   const fem::Supports& supports, const Eigen::MatrixXd& loads,
                                   const std::vector<double>& weights, const simp::SimpParams& params,
                                   const Progress& progress,
                                   const std::function<void(const simp::IterationRecord&)>& on_iteration,
                                   const Eigen::Matrix3Xd& gravity, Amg amg, std::vector<RankStats>* stats) {
  simp::check_params(params);
  simp::check_volume_fraction(params.volume_fraction);
  check_distributable(params, gravity.size() && !gravity.isZero());
  Settings settings;
  settings.command = Command::Optimize;
  settings.material = material;
  settings.simp = SimpCore::of(params);
  settings.solver.tolerance = params.solver.tolerance;
  settings.solver.max_iterations = params.solver.max_iterations;
  settings.solver.amg = amg;
  settings.solver.reuse = params.solver.recycle_factor;
  settings.cases = static_cast<int>(loads.cols());
  simp::FilterParams& f = settings.simp.filter;
  f.radius = simp::filter_radius(mesh, f);
  if (f.kind != simp::FilterKind::Helmholtz) {
    f.like_gaussian = f.kind == simp::FilterKind::Gaussian;
    f.kind = simp::FilterKind::Helmholtz;
    progress.info("under mpirun the density filter is the Helmholtz (PDE) one standing in for the explicit filter");
  }
  std::vector<double> w = weights;
  if (w.empty()) w.assign(loads.cols(), 1.0);
  share_settings(session, settings);
  Answer a = run(session, settings, mesh, supports, loads, w, progress, on_iteration);
  if (stats) *stats = std::move(a.stats);
  return std::move(a.simp);
}

void serve_ranks(const MpiSession& session, const ServeParams& params) {
  while (true) {
    Settings settings;
    share_settings(session, settings);
    if (settings.command == Command::Stop) return;
    run(session, settings, TetMesh(), fem::Supports(), Eigen::MatrixXd(), {}, {}, {}, params.fail_after_distribution);
  }
}

void release_ranks(const MpiSession& session) {
  Settings settings;
  share_settings(session, settings);
}

std::string stats_json(const std::vector<RankStats>& stats) {
  nlohmann::json j;
  j["ranks"] = stats.size();
  j["per_rank"] = nlohmann::json::array();
  for (const RankStats& r : stats)
    j["per_rank"].push_back({{"rank", r.rank},
                             {"tets", r.tets},
                             {"owned_nodes", r.owned_nodes},
                             {"ghost_nodes", r.ghost_nodes},
                             {"seconds_distribute", r.seconds_distribute},
                             {"seconds_run", r.seconds_run},
                             {"cpu_seconds", r.cpu_seconds},
                             {"peak_mb", r.peak_bytes / 1e6},
                             {"solver_iterations", r.solver_iterations}});
  return j.dump(2);
}

}  // namespace topopt::dist
