// The native mesher: the part Ω and the non-design solids Ω̄ meshed as two B-Reps by the 14
// steps of DESIGN.md into one conformal tagged tet mesh. Both models' surface meshes are
// built stage by stage on one node pool (ModelSurface), and nodes, segments, triangles and
// tets move between them by the classification of Ω̄ against Ω (brep/classify.h); the
// volumes are filled by the 3D advancing front (Ω̄'s solids first, then Ω around their tets).
// Non-design solids that touch each other share their vertices, edges and touching faces.
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
  NativeMeshParams() { surface.max_angle = 2 * 3.14159265358979323846 / 40; }
  /// 40 elements per 2π on curved faces, as the product's default: the faceting error of a
  /// bore, about (2π/N)²/6 of a ring's volume, stays under the 0.5 % the volumes are held to
  SurfaceMeshParams surface;
  VolumeFillParams volume;  ///< its size is set from the surface size and the gradation if empty
  /// Refuse meshes estimated above this many tets (memory: ~1 kB per tet through SIMP); the
  /// fills stop at twice this, should the estimate be off.
  double max_tets = 6e6;
};

/// What a run did: the mesher that made the mesh and the seconds of each stage.
struct MeshRun {
  std::string mesher;                                   ///< "native" or "gmsh"
  std::vector<std::pair<std::string, double>> seconds;  ///< (stage, seconds) in order
  std::string fallback_reason;                          ///< why "auto" fell back to Gmsh, if it did
};

/// The 14 steps: one conformal tet mesh of Ω, every tet tagged 0 (design, Ω − Ω̄) or i (the
/// i-th non-design solid, input order); boundary triangles = Ω's boundary with Ω's FreeCAD
/// face numbers, and nd_face = the face of Ω̄ a triangle also lies on (load pads).
/// Throws MeshingFailed naming the face, edge, solid or region that could not be meshed.
TetMesh mesh_native(const brep::TwoBReps& model, const NativeMeshParams& params = {}, const Progress& progress = {},
                    MeshRun* run = nullptr);

/// The product's choice of mesher: "native" (mesh_native), "gmsh" (OCC fragments and Gmsh,
/// gmsh_fragments.h) or "auto" (native; where it cannot close a mesh, a warning through
/// `progress` and Gmsh). size, min_size in mm, 0 = automatic; wall_layers as
/// SurfaceMeshParams::wall_layers (the native mesher only).
TetMesh mesh_two_breps(const brep::TwoBReps& model, const std::string& mesher, double size, double min_size,
                       const Progress& progress = {}, MeshRun* run = nullptr, int wall_layers = 0);

}  // namespace topopt::mesh
