// A fixture shared by the result tests: a smooth density field of a round bar between two
// non-design blocks, on a structured tet mesh of a box.
#pragma once
#include <cmath>
#include <functional>

#include "common/types.h"
#include "mesh/core/structured_box.h"
#include "result/verification.h"
#include "simp/density_filter.h"

namespace topopt::testing {

struct BarField {
  TetMesh mesh;   ///< 40x20x10 mm box in 2 mm cells, domain 1 and 2 the end blocks
  VecXd density;  ///< #T: 1 in the blocks, ≈ 1 inside the bar, ≈ 0 outside
};

/// The box [0, 40] x [0, 20] x [0, 10] with non-design blocks x in [0, first_block_end] and
/// [36, 40] (y in [6, 14], z in [2, 8]) and, between them, a bar along x through (y, z) =
/// (10, 5) of radius radius(x) mm: density 1 / (1 + exp(2 (r − radius(x)))) at each tet's
/// centroid, r its distance from the bar's axis.
inline BarField bar_field(double first_block_end, const std::function<double(double)>& radius) {
  mesh::StructuredBoxParams p;
  p.size = {40, 20, 10};
  p.cells = {20, 10, 5};
  p.nondesign = {{0, 6, 2, first_block_end, 14, 8}, {36, 6, 2, 40, 14, 8}};
  BarField b;
  b.mesh = mesh::structured_box_mesh(p);
  const MatX3d c = simp::tet_centroids(b.mesh);
  b.density.resize(b.mesh.T.rows());
  for (long t = 0; t < b.mesh.T.rows(); ++t) {
    const double r = std::hypot(c(t, 1) - 10, c(t, 2) - 5);
    b.density[t] = b.mesh.domain[t] ? 1.0 : 1.0 / (1.0 + std::exp(2.0 * (r - radius(c(t, 0)))));
  }
  return b;
}

/// The varying radius 3.5 + 1.5 sin(x / 6) mm the iso-surface tests use.
inline double wavy_radius(double x) { return 3.5 + 1.5 * std::sin(x / 6); }

/// The result tests' load case: Ω's Face1 (x = 0) fixed, 100 N down (−z) on non-design face
/// `nd_face` (the far block's end face).
inline result::VerificationProblem fixed_at_face1_pulled_down_on(int nd_face) {
  fem::SupportSpec fixed;
  fixed.faces = {1};
  fem::LoadSpec down;
  down.vector = {0, 0, -100};
  down.nd_faces = {nd_face};
  result::VerificationProblem problem;
  problem.supports = {fixed};
  problem.load_cases = {{"down", {down}, 1.0}};
  return problem;
}

}  // namespace topopt::testing
