// The native mesher, as far as it goes today: one model meshed by our own surface mesher
// (steps 1, 5, 9 for a single B-Rep) and filled by our 3D advancing front (step 12 for a
// single B-Rep). The part with non-design solids needs the 14-step driver (issue 5); until it
// lands this takes a part without non-design solids and says so otherwise.
#pragma once
#include "brep/two_breps.h"
#include "common/progress.h"
#include "common/types.h"
#include "mesh/surface_mesher.h"
#include "mesh/volume_front.h"

namespace topopt::mesh {

struct NativeMeshParams {
  NativeMeshParams() { surface.max_angle = 2 * 3.14159265358979323846 / 40; }
  /// 40 elements per 2π on curved faces, as the product's default: the faceting error of a
  /// bore, about (2π/N)²/6 of a ring's volume, stays under the 0.5 % the volumes are held to
  SurfaceMeshParams surface;
  VolumeFillParams volume;  ///< its size is set from the surface size and the gradation if empty
};

/// A tagged tet mesh of the part (domain 0; boundary triangles tagged with its FreeCAD face
/// numbers). Throws InvalidParameter when non-design solids are given, MeshingFailed naming
/// the faces or the region that could not be meshed.
TetMesh mesh_native(const brep::TwoBReps& model, const NativeMeshParams& params = {}, const Progress& progress = {});

}  // namespace topopt::mesh
