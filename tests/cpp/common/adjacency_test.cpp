// Compressed rows: grouping keeps the emission order within a row, sorting compacts rows in
// place, and rows are read back as ranges.
#include "common/adjacency.h"

#include <gtest/gtest.h>

#include <array>

namespace topopt {
namespace {

std::vector<int> row_of(const Adjacency& a, int i) { return std::vector<int>(a.begin(i), a.end(i)); }

TEST(Adjacency, GroupPairsKeepsTheEmissionOrderWithinRows) {
  // the tets around each node of two tets sharing the face (1, 2, 3), plus an unused node 5
  const std::vector<std::array<int, 4>> tets = {{0, 1, 2, 3}, {4, 3, 2, 1}};
  int calls = 0;
  const Adjacency stars = group_pairs(6, [&](auto emit) {
    ++calls;
    for (int t = 0; t < 2; ++t)
      for (int v : tets[t]) emit(v, t);
  });
  EXPECT_EQ(calls, 2);  // one counting pass, one filling pass
  ASSERT_EQ(stars.rows(), 6);
  EXPECT_EQ(row_of(stars, 0), std::vector<int>({0}));
  EXPECT_EQ(row_of(stars, 2), std::vector<int>({0, 1}));
  EXPECT_EQ(row_of(stars, 4), std::vector<int>({1}));
  EXPECT_EQ(stars.size(5), 0);
  EXPECT_EQ(stars.offset.back(), 8);
  // emission order, not sorted order, within a row
  const Adjacency reversed = group_pairs(1, [](auto emit) {
    for (int x : {7, 3, 5}) emit(0, x);
  });
  EXPECT_EQ(row_of(reversed, 0), std::vector<int>({7, 3, 5}));
}

TEST(Adjacency, SortUniqueRowsCompactsEveryRow) {
  Adjacency a;
  a.push_row({3, 1, 3, 2});
  a.push_row({});
  a.push_row({5, 5, 5});
  a.push_row({9, 0});
  sort_unique_rows(a);
  ASSERT_EQ(a.rows(), 4);
  EXPECT_EQ(row_of(a, 0), std::vector<int>({1, 2, 3}));
  EXPECT_EQ(a.size(1), 0);
  EXPECT_EQ(row_of(a, 2), std::vector<int>({5}));
  EXPECT_EQ(row_of(a, 3), std::vector<int>({0, 9}));
  EXPECT_EQ(a.index.size(), 6u);
  EXPECT_EQ(a.offset, std::vector<int>({0, 3, 3, 4, 6}));
}

TEST(Adjacency, RowsAreRangesAndRowsCanBeBuiltInPlace) {
  Adjacency a;
  a.index.push_back(4);
  a.index.push_back(2);
  a.close_row();
  a.close_row();  // an empty row
  a.push_row({8});
  ASSERT_EQ(a.rows(), 3);
  int sum = 0;
  for (int x : a.row(0)) sum += x;
  EXPECT_EQ(sum, 6);
  EXPECT_EQ(a.row(0).size(), 2);
  EXPECT_EQ(a.row(1).size(), 0);
  EXPECT_EQ(*a.row(2).begin(), 8);
}

}  // namespace
}  // namespace topopt
