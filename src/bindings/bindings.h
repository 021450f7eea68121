// The Python module topopt._native, split by stage: each bind_*.cpp adds its stage's
// functions. This is the only code that sees Python.
#pragma once
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <string>
#include <vector>

#include "common/progress.h"
#include "common/types.h"

namespace topopt::py {
void bind_brep(pybind11::module_& m);
void bind_mesh(pybind11::module_& m);
void bind_fem(pybind11::module_& m);
void bind_simp(pybind11::module_& m);

/// The tet mesh as every result dict carries it: nodes #V x 3, tets #T x 4, domain #T,
/// boundary_triangles #F x 3, boundary_faces #F (the part's FreeCAD face numbers),
/// boundary_nondesign_faces #F (the non-design face a triangle also lies on, 0: none).
inline void put_tet_mesh(pybind11::dict& out, const TetMesh& mesh) {
  out["nodes"] = mesh.V;
  out["tets"] = mesh.T;
  out["domain"] = mesh.domain;
  out["boundary_triangles"] = mesh.F;
  out["boundary_faces"] = mesh.face;
  out["boundary_nondesign_faces"] = mesh.nd_face;
}

/// Makes `progress` keep the core's warnings (e.g. the mesher fell back to Gmsh) in
/// `warnings`, which the result dict returns as "warnings".
inline void keep_warnings(Progress& progress, std::vector<std::string>& warnings) {
  progress.log = [&warnings](LogLevel level, const std::string& message) {
    if (level == LogLevel::Warning) warnings.push_back(message);
  };
}
}  // namespace topopt::py
