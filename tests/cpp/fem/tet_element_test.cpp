// The element kernels of fem/tet_element.h: the upper-triangle stiffness that assembly uses
// against the full 12 by 12 one, and its two scatters into K's layout against each other.
#include "fem/tet_element.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace topopt::fem {
namespace {

TEST(TetElement, UpperTriangleIsTheFullStiffnessToTheBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 50; ++trial) {
    double g[12];
    for (double& v : g) v = u(rng);
    const double vol = 0.1 + std::abs(u(rng)), lambda = 1e5 * (1 + std::abs(u(rng))), mu = 8e4;
    double full[144], upper[78];
    element_stiffness(g, vol, lambda, mu, full);
    element_stiffness_upper(g, vol, lambda, mu, upper);
    int k = 0;
    for (int i = 0; i < 12; ++i)
      for (int j = i; j < 12; ++j, ++k) ASSERT_EQ(upper[k], full[12 * i + j]) << "entry " << i << ", " << j;
    ASSERT_EQ(k, 78);
  }
}

TEST(TetElement, FreeElementScatterEqualsTheEntryByEntryOneToTheBit) {
  // A tet's four nodes in a matrix laid out as K is (node blocks of 3 rows sharing their columns),
  // each row also holding columns of other nodes around them: both scatters add the same values to
  // the same entries, and the matrix is the element's full stiffness (its upper triangle mirrored).
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  const int order[4] = {2, 0, 3, 1};  // the tet's nodes among the matrix's 5 nodes (node 4: none)
  const int len = 15, rows = 15;      // 5 nodes × 3 dofs, every row reaching every column
  int dof[12], first[4], lens[4], at[16];
  for (int a = 0; a < 4; ++a) {
    first[a] = 3 * order[a], lens[a] = len;
    for (int i = 0; i < 3; ++i) dof[3 * a + i] = 3 * order[a] + i;
    for (int b = 0; b < 4; ++b) at[4 * a + b] = len * 3 * order[a] + 3 * order[b];
  }
  for (int trial = 0; trial < 20; ++trial) {
    double g[12], full[144], upper[78];
    for (double& v : g) v = u(rng);
    const double vol = 0.1 + std::abs(u(rng)), lambda = 1e5 * (1 + std::abs(u(rng))), mu = 8e4;
    element_stiffness(g, vol, lambda, mu, full);
    element_stiffness_upper(g, vol, lambda, mu, upper);
    std::vector<double> by_entries(rows * len), by_blocks(rows * len);
    for (size_t k = 0; k < by_entries.size(); ++k) by_entries[k] = by_blocks[k] = u(rng);  // earlier tets
    add_element_upper(dof, first, lens, at, upper, by_entries.data());
    add_free_element_upper(lens, at, upper, by_blocks.data());
    ASSERT_EQ(by_blocks, by_entries);
    std::vector<double> alone(rows * len, 0.0);
    add_free_element_upper(lens, at, upper, alone.data());
    double largest = 0;  // the lower triangle is the full matrix's to its rounding (it sums other products)
    for (double v : full) largest = std::max(largest, std::abs(v));
    for (int I = 0; I < 12; ++I)
      for (int J = 0; J < 12; ++J) {
        const double k = alone[dof[I] * len + dof[J]];
        ASSERT_EQ(k, alone[dof[J] * len + dof[I]]);  // symmetric to the bit
        ASSERT_NEAR(k, full[12 * I + J], 1e-14 * largest);
        if (I <= J) {
          ASSERT_EQ(k, full[12 * I + J]);  // the upper triangle's value itself
        }
      }
  }
}

}  // namespace
}  // namespace topopt::fem
