// The distributed runs as rank 0 starts them and the other ranks serve them. Rank 0 reads the
// job, meshes it (serially) and calls solve_on_ranks / optimize_on_ranks in place of the serial
// solve or SIMP; those broadcast the settings, partition the tets (partition.h), distribute the
// mesh with its ghost layer (dist_mesh.h), run on every rank and gather the answer on rank 0 in
// the serial mesh's numbering, so that the pipeline writes the same files as a serial run. The
// other ranks sit in serve_ranks until rank 0 calls release_ranks.
//
// Errors: one raised on rank 0 before a run starts (reading, meshing, check_distributable) is
// reported there as in a serial run, and release_ranks ends the others. One raised inside a run,
// on any rank, ends every rank (MpiSession::end_run: the message, then MPI_Abort), since the
// other ranks may be waiting for the failing one inside a collective call.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "dist/dist_elasticity.h"
#include "dist/mpi_session.h"
#include "simp/optimizer.h"

namespace topopt::dist {

/// What one rank held and spent in a distributed run (`--stats`).
struct RankStats {
  int rank = 0;
  long tets = 0, owned_nodes = 0, ghost_nodes = 0;
  double seconds_distribute = 0;  ///< partition and distribution of the mesh
  double seconds_run = 0;         ///< the solve, or SIMP
  double peak_bytes = 0;          ///< peak resident memory of the process so far
  double cpu_seconds = 0;         ///< user + system CPU time of the process so far
  int solver_iterations = 0;      ///< CG iterations of the last FE solve (the largest over the cases)
};

/// Rank 0: solves the load cases ((3 #V) by #cases loads; supports at zero) on all ranks.
/// U: (3 #V) by #cases displacements, von_mises: #T per case (MPa); stats (optional): one entry
/// per rank. Collective with serve_ranks on the others.
void solve_on_ranks(const MpiSession& session, const TetMesh& mesh, const fem::Material& material,
                    const fem::Supports& supports, const Eigen::MatrixXd& loads, const DistSolverParams& solver,
                    Eigen::MatrixXd& U, std::vector<VecXd>& von_mises, std::vector<RankStats>* stats = nullptr);

/// Rank 0: SIMP on all ranks, as simp::optimize with the same arguments; the filter becomes
/// the Helmholtz one (an explicit kind is replaced by the Helmholtz filter standing in for it,
/// said through progress.info); amg: the preconditioner of the FE solves. Throws
/// Error(InvalidParameter) before any distributed work for what check_distributable refuses.
/// Collective with serve_ranks on the others.
simp::SimpResult optimize_on_ranks(const MpiSession& session, const TetMesh& mesh, const fem::Material& material,
                                   const fem::Supports& supports, const Eigen::MatrixXd& loads,
                                   const std::vector<double>& weights, const simp::SimpParams& params,
                                   const Progress& progress,
                                   const std::function<void(const simp::IterationRecord&)>& on_iteration,
                                   const Eigen::Matrix3Xd& gravity, Amg amg, std::vector<RankStats>* stats = nullptr);

/// How a serving rank runs.
struct ServeParams {
  /// Test hook (tests/cpp/dist/cli_mpi_test.cpp; the CLI's hidden --test-fail-after-distribution,
  /// given to one rank of an MPMD launch): fail every run with Error(Internal) right after the
  /// mesh is distributed, to test that an error on one rank ends every rank with its message.
  bool fail_after_distribution = false;
};

/// Ranks other than 0: takes part in every run rank 0 starts until it calls release_ranks. An
/// error inside a run ends every rank (MpiSession::end_run).
void serve_ranks(const MpiSession& session, const ServeParams& params = {});

/// Rank 0: ends serve_ranks on the other ranks (once, at the end, also after an error).
void release_ranks(const MpiSession& session);

/// The per-rank figures as JSON text: {"ranks": N, "per_rank": [{rank, tets, owned_nodes,
/// ghost_nodes, seconds_distribute, seconds_run, cpu_seconds, peak_mb, solver_iterations}, ...]}.
std::string stats_json(const std::vector<RankStats>& stats);

}  // namespace topopt::dist
