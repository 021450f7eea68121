// Morton-order renumbering of a tet mesh (see reorder.h).
#include "mesh/core/reorder.h"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <vector>

namespace topopt::mesh {
namespace {

/// Spreads the low 21 bits of v so that bit k lands on bit 3k.
uint64_t spread_bits(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

struct MortonCoder {
  Eigen::RowVector3d lo, scale;
  explicit MortonCoder(const MatX3d& V) {
    lo = V.colwise().minCoeff();
    Eigen::RowVector3d ext = V.colwise().maxCoeff() - lo;
    const double e = std::max(ext.maxCoeff(), 1e-300);
    scale.setConstant(static_cast<double>((1 << 21) - 1) / e);
  }
  uint64_t operator()(const Eigen::RowVector3d& p) const {
    uint64_t code = 0;
    for (int c = 0; c < 3; ++c) {
      double q = std::clamp((p[c] - lo[c]) * scale[c], 0.0, static_cast<double>((1 << 21) - 1));
      code |= spread_bits(static_cast<uint64_t>(q)) << c;
    }
    return code;
  }
};

/// Indices 0..n-1 sorted by key (stable, so equal keys keep their order).
std::vector<int> sorted_by(const std::vector<uint64_t>& key) {
  std::vector<int> order(key.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  return order;
}

}  // namespace

VecXi reorder_for_locality(TetMesh& mesh) {
  const long nv = mesh.V.rows(), nt = mesh.T.rows();
  VecXi new_id(nv);
  if (nv == 0) return new_id;
  const MortonCoder code(mesh.V);
  std::vector<uint64_t> key(nv);
  for (long i = 0; i < nv; ++i) key[i] = code(mesh.V.row(i));
  const std::vector<int> order = sorted_by(key);
  MatX3d V(nv, 3);
  for (long k = 0; k < nv; ++k) {
    V.row(k) = mesh.V.row(order[k]);
    new_id[order[k]] = static_cast<int>(k);
  }
  mesh.V = std::move(V);
  for (long t = 0; t < nt; ++t)
    for (int a = 0; a < 4; ++a) mesh.T(t, a) = new_id[mesh.T(t, a)];
  for (long f = 0; f < mesh.F.rows(); ++f)
    for (int a = 0; a < 3; ++a) mesh.F(f, a) = new_id[mesh.F(f, a)];
  // Tets by their centroids' codes, tags alongside.
  std::vector<uint64_t> tkey(nt);
  for (long t = 0; t < nt; ++t)
    tkey[t] = code(0.25 * (mesh.V.row(mesh.T(t, 0)) + mesh.V.row(mesh.T(t, 1)) + mesh.V.row(mesh.T(t, 2)) +
                           mesh.V.row(mesh.T(t, 3))));
  const std::vector<int> torder = sorted_by(tkey);
  MatX4i T(nt, 4);
  VecXi domain(mesh.domain.size());
  for (long k = 0; k < nt; ++k) {
    T.row(k) = mesh.T.row(torder[k]);
    if (mesh.domain.size() == nt) domain[k] = mesh.domain[torder[k]];
  }
  mesh.T = std::move(T);
  if (mesh.domain.size() == nt) mesh.domain = std::move(domain);
  return new_id;
}

}  // namespace topopt::mesh
