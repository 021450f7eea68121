// The structured test beam of the SIMP control tests: 30 × 10 × 10 mm centred on the x axis,
// fixed at x = 0 (Face1), a non-design load pad at x in [28, 30] pulled on its end face (Face2).
#pragma once
#include <array>

#include "fem/boundary_conditions.h"
#include "fem/elasticity.h"
#include "mesh/core/structured_box.h"

namespace topopt::simp {

struct TestBeam {
  mesh::StructuredBoxParams box;
  TetMesh mesh;
  fem::Material mat;
  fem::Supports supports;
  Eigen::MatrixXd loads;

  /// cells: cubes per axis (each split into six tets); force: N on the end face, one load case.
  TestBeam(std::array<int, 3> cells, std::array<double, 3> force) {
    box.origin = {0, -5, -5};
    box.size = {30, 10, 10};
    box.cells = cells;
    box.nondesign = {{28, -5, -5, 30, 5, 5}};
    mesh = mesh::structured_box_mesh(box);
    supports = fem::make_supports(mesh, {fem::support_on(fem::SupportSpec::Kind::Fixed, {1})});
    fem::LoadSpec pull{fem::LoadSpec::Kind::Force, {2}, force, 0, {}};
    loads = fem::make_loads(mesh, mat, {fem::LoadCase{"a", {pull}, 1}});
  }
  /// The cells' edge along `axis` (mm).
  double cell(int axis) const { return box.size[axis] / box.cells[axis]; }
};

}  // namespace topopt::simp
