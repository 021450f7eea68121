// A structured tetrahedral mesh of an axis-aligned box: the fixture on which FEM, SIMP and
// the result surface are tested independently of the advancing-front mesher, and the mesh
// of the structured-grid reference in bench/. Not the product's mesher.
#pragma once
#include <array>
#include <vector>

#include "common/types.h"

namespace topopt::mesh {

struct StructuredBoxParams {
  std::array<double, 3> origin{0, 0, 0};  ///< lower corner (mm)
  std::array<double, 3> size{1, 1, 1};    ///< edge lengths (mm), > 0
  std::array<int, 3> cells{1, 1, 1};      ///< hexahedral cells per axis, >= 1
  /// Non-design boxes as {xmin, ymin, zmin, xmax, ymax, zmax}: a tet whose centroid lies in
  /// box k gets domain k+1 (the first box that holds it); all others are design (0).
  std::vector<std::array<double, 6>> nondesign;
};

/// Each cell is split into 6 tets around its main diagonal (Kuhn split, the same in every
/// cell, so the mesh is conformal). Boundary triangles carry the box's face numbers in
/// OCCT/FreeCAD order: 1 x=min, 2 x=max, 3 y=min, 4 y=max, 5 z=min, 6 z=max.
/// nd_face marks boundary triangles lying on a non-design box's face, numbered as FreeCAD
/// numbers the faces of a compound of those boxes (box k's face j is 6k + j).
/// Returns a TetMesh with positively oriented tets and outward boundary triangles.
TetMesh structured_box_mesh(const StructuredBoxParams& params);

}  // namespace topopt::mesh
