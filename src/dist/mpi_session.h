// The MPI/PETSc session of one `topopt` process started by mpirun (or srun): PETSc initialised
// for the life of the object, the communicator, this process's rank and the number of ranks.
// Passed to everything distributed; nothing in src/dist reads MPI's world on its own.
#pragma once
#include <mpi.h>

#include <exception>
#include <functional>
#include <string>

namespace topopt::dist {

/// How an error that ends a distributed run is put to the user: `failure` (what was thrown on
/// this rank), `rank` (this process's); prints the message and returns the exit code.
using FailureReport = std::function<int(std::exception_ptr failure, int rank)>;

class MpiSession {
 public:
  /// Initialises PETSc (and MPI) without command-line arguments; PETSc's own options come
  /// from the environment variable PETSC_OPTIONS (e.g. "-pc_type hypre"). report: see
  /// end_run (empty: the message alone on stderr, exit code 1). Throws Error(Internal) when
  /// PETSc cannot start.
  explicit MpiSession(FailureReport report = {});
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  MPI_Comm comm() const { return comm_; }
  int rank() const { return rank_; }
  int size() const { return size_; }

  /// Ends every rank after `failure` escaped this rank's part of a run: reports it (the
  /// FailureReport, on this rank), then MPI_Abort with the exit code it returned. The other
  /// ranks may be waiting for this one in a collective call and would otherwise wait forever.
  [[noreturn]] void end_run(std::exception_ptr failure) const;

 private:
  FailureReport report_;
  MPI_Comm comm_ = MPI_COMM_WORLD;
  int rank_ = 0, size_ = 1;
};

/// Throws Error(Internal) naming `what` when a PETSc call returned a non-zero code.
void check_petsc(int code, const char* what);

/// Peak resident memory of this process (bytes), from getrusage.
double peak_memory_bytes();

}  // namespace topopt::dist
