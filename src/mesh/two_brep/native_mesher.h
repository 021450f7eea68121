// The native mesher: the part Ω and the non-design solids Ω̄ meshed as two B-Reps by the 14
// steps of DESIGN.md into one conformal tagged tet mesh. Both models' surface meshes are
// built stage by stage on one node pool (ModelSurface), and nodes, segments, triangles and
// tets move between them by the classification of Ω̄ against Ω (brep/classify.h); the
// volumes are filled by the 3D advancing front (Ω̄'s solids first, then Ω around their tets:
// volume_steps.h). Non-design solids that touch each other share their vertices, edges and
// touching faces. Sizes and the choice of mesher are decided by the caller
// (pipeline/mesh_settings.h), not here.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "brep/two_breps.h"
#include "common/progress.h"
#include "common/types.h"
#include "mesh/surface/surface_mesher.h"
#include "mesh/volume/volume_front.h"

namespace topopt::mesh {

struct NativeMeshParams {
  /// Both models' surface settings (the part's size for both, so that what one transfers
  /// suits the other). size and min_size must be set (> 0).
  SurfaceMeshParams surface;
  /// The fills' settings; an empty size is graded from both surfaces at the surface's
  /// gradation and seeded at the middle of thin walls.
  VolumeFillParams volume;
};

/// What a run did: the mesher that made the mesh and the seconds of each stage.
struct MeshRun {
  std::string mesher;                                   ///< "native" or "gmsh"
  std::vector<std::pair<std::string, double>> seconds;  ///< (stage, seconds) in order
  std::string fallback_reason;                          ///< why "auto" fell back to Gmsh, if it did
  std::vector<FaceSize> face_sizes;                     ///< native: per face of the part, its finest size and why
};

/// The 14 steps: one conformal tet mesh of Ω, every tet tagged 0 (design, Ω − Ω̄) or i (the
/// i-th non-design solid, input order); boundary triangles = Ω's boundary with Ω's FreeCAD
/// face numbers, and nd_face = the face of Ω̄ a triangle also lies on (load pads).
/// `run` (optional) gets mesher "native", the seconds of steps 1-7, 8-11, 12, 13-14, the
/// last sliver pass (sliver_pass.h) and the conformity check, and the part's face sizes with their rules (ModelSurface::face_sizes). Throws MeshingFailed
/// naming the face, edge, solid or region that could not be meshed.
TetMesh mesh_native(const brep::TwoBReps& model, const NativeMeshParams& params, const Progress& progress = {},
                    MeshRun* run = nullptr);

}  // namespace topopt::mesh
