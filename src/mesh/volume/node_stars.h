// The volume fill's working formats — tets and triangles as arrays of node indices into a
// vector of points — and the node stars over them: the tets around each node as one flat
// array (CSR), built on demand and rebuilt when the tets change (DESIGN.md: adjacency in
// separate arrays, no per-node vectors).
#pragma once
#include <array>
#include <vector>

namespace topopt::mesh {

using Tet = std::array<int, 4>;  ///< node indices, positively oriented
using Tri = std::array<int, 3>;  ///< node indices

/// The tets around each node: the tets of node v are items[start[v] .. start[v + 1]),
/// ascending. Removed tets (first index < 0) are left out.
class NodeStars {
 public:
  /// nodes: #P (every index in tets below it); tets: #T tets, removed ones with t[0] < 0.
  NodeStars(size_t nodes, const std::vector<Tet>& tets) : start_(nodes + 1, 0) {
    for (const Tet& t : tets)
      if (t[0] >= 0)
        for (int x : t) ++start_[x + 1];
    for (size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
    items_.resize(start_.back());
    std::vector<int> next(start_.begin(), start_.end() - 1);
    for (size_t t = 0; t < tets.size(); ++t)
      if (tets[t][0] >= 0)
        for (int x : tets[t]) items_[next[x]++] = static_cast<int>(t);
  }
  /// A node's tets, for range-for.
  struct Range {
    const int *b, *e;
    const int* begin() const { return b; }
    const int* end() const { return e; }
  };
  /// The tets of node v (ascending; empty for a node no tet uses).
  Range of(int v) const { return {items_.data() + start_[v], items_.data() + start_[v + 1]}; }

 private:
  std::vector<int> start_, items_;
};

}  // namespace topopt::mesh
