// INTERIM mesher, until the native two-B-Rep advancing-front mesher (issues 3–5) lands:
// what a Gmsh user does today — OCC fragments of Ω with Ω̄, then a conformal 3D mesh — driven
// from our B-Rep layer so that the result is a TetMesh in our conventions (domains in input
// order, boundary triangles tagged with FreeCAD's face numbers of Ω and of Ω̄). It makes the
// whole product path (CLI, Python, workbench) work on real parts today, and it is the
// reference the native mesher is benchmarked against.
#pragma once
#include "brep/two_breps.h"
#include "common/progress.h"
#include "common/types.h"

namespace topopt::mesh {

struct FragmentMeshParams {
  double size = 0;      ///< target element size (mm); <= 0: the part's diagonal / 50
  double min_size = 0;  ///< smallest size (mm); <= 0: size / 5
  /// Refuse meshes estimated above this many tets (memory: ~1 kB per tet through SIMP).
  double max_tets = 6e6;
  /// Fill the volumes with our advancing front (mesh/volume_front.h) instead of Gmsh's 3D
  /// mesher: each non-design solid from its surface, then Ω around their tets (steps 12–14
  /// of the method, on Gmsh's conformal surface mesh). Experimental.
  bool native_volume = false;
};

/// Meshes Ω with Ω̄ into one conformal tagged tet mesh: domain 0 = Ω − Ω̄, i = the i-th
/// non-design solid; F = the boundary of Ω with face = FreeCAD face number of Ω and
/// nd_face = face number in Ω̄ where the triangle lies on a non-design face.
/// Throws Error(TooLarge) if the estimated mesh exceeds params.max_tets, Error(MeshingFailed)
/// with Gmsh's message if meshing fails.
TetMesh mesh_with_gmsh_fragments(const brep::TwoBReps& model, const FragmentMeshParams& params = {},
                                 const Progress& progress = {});

}  // namespace topopt::mesh
