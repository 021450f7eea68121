// Distributing the mesh with its ghost layer (see dist_mesh.h).
#include "dist/dist_mesh.h"

#include <algorithm>
#include <numeric>

#include "common/error.h"

namespace topopt::dist {
namespace {

template <class T>
MPI_Datatype mpi_type();
template <>
MPI_Datatype mpi_type<double>() {
  return MPI_DOUBLE;
}
template <>
MPI_Datatype mpi_type<int>() {
  return MPI_INT;
}
template <>
MPI_Datatype mpi_type<long>() {
  return MPI_LONG;
}
template <>
MPI_Datatype mpi_type<char>() {
  return MPI_CHAR;
}

/// Sends v to `dest` (its length first), or keeps it when dest is this rank.
template <class T>
void send_vector(MPI_Comm comm, int dest, const std::vector<T>& v) {
  long n = static_cast<long>(v.size());
  MPI_Send(&n, 1, MPI_LONG, dest, 0, comm);
  if (n) MPI_Send(v.data(), static_cast<int>(n), mpi_type<T>(), dest, 0, comm);
}

template <class T>
std::vector<T> receive_vector(MPI_Comm comm) {
  long n = 0;
  MPI_Recv(&n, 1, MPI_LONG, 0, 0, comm, MPI_STATUS_IGNORE);
  std::vector<T> v(static_cast<size_t>(n));
  if (n) MPI_Recv(v.data(), static_cast<int>(n), mpi_type<T>(), 0, 0, comm, MPI_STATUS_IGNORE);
  return v;
}

/// One rank's share as flat arrays, built on rank 0.
struct Package {
  std::vector<long> header;  // owned nodes, node_begin, total nodes, total tets, #cases
  std::vector<double> V, loads;
  std::vector<int> T, domain;
  std::vector<long> node_global, tet_serial;
  std::vector<char> fixed;
};

/// Rank 0's view of the whole distribution: owners, global numbers, held dofs.
struct Layout {
  std::vector<int> owner, global;  // #V
  std::vector<long> begin;         // #ranks + 1: first global node of each rank
  std::vector<char> fixed;         // 3 #V
};

}  // namespace

std::vector<int> node_owners(const MatX4i& T, long nodes, const std::vector<int>& part, int ranks) {
  std::vector<int> low(nodes, ranks), high(nodes, -1);
  for (long t = 0; t < T.rows(); ++t)
    for (int a = 0; a < 4; ++a) {
      const int n = T(t, a);
      low[n] = std::min(low[n], part[t]);
      high[n] = std::max(high[n], part[t]);
    }
  // nodes inside one rank's tets first, then each shared node to the less loaded of its two
  std::vector<int> owner(nodes, 0);
  std::vector<long> load(ranks, 0);
  for (long n = 0; n < nodes; ++n)
    if (high[n] >= 0 && low[n] == high[n]) ++load[owner[n] = low[n]];
  for (long n = 0; n < nodes; ++n)
    if (high[n] >= 0 && low[n] != high[n]) ++load[owner[n] = load[high[n]] < load[low[n]] ? high[n] : low[n]];
  return owner;
}

namespace {

Layout make_layout(const TetMesh& mesh, const std::vector<int>& part, const fem::Supports& supports, int ranks,
                   DistMesh& d) {
  const long nv = mesh.V.rows();
  Layout L;
  L.owner = node_owners(mesh.T, nv, part, ranks);
  L.fixed.assign(3 * nv, 0);
  std::vector<char> used(nv, 0);
  for (long t = 0; t < mesh.T.rows(); ++t)
    for (int a = 0; a < 4; ++a) used[mesh.T(t, a)] = 1;
  for (long n = 0; n < nv; ++n)
    if (!used[n]) L.fixed[3 * n] = L.fixed[3 * n + 1] = L.fixed[3 * n + 2] = 1;
  for (size_t k = 0; k < supports.dofs.size(); ++k) {
    if (supports.values[k] != 0)
      throw Error(ErrorCode::InvalidParameter,
                  "a support prescribes a non-zero displacement, which the distributed solver does not take: "
                  "run this job without mpirun");
    L.fixed[supports.dofs[k]] = 1;
  }
  d.nodes_per_rank.assign(ranks, 0);
  for (long n = 0; n < nv; ++n) ++d.nodes_per_rank[L.owner[n]];
  L.begin.assign(ranks + 1, 0);
  for (int r = 0; r < ranks; ++r) L.begin[r + 1] = L.begin[r] + d.nodes_per_rank[r];
  L.global.assign(nv, 0);
  d.serial_node.assign(nv, 0);
  std::vector<long> next(L.begin.begin(), L.begin.end() - 1);
  for (long n = 0; n < nv; ++n) {
    L.global[n] = static_cast<int>(next[L.owner[n]]++);
    d.serial_node[L.global[n]] = static_cast<int>(n);
  }
  return L;
}

/// Rank r's tets, owned nodes and ghosts. `local` (#V, all -1) is scratch, left all -1;
/// serial_node: the serial node of each global one.
Package make_package(const TetMesh& mesh, const std::vector<int>& tets, const Layout& L, int r,
                     const std::vector<int>& serial_node, const Eigen::MatrixXd& loads, std::vector<int>& local) {
  Package p;
  std::vector<long> ghosts;
  for (int t : tets)
    for (int a = 0; a < 4; ++a)
      if (L.owner[mesh.T(t, a)] != r) ghosts.push_back(L.global[mesh.T(t, a)]);
  std::sort(ghosts.begin(), ghosts.end());
  ghosts.erase(std::unique(ghosts.begin(), ghosts.end()), ghosts.end());
  const long owned = L.begin[r + 1] - L.begin[r];
  p.node_global.resize(owned);
  std::iota(p.node_global.begin(), p.node_global.end(), L.begin[r]);
  p.node_global.insert(p.node_global.end(), ghosts.begin(), ghosts.end());
  for (size_t i = 0; i < p.node_global.size(); ++i) {
    const int n = serial_node[p.node_global[i]];
    local[n] = static_cast<int>(i);
    for (int c = 0; c < 3; ++c) p.V.push_back(mesh.V(n, c)), p.fixed.push_back(L.fixed[3 * n + c]);
  }
  for (long k = 0; k < loads.cols(); ++k)
    for (long i = 0; i < owned; ++i)
      for (int c = 0; c < 3; ++c) p.loads.push_back(loads(3 * serial_node[p.node_global[i]] + c, k));
  for (int t : tets) {
    for (int a = 0; a < 4; ++a) p.T.push_back(local[mesh.T(t, a)]);
    p.domain.push_back(mesh.domain.size() ? mesh.domain[t] : 0);
    p.tet_serial.push_back(t);
  }
  for (long g : p.node_global) local[serial_node[g]] = -1;
  p.header = {owned, L.begin[r], static_cast<long>(mesh.V.rows()), static_cast<long>(mesh.T.rows()),
              static_cast<long>(loads.cols())};
  return p;
}

void send_package(MPI_Comm comm, int dest, const Package& p) {
  send_vector(comm, dest, p.header);
  send_vector(comm, dest, p.V);
  send_vector(comm, dest, p.loads);
  send_vector(comm, dest, p.T);
  send_vector(comm, dest, p.domain);
  send_vector(comm, dest, p.node_global);
  send_vector(comm, dest, p.tet_serial);
  send_vector(comm, dest, p.fixed);
}

Package receive_package(MPI_Comm comm) {
  Package p;
  p.header = receive_vector<long>(comm);
  p.V = receive_vector<double>(comm);
  p.loads = receive_vector<double>(comm);
  p.T = receive_vector<int>(comm);
  p.domain = receive_vector<int>(comm);
  p.node_global = receive_vector<long>(comm);
  p.tet_serial = receive_vector<long>(comm);
  p.fixed = receive_vector<char>(comm);
  return p;
}

/// The package unpacked into d's per-rank fields.
void unpack(Package&& p, DistMesh& d) {
  d.owned_nodes = static_cast<int>(p.header[0]);
  d.node_begin = p.header[1];
  d.total_nodes = p.header[2];
  d.total_tets = p.header[3];
  const long cases = p.header[4];
  const long nl = static_cast<long>(p.node_global.size()), nt = static_cast<long>(p.domain.size());
  d.local.V = Eigen::Map<const MatX3d>(p.V.data(), nl, 3);
  d.local.T = Eigen::Map<const MatX4i>(p.T.data(), nt, 4);
  d.local.domain = Eigen::Map<const VecXi>(p.domain.data(), nt);
  d.loads = Eigen::Map<const Eigen::MatrixXd>(p.loads.data(), 3 * d.owned_nodes, cases);
  d.node_global = std::move(p.node_global);
  d.tet_serial = std::move(p.tet_serial);
  d.fixed = std::move(p.fixed);
}

}  // namespace

DistMesh distribute_mesh(const MpiSession& session, const TetMesh& mesh, const std::vector<int>& part,
                         const fem::Supports& supports, const Eigen::MatrixXd& loads) {
  DistMesh d;
  if (session.rank() != 0) {
    unpack(receive_package(session.comm()), d);
    return d;
  }
  const int ranks = session.size();
  const Layout layout = make_layout(mesh, part, supports, ranks, d);
  std::vector<std::vector<int>> tets(ranks);
  for (long t = 0; t < mesh.T.rows(); ++t) tets[part[t]].push_back(static_cast<int>(t));
  std::vector<int> scratch(mesh.V.rows(), -1);
  for (int r = ranks - 1; r >= 0; --r) {
    d.tets_per_rank.insert(d.tets_per_rank.begin(), static_cast<int>(tets[r].size()));
    Package p = make_package(mesh, tets[r], layout, r, d.serial_node, loads, scratch);
    if (r > 0)
      send_package(session.comm(), r, p);
    else
      unpack(std::move(p), d);
  }
  for (const auto& list : tets) d.gathered_tets.insert(d.gathered_tets.end(), list.begin(), list.end());
  return d;
}

VecXd gather_tets(const MpiSession& session, const DistMesh& mesh, const VecXd& local) {
  const bool root = session.rank() == 0;
  std::vector<int> offsets;
  VecXd all(root ? mesh.total_tets : 0);
  if (root) {
    offsets.assign(session.size(), 0);
    for (int r = 1; r < session.size(); ++r) offsets[r] = offsets[r - 1] + mesh.tets_per_rank[r - 1];
  }
  MPI_Gatherv(local.data(), static_cast<int>(local.size()), MPI_DOUBLE, all.data(),
              root ? mesh.tets_per_rank.data() : nullptr, root ? offsets.data() : nullptr, MPI_DOUBLE, 0,
              session.comm());
  if (!root) return VecXd();
  VecXd serial(mesh.total_tets);
  for (long i = 0; i < mesh.total_tets; ++i) serial[mesh.gathered_tets[i]] = all[i];
  return serial;
}

Eigen::MatrixXd gather_nodes(const MpiSession& session, const DistMesh& mesh, const Eigen::MatrixXd& owned) {
  const bool root = session.rank() == 0;
  std::vector<int> counts, offsets;
  if (root) {
    counts.assign(session.size(), 0);
    offsets.assign(session.size(), 0);
    for (int r = 0; r < session.size(); ++r) counts[r] = 3 * mesh.nodes_per_rank[r];
    for (int r = 1; r < session.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  }
  Eigen::MatrixXd serial(root ? 3 * mesh.total_nodes : 0, owned.cols());
  VecXd all(root ? 3 * mesh.total_nodes : 0);
  for (long k = 0; k < owned.cols(); ++k) {
    const VecXd column = owned.col(k);
    MPI_Gatherv(column.data(), static_cast<int>(column.size()), MPI_DOUBLE, all.data(), root ? counts.data() : nullptr,
                root ? offsets.data() : nullptr, MPI_DOUBLE, 0, session.comm());
    if (root)
      for (long g = 0; g < mesh.total_nodes; ++g)
        serial.block<3, 1>(3 * mesh.serial_node[g], k) = all.segment<3>(3 * g);
  }
  return serial;
}

}  // namespace topopt::dist
