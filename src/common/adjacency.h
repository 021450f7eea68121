// Compressed rows of integers: the one adjacency type of the code base. B-Rep topology tables
// (a face's edges, a solid's faces), a mesh's node graph, the tets around each node, the
// multigrid's strength graph and aggregates are all "row i relates to these entities", stored
// as two flat arrays (DESIGN.md: flat arrays, adjacency built on demand in separate arrays).
//
// A sparse matrix is not an Adjacency: it carries values, a column count and row blocks, and
// its kernels are matrix algebra (fem/amg.h's CsrMatrix; a PETSc Mat in the distributed path).
#pragma once
#include <algorithm>
#include <vector>

namespace topopt {

/// Compressed rows: the entities related to entity i are index[offset[i] .. offset[i+1]).
struct Adjacency {
  std::vector<int> offset{0};  ///< rows()+1 offsets into `index`, the first 0
  std::vector<int> index;      ///< the related entities, row after row

  /// One row, iterable with a range-for.
  struct Row {
    const int* first;
    const int* last;
    const int* begin() const { return first; }
    const int* end() const { return last; }
    int size() const { return static_cast<int>(last - first); }
  };

  int rows() const { return static_cast<int>(offset.size()) - 1; }
  int size(int i) const { return offset[i + 1] - offset[i]; }
  const int* begin(int i) const { return index.data() + offset[i]; }
  const int* end(int i) const { return index.data() + offset[i + 1]; }
  Row row(int i) const { return {begin(i), end(i)}; }

  /// Appends a row holding `entities` in their order.
  void push_row(const std::vector<int>& entities) {
    index.insert(index.end(), entities.begin(), entities.end());
    close_row();
  }
  /// Ends the row whose entities were appended to `index` since the last row ended.
  void close_row() { offset.push_back(static_cast<int>(index.size())); }
};

/// Groups (row, entity) pairs into compressed rows (a counting sort, two passes over the same
/// pairs). `each_pair(emit)` must call emit(row, entity) for every pair, row in [0, rows), and
/// emit the same pairs in the same order both times it is called. Within a row the entities
/// keep the order they were emitted in.
/// Example: the tets around each node of T (#T by 4):
///   group_pairs(#V, [&](auto emit) { for t, for a: emit(T(t, a), t); })
template <class EachPair>
Adjacency group_pairs(int rows, const EachPair& each_pair) {
  Adjacency a;
  a.offset.assign(static_cast<size_t>(rows) + 1, 0);
  each_pair([&a](int row, int) { ++a.offset[row + 1]; });
  for (int i = 0; i < rows; ++i) a.offset[i + 1] += a.offset[i];
  a.index.resize(a.offset[rows]);
  std::vector<int> fill(a.offset.begin(), a.offset.end() - 1);
  each_pair([&a, &fill](int row, int entity) { a.index[fill[row]++] = entity; });
  return a;
}

/// Sorts every row of `a` and drops repeated entities within a row (in place; the rows are
/// compacted, their number stays).
inline void sort_unique_rows(Adjacency& a) {
  int out = 0;
  for (int i = 0; i < a.rows(); ++i) {
    auto b = a.index.begin() + a.offset[i], e = a.index.begin() + a.offset[i + 1];
    std::sort(b, e);
    auto last = std::unique(b, e);
    const auto dest = a.index.begin() + out;
    if (dest != b) std::copy(b, last, dest);  // dest lies before b: a forward copy is safe
    a.offset[i] = out;
    out += static_cast<int>(last - b);
  }
  a.offset[a.rows()] = out;
  a.index.resize(out);
}

}  // namespace topopt
