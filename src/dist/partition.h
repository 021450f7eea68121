// Partitioning the tets among the ranks: the tet dual graph (tets sharing a face) handed to
// PETSc's MatPartitioning (PT-Scotch by default; -mat_partitioning_type in PETSC_OPTIONS picks
// another), so that each rank gets about as many tets and few faces are cut.
#pragma once
#include <vector>

#include "common/types.h"
#include "dist/mpi_session.h"

namespace topopt::dist {

/// Compressed rows of the tet dual graph of T (#T by 4): the tets sharing a face with each
/// tet. ptr: #T + 1 offsets into adj; adj: the neighbours, each tet's sorted.
struct DualGraph {
  std::vector<int> ptr, adj;
};
DualGraph tet_dual_graph(const MatX4i& T);

/// The rank (0 .. size − 1) of each tet. Collective: rank 0 passes the mesh's tets T (#T by 4),
/// the others an empty matrix. Returns #T parts on rank 0, nothing elsewhere.
std::vector<int> partition_tets(const MpiSession& session, const MatX4i& T);

}  // namespace topopt::dist
