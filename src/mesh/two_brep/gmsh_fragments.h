// The Gmsh fallback: what a Gmsh user does — OCC fragments of Ω with Ω̄, then a conformal 3D
// mesh — driven from our B-Rep layer so that the result is a TetMesh in our conventions
// (domains in input order, boundary triangles tagged with FreeCAD's face numbers of Ω and of
// Ω̄). The mesher choice "auto" falls back to it where the native mesher cannot close a
// mesh, "gmsh" asks for it, and it is the reference the native mesher is benchmarked against.
//
// Gmsh keeps global state (calls here are serialised by a mutex) and can crash or abort
// inside (an exception thrown in an OpenMP region); it also rewrites FLTK's preference files
// when it starts. The product therefore runs it in a child process (pipeline/mesh_model.h),
// which keeps those effects out of the caller's process and files.
#pragma once
#include "brep/two_breps.h"
#include "common/progress.h"
#include "common/types.h"

namespace topopt::mesh {

struct FragmentMeshParams {
  double size = 0;                ///< target element size (mm); must be set (> 0)
  double min_size = 0;            ///< smallest element size (mm); must be set (> 0)
  double elements_per_turn = 40;  ///< on curved faces (Gmsh's Mesh.MeshSizeFromCurvature)
  /// Fill the volumes with our advancing front (steps 12-14, volume_steps.h) on Gmsh's
  /// conformal surface mesh instead of Gmsh's 3D mesher (a comparison aid).
  bool volume_by_front = false;
};

/// Meshes Ω with Ω̄ into one conformal tagged tet mesh: domain 0 = Ω − Ω̄, i = the i-th
/// non-design solid; F = the boundary of Ω with face = FreeCAD face number of Ω and
/// nd_face = face number in Ω̄ where the triangle lies on a non-design face.
/// Throws Error(MeshingFailed) with Gmsh's message if meshing fails, naming a non-design
/// solid that does not fragment into one volume.
TetMesh mesh_with_gmsh_fragments(const brep::TwoBReps& model, const FragmentMeshParams& params,
                                 const Progress& progress = {});

}  // namespace topopt::mesh
