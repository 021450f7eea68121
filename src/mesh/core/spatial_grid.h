// Spatial search by a multi-level hashed grid of boxes, in 2 or 3 dimensions: "which items may
// meet this box?" for items that come and go (the 3D front's faces and nodes, whose dead
// entries are dropped lazily by the queries that meet them) and for fixed point sets (a face's
// fine boundary points, looked up by a const visit).
//
// An item goes to the level whose cells are at least as large as it (level k has cells of
// base·2^k), so it sits in at most 2^Dim cells and the buckets stay small where the sizes are
// graded from tiny to large. Every level also counts its non-empty cells per block of 16^Dim
// cells: a query visits, on each level holding items, either the cells overlapping its box
// (at most 64 of them) or the occupied blocks overlapping it, so a large box over a fine level
// costs its occupied blocks, not its cells. Answers are candidates: every item whose box meets
// the query box is among them, and the caller tests the geometry.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace topopt::mesh {

template <int Dim>
class SpatialGrid {
  static_assert(Dim == 2 || Dim == 3, "SpatialGrid is for the plane and for space");

 public:
  /// origin: Dim coordinates from which cells are counted; base: the edge of level 0's cells
  /// (> 0; the smallest items' size: finer costs memory, coarser costs longer buckets).
  SpatialGrid(const double* origin, double base) : base_(base) { std::copy(origin, origin + Dim, origin_.begin()); }

  /// Registers item `id` (>= 0) with the box [lo, hi] (Dim coordinates each); `size`, when
  /// larger than the box's largest extent, chooses a coarser level (an item that should be
  /// found from as far as a neighbour of that size). An id may be registered only once.
  void insert(int id, const double* lo, const double* hi, double size = 0) {
    double ext = size;
    for (int d = 0; d < Dim; ++d) ext = std::max(ext, hi[d] - lo[d]);
    int k = 0;
    while (k < 48 && base_ * std::ldexp(1.0, k) < ext) ++k;
    while (static_cast<int>(levels_.size()) <= k)
      levels_.emplace_back(1.0 / (base_ * std::ldexp(1.0, static_cast<int>(levels_.size()))));
    Level& L = levels_[k];
    for_cells(L.cell(lo, origin_), L.cell(hi, origin_), [&](const Cell& c) {
      std::vector<int>& ids = L.buckets[key(c)];
      if (ids.empty()) {
        Block& bl = L.blocks[key(block_of(c))];
        bl.at = block_of(c);
        ++bl.cells;
      }
      ids.push_back(id);
    });
    max_id_ = std::max(max_id_, id);
  }

  /// Appends to `out` (not cleared) the ids registered in cells overlapping [lo, hi] for which
  /// keep(id) holds, each once, in the order of the levels, then of the cells (last
  /// coordinate fastest), then of insertion. Ids for which keep(id) fails are dropped from the
  /// cells visited (so they must never be wanted again); a cell left empty is freed.
  template <class Keep>
  void query(const double* lo, const double* hi, std::vector<int>& out, Keep&& keep) {
    if (stamp_.size() <= static_cast<size_t>(max_id_)) stamp_.resize(max_id_ + max_id_ / 2 + 16, 0);
    if (++ticket_ == 0) std::fill(stamp_.begin(), stamp_.end(), 0), ticket_ = 1;  // the stamps wrapped round
    scan(*this, lo, hi, [&](Level& L, const Cell& c) {
      auto it = L.buckets.find(key(c));
      if (it == L.buckets.end()) return;
      std::vector<int>& ids = it->second;
      size_t w = 0;
      for (size_t r = 0; r < ids.size(); ++r) {
        const int id = ids[r];
        if (!keep(id)) continue;
        ids[w++] = id;
        if (stamp_[id] != ticket_) stamp_[id] = ticket_, out.push_back(id);
      }
      ids.resize(w);
      if (w == 0) {  // the cell emptied: its block counts one occupied cell less
        L.buckets.erase(it);
        auto bl = L.blocks.find(key(block_of(c)));
        if (bl != L.blocks.end() && --bl->second.cells <= 0) L.blocks.erase(bl);
      }
    });
  }

  /// Calls visit(id) for every id registered in a cell overlapping [lo, hi], in the order of
  /// query(); an item spanning several such cells is visited once per cell (a point: once).
  /// Leaves the grid as it is (safe to call from several threads at once).
  template <class Visit>
  void for_each(const double* lo, const double* hi, Visit&& visit) const {
    scan(*this, lo, hi, [&](const Level& L, const Cell& c) {
      auto it = L.buckets.find(key(c));
      if (it != L.buckets.end())
        for (int id : it->second) visit(id);
    });
  }

