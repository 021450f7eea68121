// Connected pieces of a set of tets (see tet_components.h).
#include "mesh/core/tet_components.h"

#include "common/adjacency.h"

namespace topopt::mesh {

namespace {

/// Labels the masked tets (#T) by connected piece, 0 .. count-1 (unmasked: -1), by flood fill;
/// each_neighbour(t, visit) calls visit(n) for the tets n next to tet t.
template <class EachNeighbour>
VecXi flood_labels(long nt, const std::vector<char>& mask, int& count, const EachNeighbour& each_neighbour) {
  VecXi label = VecXi::Constant(nt, -1);
  count = 0;
  std::vector<int> stack;
  for (long s = 0; s < nt; ++s) {
    if (!mask[s] || label[s] >= 0) continue;
    label[s] = count;
    stack.assign(1, static_cast<int>(s));
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      each_neighbour(t, [&](int n) {
        if (mask[n] && label[n] < 0) label[n] = count, stack.push_back(n);
      });
    }
    ++count;
  }
  return label;
}

}  // namespace

VecXi node_components(const TetMesh& mesh, const std::vector<char>& mask, int& count) {
  // the masked tets around each node
  const Adjacency around = group_pairs(static_cast<int>(mesh.V.rows()), [&](auto emit) {
    for (long t = 0; t < mesh.T.rows(); ++t)
      if (mask[t])
        for (int k = 0; k < 4; ++k) emit(mesh.T(t, k), static_cast<int>(t));
  });
  return flood_labels(mesh.T.rows(), mask, count, [&](int t, const auto& visit) {
    for (int k = 0; k < 4; ++k)
      for (int n : around.row(mesh.T(t, k))) visit(n);
  });
}

VecXi tet_components(const MatX4i& neighbours, const std::vector<char>& mask, int& count) {
  return flood_labels(neighbours.rows(), mask, count, [&](int t, const auto& visit) {
    for (int k = 0; k < 4; ++k)
      if (neighbours(t, k) >= 0) visit(neighbours(t, k));
  });
}

}  // namespace topopt::mesh
