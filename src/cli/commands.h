// Sub-commands of build/topopt. Each takes the arguments after its name and returns the exit
// code; a topopt::Error escaping one is printed by main with its code.
#pragma once
#include <string>
#include <vector>

#include "brep/foreign.h"

namespace topopt::dist {
class MpiSession;
}

namespace topopt::cli {

using Args = std::vector<std::string>;

int cmd_info(const Args& args);
int cmd_mesh(const Args& args);
/// solve and optimize run on all MPI ranks when given the session (rank 0 calls them; a build
/// with PETSc under mpirun), serially when it is null.
int cmd_solve(const Args& args, const dist::MpiSession* session);
int cmd_optimize(const Args& args, const dist::MpiSession* session);
int cmd_surface(const Args& args);
/// topopt result JOB.json --threshold T: the shape of a finished optimize run at another
/// threshold, written as STEP (and STL) without optimising again.
int cmd_result(const Args& args);
/// topopt worker REQUEST.json: one request of the FreeCAD workbench, run out of FreeCAD's process
/// (JSON lines on stdout, results in files; see cmd_worker.cpp and worker_channel.h).
int cmd_worker(const Args& args);

/// The number of processes an MPI launcher started this one among (mpirun's
/// OMPI_COMM_WORLD_SIZE, MPICH's PMI_SIZE, srun's SLURM_STEP_NUM_TASKS), 1 without one; and
/// this process's rank among them (0 without one).
int launched_ranks();
int launched_rank();

/// Writes the --stats file of solve and optimize (JSON text) under a temporary name and renames
/// it; `path` empty: nothing.
void write_stats_file(const std::string& path, const std::string& json_text);

/// The figures of a serial run for --stats, in the shape of the distributed one's (one rank):
/// {"ranks": 1, "per_rank": [{"rank": 0, "tets", "seconds_run", "cpu_seconds", "peak_mb"}]}
/// (CPU time and peak memory of the whole process).
std::string serial_stats_json(long tets, double seconds_run);

class ArgReader;

/// The choices of --amg, for the usage texts of solve and optimize.
#define TOPOPT_AMG_CHOICES                                                                       \
  "gamg (PETSc's smoothed aggregation with the rigid-body modes) or boomeramg (hypre's, nodal\n" \
  "             coarsening); default gamg. Ignored by a serial run."

/// --amg of solve and optimize: "gamg" (also when absent) or "boomeramg" (the multigrid under
/// mpirun, dist::Amg). Throws Error(InvalidParameter) naming the choices for anything else.
std::string amg_option(ArgReader& reader);

/// Small argument reader shared by the sub-commands: `--name value` options, `--flag`
/// switches and positionals. Unknown options are an error with the usage text.
class ArgReader {
 public:
  ArgReader(const Args& args, std::string usage);
  /// Value of --name, or `fallback` if absent. Throws InvalidParameter if given without a value.
  std::string option(const std::string& name, const std::string& fallback = "");
  /// Value of --name as a finite number, or `fallback` if absent. Throws InvalidParameter
  /// for anything else ("abc", "nan", "inf").
  double number(const std::string& name, double fallback);
  /// --time-budget S: the seconds allowed for reading, or checking and healing, one input
  /// (brep::ForeignParams::seconds; absent or 0: from the input's size).
  brep::ForeignParams time_budget();
  bool flag(const std::string& name);
  bool has(const std::string& name) const;
  /// Remaining positional arguments; call after every option and flag has been read.
  /// Throws InvalidParameter naming any option that was not consumed.
  std::vector<std::string> positionals();
  bool wants_help() const { return help_; }
  /// When --help was given: prints the usage to stdout and returns true (the command returns 0).
  bool print_help() const;
  const std::string& usage() const { return usage_; }

 private:
  std::vector<std::string> args_;
  std::vector<bool> used_;
  std::string usage_;
  bool help_ = false;
};

/// CHOLMOD's malloc and calloc with the huge-page advice for large blocks, as the executables'
/// operator new (src/cli/large_allocations.cpp). Called once by main, before any command.
void use_huge_pages_in_cholmod();

}  // namespace topopt::cli
