// Steps 12-14 on a conformal surface mesh (see volume_steps.h).
#include "mesh/two_brep/volume_steps.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <string>

#include "common/error.h"
#include "common/parallel.h"

namespace topopt::mesh {
namespace {

/// The pool of nodes and tets the fills grow.
struct Pool {
  std::vector<std::array<double, 3>> nodes;
  std::vector<std::array<int, 4>> tets;
  std::vector<int> domain;
};

MatX3d matrix_of(const std::vector<std::array<double, 3>>& nodes) {
  MatX3d V(static_cast<long>(nodes.size()), 3);
  for (size_t i = 0; i < nodes.size(); ++i) V.row(static_cast<long>(i)) << nodes[i][0], nodes[i][1], nodes[i][2];
  return V;
}

/// One fill of the region bounded by F around the tets T0; a front that cannot close is
/// reported with `what` in front of its message.
VolumeFillResult fill(const MatX3d& V, const MatX3i& F, const MatX4i& T0, const VolumeFillParams& params,
                      const std::string& what, const Progress& progress) {
  try {
    return fill_volume(V, F, T0, params, progress);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::MeshingFailed) throw;
    throw Error(ErrorCode::MeshingFailed, what + ": " + e.what());
  }
}

/// A fill's new nodes join the pool and its tets the mesh, tagged `dom`. The fill ran on the
/// first n0 nodes of the pool (its rows from n0 on are its own new nodes).
void merge(Pool& pool, const VolumeFillResult& r, long n0, int dom) {
  const long offset = static_cast<long>(pool.nodes.size()) - n0;  // where these new nodes start, minus n0
  for (long k = n0; k < r.V.rows(); ++k) pool.nodes.push_back({r.V(k, 0), r.V(k, 1), r.V(k, 2)});
  for (long t = 0; t < r.T.rows(); ++t) {
    std::array<int, 4> tet;
    for (int c = 0; c < 4; ++c) tet[c] = static_cast<int>(r.T(t, c) < n0 ? r.T(t, c) : r.T(t, c) + offset);
    pool.tets.push_back(tet);
    pool.domain.push_back(dom);
  }
}

// Step 12: each non-design solid from its closed surface, in parallel (largest first) on the
// same snapshot of the pool; merged in input order.
void step12_fill_nondesign(Pool& pool, const std::vector<MatX3i>& nondesign, const VolumeFillParams& params,
                           int threads, const Progress& progress) {
  const int n = static_cast<int>(nondesign.size());
  if (n == 0) return;
  const MatX3d V = matrix_of(pool.nodes);
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return nondesign[a].rows() > nondesign[b].rows(); });
  std::vector<VolumeFillResult> results(n);
  parallel_tasks(order, thread_count(threads), progress, "volume meshing", [&](int i, const Progress& prog) {
    results[i] = fill(V, nondesign[i], MatX4i(), params, "non-design solid " + std::to_string(i + 1), prog);
  });
  progress.check_cancel("volume meshing");
  for (int i = 0; i < n; ++i) merge(pool, results[i], V.rows(), i + 1);
}

MatX4i tet_matrix(const std::vector<std::array<int, 4>>& tets) {
  MatX4i T(static_cast<long>(tets.size()), 4);
  for (size_t i = 0; i < tets.size(); ++i)
    T.row(static_cast<long>(i)) << tets[i][0], tets[i][1], tets[i][2], tets[i][3];
  return T;
}

// Step 13: Ω̄'s tets become tets already present in Ω (on the shared pool): the front of
// step 14 starts from their free faces.
MatX4i step13_transfer_tets(const Pool& pool) { return tet_matrix(pool.tets); }

// Step 14: the rest of Ω, from its boundary triangles plus the free faces of those tets.
void step14_fill_design(Pool& pool, const MatX3i& part, const MatX4i& T0, const VolumeFillParams& params,
                        const Progress& progress) {
  const MatX3d V = matrix_of(pool.nodes);
  merge(pool, fill(V, part, T0, params, "design domain", progress), V.rows(), 0);
}

}  // namespace

TwoBRepVolumes fill_two_brep_volumes(const MatX3d& V, const std::vector<MatX3i>& nondesign, const MatX3i& part,
                                     const VolumeFillParams& params, int threads, const Progress& progress) {
  Pool pool;
  pool.nodes.resize(static_cast<size_t>(V.rows()));
  for (long i = 0; i < V.rows(); ++i) pool.nodes[static_cast<size_t>(i)] = {V(i, 0), V(i, 1), V(i, 2)};
  step12_fill_nondesign(pool, nondesign, params, threads, progress);
  const auto t0 = std::chrono::steady_clock::now();
  step14_fill_design(pool, part, step13_transfer_tets(pool), params, progress);
  TwoBRepVolumes out;
  out.seconds_design = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  out.V = matrix_of(pool.nodes);
  out.T = tet_matrix(pool.tets);
  out.domain = Eigen::Map<const VecXi>(pool.domain.data(), static_cast<long>(pool.domain.size()));
  return out;
}

}  // namespace topopt::mesh
