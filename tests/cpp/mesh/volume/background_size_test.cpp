// The graded background size and the tet count a size asks for, on a box whose answers are
// known in closed form.
#include "mesh/volume/background_size.h"

#include <gtest/gtest.h>

#include <cmath>

#include "io/msh.h"
#include "mesh/core/structured_box.h"

namespace topopt::mesh {
namespace {

/// The surface of a structured box of side `side` with `cells` cells per side (spacing
/// side / cells on every face), outward, on the box's own node numbering.
void box_surface(double side, int cells, MatX3d& V, MatX3i& F) {
  StructuredBoxParams p;
  p.size = {side, side, side};
  p.cells = {cells, cells, cells};
  const TetMesh box = structured_box_mesh(p);
  V = box.V;
  F = io::boundary_triangles(box.T);
}

TEST(ExpectedTets, UniformSizeGivesVolumeOverTheRegularTet) {
  MatX3d V;
  MatX3i F;
  box_surface(10, 5, V, F);
  // 1000 mm³ of regular tets of edge 1 (volume 1/(6√2)): 8485
  const double n = expected_tets(V, F, [](const double*) { return 1.0; });
  EXPECT_NEAR(n, 1000 * 6 * std::sqrt(2.0), 0.02 * 8485);
}

TEST(ExpectedTets, GradedSizeMatchesTheIntegral) {
  MatX3d V;
  MatX3i F;
  box_surface(10, 5, V, F);
  // h = 1 + 0.1 x: 100 · 6√2 · ∫₀¹⁰ (1 + 0.1x)⁻³ dx = 100 · 6√2 · 5 · (1 − 1/4)
  const double n = expected_tets(V, F, [](const double* x) { return 1.0 + 0.1 * x[0]; });
  const double exact = 100 * 6 * std::sqrt(2.0) * 5 * 0.75;
  EXPECT_NEAR(n, exact, 0.02 * exact);
  // a region outside the surface counts nothing: the same box shifted away from a size that
  // is tiny only there changes nothing
  const double shifted = expected_tets(V, F, [](const double* x) { return x[0] > 10.5 ? 1e-3 : 1.0 + 0.1 * x[0]; });
  EXPECT_NEAR(shifted, n, 1e-9 * n);
}

TEST(BackgroundSize, GrowsFromTheBoundarySpacingUpToTheCap) {
  MatX3d V;
  MatX3i F;
  box_surface(10, 10, V, F);  // boundary spacing: mean edge at a node, 1 to √2
  const BackgroundSize fine(V, F, 4.0, 0.3);
  const double centre[3] = {5, 5, 5}, near_face[3] = {5, 5, 0.5}, corner[3] = {0, 0, 0};
  // 5 mm from the nearest face: spacing + 0.3 · 5, within the grid's resolution (cells of 2)
  EXPECT_GT(fine.at(centre), 1.0 + 0.3 * 4.0);
  EXPECT_LT(fine.at(centre), 1.5 + 0.3 * 6.0);
  EXPECT_LT(fine.at(near_face), 1.5 + 0.3 * 1.5);
  EXPECT_LT(fine.at(corner), fine.at(centre));
  // the cap: a far-away coarse size stays at the cap, and a fast growth reaches it inside
  const BackgroundSize fast(V, F, 2.0, 2.0);
  EXPECT_NEAR(fast.at(centre), 2.0, 1e-6);
  // the box's inner nodes are on no triangle: no spacing; its boundary nodes: 1 to √2
  const std::vector<double> s = node_spacing(V, F);
  long on_boundary = 0;
  for (double x : s) {
    if (x == 0) continue;
    ++on_boundary;
    EXPECT_GE(x, 1.0 - 1e-12);
    EXPECT_LE(x, std::sqrt(2.0) + 1e-12);
  }
  EXPECT_EQ(on_boundary, 11 * 11 * 11 - 9 * 9 * 9);
}

}  // namespace
}  // namespace topopt::mesh
