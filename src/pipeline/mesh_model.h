// The mesher choice: the part and its non-design solids meshed as MeshSettings say — the
// native mesher, Gmsh, or "auto" (native, and Gmsh where native cannot close a mesh). Gmsh
// always runs in a child process with a time budget (common/isolate.h), so that its crashes,
// aborts and hangs end the child and come back as named errors, and it may write no files.
#pragma once
#include "brep/two_breps.h"
#include "common/progress.h"
#include "common/types.h"
#include "mesh/two_brep/native_mesher.h"
#include "pipeline/mesh_settings.h"

namespace topopt::pipeline {

/// One conformal tagged tet mesh of `model` (mesh::mesh_native's conventions), nodes in the
/// order the mesher made them. Sizes from resolve_mesh_sizes (a warning through `progress`
/// when a size is clamped). "auto": whatever stops the native mesher, except a cancel or a
/// mesh too large for memory, falls back to Gmsh with a warning (the reason in run->fallback_reason). `run` (optional)
/// gets the mesher used and the seconds per stage. Each mesher runs within a time budget proportional to the estimated
/// tet count (native_time_budget, gmsh_time_budget), and every mesh is checked before it is returned
/// (mesh::check_conformity: exact orientation of every tet, conformity, volumes; the native mesher checks its own).
/// Throws Error(TooLarge) before any meshing for a size asking for too many tets; Error(MeshingFailed) naming where a
/// mesher failed or what is wrong with its mesh (the worst tets by position and quality); Error(Timeout) when the
/// native mesher ran past its budget (naming the stage; under "auto" Gmsh follows), Error(Crashed) or Error(Timeout)
/// when Gmsh crashed or ran past its budget (naming the native mesher's failure first under "auto");
/// Error(Cancelled).
TetMesh mesh_model(const brep::TwoBReps& model, const MeshSettings& settings, const Progress& progress = {},
                   mesh::MeshRun* run = nullptr);

/// Gmsh's mesh of `model` made in a child process that may not write any file (its HOME
/// points nowhere and, where the kernel has Landlock, writes are refused), stopped after
/// `seconds`. Throws what mesh_with_gmsh_fragments throws, Error(Crashed), Error(Timeout)
/// and Error(Cancelled), each naming "meshing with Gmsh".
TetMesh mesh_with_gmsh_isolated(const brep::TwoBReps& model, const mesh::FragmentMeshParams& params, double seconds,
                                const Progress& progress = {});

}  // namespace topopt::pipeline
