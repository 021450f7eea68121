// The MPI session of topopt_dist_tests (made in its main, for the whole run).
#pragma once
#include "dist/mpi_session.h"

namespace topopt::testing {
/// Set by main before any test runs; the tests only read it. (A test binary's fixture, not
/// product code: the library itself takes the session as an argument everywhere.)
extern const dist::MpiSession* g_session;
}  // namespace topopt::testing
