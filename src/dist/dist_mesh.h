// The mesh distributed among the ranks, with its ghost layer. Rank 0 holds the serial mesh
// (read or meshed there: the mesher is serial); distribute_mesh sends every rank its tets (the
// partition's), the nodes it owns and the ghost nodes — nodes of its tets owned by another
// rank — so that a rank assembles, filters and differentiates its own tets without asking.
//
// Numbering: a node belongs to one of the ranks among its tets' (node_owners: a shared node to
// the less loaded of the lowest and the highest, so that the ranks own about as many nodes
// each as the partition allows). Global node numbers (PETSc's
// rows, divided by 3 for the dofs) run rank by rank, each rank's owned nodes contiguous in the
// serial order; on a rank the local nodes are its owned ones, then its ghosts by global number.
#pragma once
#include <vector>

#include "common/types.h"
#include "dist/mpi_session.h"
#include "fem/elasticity.h"

namespace topopt::dist {

struct DistMesh {
  /// This rank's part: V #local nodes by 3 (owned first, then ghosts), T #local tets by 4 in
  /// local node numbers, domain #local tets (0 design, >= 1 non-design solid).
  TetMesh local;
  int owned_nodes = 0;            ///< the first owned_nodes rows of local.V are owned
  std::vector<long> node_global;  ///< #local nodes: global node number
  long node_begin = 0;            ///< global number of the first owned node
  long total_nodes = 0;           ///< over all ranks
  long total_tets = 0;            ///< over all ranks
  std::vector<long> tet_serial;   ///< #local tets: the tet's index in the serial mesh
  std::vector<char> fixed;        ///< 3 × #local nodes: the dof is held (support, or unused node)
  Eigen::MatrixXd loads;          ///< 3 × owned_nodes by #cases: the loads on owned nodes
  // rank 0 only: where gathered values go in the serial mesh
  std::vector<int> serial_node;     ///< #total nodes: serial index of each global node
  std::vector<int> gathered_tets;   ///< #total tets: serial index of each tet in rank order
  std::vector<int> tets_per_rank;   ///< #ranks
  std::vector<int> nodes_per_rank;  ///< #ranks: owned nodes
};

/// The rank owning each node. A node inside one rank's tets: that rank; a node of no tet: rank 0;
/// a shared node, in node order: of the lowest and the highest rank among its tets', the one that
/// owns fewer nodes so far (the nodes inside a rank's tets counted first), so that the owned
/// nodes, PETSc's rows, balance as well as the partition allows. T: #T by 4, nodes: #V, part:
/// #T ranks in [0, ranks). Returns #V ranks.
std::vector<int> node_owners(const MatX4i& T, long nodes, const std::vector<int>& part, int ranks);

/// Distributes the serial mesh. Collective. On rank 0: mesh, part (#T ranks, partition_tets),
/// supports (fixed dofs; prescribed values must be 0) and loads ((3 #V) by #cases); the other
/// ranks pass empty ones. Throws Error(InvalidParameter) on rank 0 for a non-zero prescribed
/// displacement (the distributed solver holds supports at zero).
DistMesh distribute_mesh(const MpiSession& session, const TetMesh& mesh, const std::vector<int>& part,
                         const fem::Supports& supports, const Eigen::MatrixXd& loads);

/// Values of this rank's tets (#local tets) gathered on rank 0 in the serial order (#T);
/// empty on the other ranks. Collective.
VecXd gather_tets(const MpiSession& session, const DistMesh& mesh, const VecXd& local);

/// Dof values of the owned nodes (3 × owned_nodes by #cols, node-major) gathered on rank 0
/// in the serial order ((3 #V) by #cols); empty elsewhere. Collective.
Eigen::MatrixXd gather_nodes(const MpiSession& session, const DistMesh& mesh, const Eigen::MatrixXd& owned);

}  // namespace topopt::dist
