// The main of topopt_dist_tests, run by ctest under `mpirun -np 2`: one MPI/PETSc session for
// all tests (every test is collective: all ranks run it, rank 0 compares with the serial code).
#include <gtest/gtest.h>

#include "dist/mpi_session.h"
#include "dist_test_session.h"

namespace topopt::testing {
const dist::MpiSession* g_session = nullptr;
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  topopt::dist::MpiSession session;
  topopt::testing::g_session = &session;
  // one rank's report is enough; the others still run every test (they are collective)
  if (session.rank() != 0)
    delete ::testing::UnitTest::GetInstance()->listeners().Release(
        ::testing::UnitTest::GetInstance()->listeners().default_result_printer());
  const int failed = RUN_ALL_TESTS();
  int any = failed;
  MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_MAX, session.comm());
  return any;
}