 private:
  using Cell = std::array<long, Dim>;
  struct Block {
    Cell at{};      ///< the block's coordinates (its cells' >> 4)
    int cells = 0;  ///< its non-empty cells
  };
  struct Level {
    explicit Level(double inv_cell) : inv(inv_cell) {}
    double inv;                                              ///< 1 / the cell's edge
    std::unordered_map<uint64_t, std::vector<int>> buckets;  ///< ids per non-empty cell
    std::unordered_map<uint64_t, Block> blocks;              ///< the occupied blocks of 16^Dim cells
    Cell cell(const double* p, const std::array<double, Dim>& o) const {
      Cell c;
      for (int d = 0; d < Dim; ++d) c[d] = static_cast<long>(std::floor((p[d] - o[d]) * inv));
      return c;
    }
  };

  static constexpr int kBits = 64 / Dim;  ///< bits of each cell coordinate in a key
  /// Distinct cells give distinct keys while |coordinates| < 2^(kBits - 1) cells; beyond, two
  /// cells may share a bucket, which only costs time (callers test the geometry).
  static uint64_t key(const Cell& c) {
    const uint64_t m = (kBits == 64 ? ~0ull : (1ull << kBits) - 1);
    uint64_t k = 0;
    for (int d = 0; d < Dim; ++d) k = (k << kBits) | (static_cast<uint64_t>(c[d]) & m);
    return k;
  }
  static Cell block_of(const Cell& c) {
    Cell b;
    for (int d = 0; d < Dim; ++d) b[d] = c[d] >> 4;
    return b;
  }

  /// Calls f(c) for every cell c with a <= c <= b, the last coordinate running fastest.
  template <class F>
  static void for_cells(const Cell& a, const Cell& b, F&& f) {
    if constexpr (Dim == 2) {
      for (long x = a[0]; x <= b[0]; ++x)
        for (long y = a[1]; y <= b[1]; ++y) f(Cell{x, y});
    } else {
      for (long x = a[0]; x <= b[0]; ++x)
        for (long y = a[1]; y <= b[1]; ++y)
          for (long z = a[2]; z <= b[2]; ++z) f(Cell{x, y, z});
    }
  }

  /// The occupied blocks of level L overlapping blocks [ba, bb], in the order of for_cells:
  /// found by walking the box's blocks or, when the box holds more blocks than the level has
  /// occupied ones (a wide query over a fine level: a surface with a few tiny triangles puts
  /// their nodes on a level whose cells are 10^-4 of the others, and a query box of the usual
  /// size then spans ~10^9 of its blocks), by filtering the occupied ones and sorting them.
  static void blocks_in(const Level& L, const Cell& ba, const Cell& bb, std::vector<Cell>& out) {
    out.clear();
    double in_box = 1;
    for (int d = 0; d < Dim; ++d) in_box *= static_cast<double>(bb[d] - ba[d] + 1);
    if (in_box <= static_cast<double>(L.blocks.size())) {
      for_cells(ba, bb, [&](const Cell& blk) {
        if (L.blocks.count(key(blk))) out.push_back(blk);
      });
      return;
    }
    for (const auto& kv : L.blocks) {
      const Cell& blk = kv.second.at;
      bool inside = true;
      for (int d = 0; d < Dim; ++d) inside = inside && blk[d] >= ba[d] && blk[d] <= bb[d];
      if (inside) out.push_back(blk);
    }
    std::sort(out.begin(), out.end());
  }

  /// Calls on_cell(level, cell) for the cells overlapping [lo, hi] on every level holding
  /// items: all of them when they are few, else those inside the level's occupied blocks
  /// (blocks_in: at most as many blocks looked at as the level has occupied).
  template <class Self, class OnCell>
  static void scan(Self& self, const double* lo, const double* hi, OnCell&& on_cell) {
    std::vector<Cell> blocks;
    for (auto& L : self.levels_) {
      if (L.blocks.empty()) continue;
      const Cell a = L.cell(lo, self.origin_), b = L.cell(hi, self.origin_);
      double cells = 1;
      for (int d = 0; d < Dim; ++d) cells *= static_cast<double>(b[d] - a[d] + 1);
      if (cells <= 64) {
        for_cells(a, b, [&](const Cell& c) { on_cell(L, c); });
        continue;
      }
      blocks_in(L, block_of(a), block_of(b), blocks);
      for (const Cell& blk : blocks) {
        Cell ca, cb;
        for (int d = 0; d < Dim; ++d) ca[d] = std::max(a[d], blk[d] << 4), cb[d] = std::min(b[d], (blk[d] << 4) + 15);
        for_cells(ca, cb, [&](const Cell& c) { on_cell(L, c); });
      }
    }
  }

  std::array<double, Dim> origin_;
  double base_;
  std::vector<Level> levels_;
  int max_id_ = -1;
  std::vector<unsigned> stamp_;  ///< stamp_[id] == ticket_: id already taken by this query
  unsigned ticket_ = 0;
};

}  // namespace topopt::mesh
