// The MPI/PETSc session (see mpi_session.h).
#include "dist/mpi_session.h"

#include <petscsys.h>
#include <sys/resource.h>

#include <cstdlib>
#include <iostream>

#include "common/error.h"

namespace topopt::dist {

MpiSession::MpiSession(FailureReport report) : report_(std::move(report)) {
  check_petsc(PetscInitializeNoArguments(), "PetscInitialize");
  comm_ = PETSC_COMM_WORLD;
  MPI_Comm_rank(comm_, &rank_);
  MPI_Comm_size(comm_, &size_);
}

MpiSession::~MpiSession() { PetscFinalize(); }

void MpiSession::end_run(std::exception_ptr failure) const {
  int code = 1;
  if (report_) {
    code = report_(failure, rank_);
  } else {
    try {
      std::rethrow_exception(failure);
    } catch (const std::exception& e) {
      std::cerr << "error on MPI rank " << rank_ << ": " << e.what() << std::endl;
    } catch (...) {
      std::cerr << "error on MPI rank " << rank_ << std::endl;
    }
  }
  std::cerr.flush();
  MPI_Abort(comm_, code);
  std::abort();  // MPI_Abort does not return; should it, no rank goes on
}

void check_petsc(int code, const char* what) {
  if (code == 0) return;
  const char* text = nullptr;
  PetscErrorMessage(static_cast<PetscErrorCode>(code), &text, nullptr);
  throw Error(ErrorCode::Internal,
              std::string("PETSc failed in ") + what + " (" + (text ? text : "unknown error") + ")");
}

double peak_memory_bytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return 1024.0 * static_cast<double>(usage.ru_maxrss);
}

}  // namespace topopt::dist
