// The volume fill's working formats — tets and triangles as arrays of node indices into a
// vector of points — and the node stars over them: the tets around each node as one flat
// array (CSR), built on demand and rebuilt when the tets change (DESIGN.md: adjacency in
// separate arrays, no per-node vectors).
#pragma once
#include <array>
#include <vector>

#include "common/adjacency.h"

namespace topopt::mesh {

using Tet = std::array<int, 4>;  ///< node indices, positively oriented
using Tri = std::array<int, 3>;  ///< node indices

/// The tets around each node as the code base's one adjacency type: row v holds the tets of
/// node v, ascending. nodes: #P (every index in tets below it); tets: #T tets, removed ones
/// (t[0] < 0) left out.
inline Adjacency node_stars(size_t nodes, const std::vector<Tet>& tets) {
  return group_pairs(static_cast<int>(nodes), [&tets](auto emit) {
    for (size_t t = 0; t < tets.size(); ++t)
      if (tets[t][0] >= 0)
        for (int x : tets[t]) emit(x, static_cast<int>(t));
  });
}

}  // namespace topopt::mesh
