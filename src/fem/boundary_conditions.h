// Supports and loads given on the part's B-Rep faces (FreeCAD numbering, "Face7"), turned
// into fixed degrees of freedom and consistent nodal load vectors on a TetMesh.
//
// INTERFACE CONTRACT (SIMP, CLI, job files and the workbench rely on it).
#pragma once
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "fem/elasticity.h"

namespace topopt::fem {

/// One support on a set of faces.
struct SupportSpec {
  enum class Kind { Fixed, Components, Symmetry } kind = Kind::Fixed;
  std::vector<int> faces;                     ///< 1-based face numbers of Ω (FreeCAD FaceN)
  std::array<bool, 3> fix{true, true, true};  ///< Components: which of x, y, z are fixed
  // Symmetry: the faces must be planar and perpendicular to x, y or z; the normal
  // component is fixed.
  /// Faces of the non-design compound Ω̄ ("NonDesign:FaceN", 1-based), matched through
  /// TetMesh::nd_face where they form part of Ω's boundary (load pads).
  std::vector<int> nd_faces;
};

/// A support of `kind` on Ω's faces `faces` (1-based; Fixed: every component), the other
/// fields at their defaults: the short form tests and callers use instead of a brace list.
inline SupportSpec support_on(SupportSpec::Kind kind, std::vector<int> faces) {
  SupportSpec s;
  s.kind = kind;
  s.faces = std::move(faces);
  return s;
}

/// One load item; a load case is a list of them.
struct LoadSpec {
  enum class Kind { Force, Pressure, Gravity } kind = Kind::Force;
  std::vector<int> faces;                 ///< Force, Pressure: 1-based face numbers of Ω
  std::array<double, 3> vector{0, 0, 0};  ///< Force: total force (N) spread by area;
                                          ///< Gravity: acceleration (mm/s²)
  double value = 0;                       ///< Pressure: MPa, positive pushes into the part
  std::vector<int> nd_faces;              ///< as SupportSpec::nd_faces
};

struct LoadCase {
  std::string name;
  std::vector<LoadSpec> items;
  double weight = 1.0;  ///< weight in a multi-case objective
};

/// Fixed dofs of the supports. Throws Error(FaceNotFound) naming a face the mesh lacks and
/// Error(NoSupport) if nothing is fixed.
Supports make_supports(const TetMesh& mesh, const std::vector<SupportSpec>& specs);

/// (3*#V) by #cases consistent nodal loads: a total force is spread over the faces'
/// triangles by area (a third of each triangle's share to each of its nodes), a pressure
/// acts along each triangle's inward normal, gravity loads every tet with ρ·vol/4 per node
/// (SIMP then scales each design tet's share by its density, see gravity_of).
/// Throws Error(FaceNotFound) for a face the mesh lacks.
Eigen::MatrixXd make_loads(const TetMesh& mesh, const Material& material, const std::vector<LoadCase>& cases);

/// 3 by #cases: each case's gravity accelerations summed (mm/s²); zero where it has none.
Eigen::Matrix3Xd gravity_of(const std::vector<LoadCase>& cases);

}  // namespace topopt::fem
