// The mesh of a job: its "mesh.file", or its part and non-design solids (from the job's
// paths, or given as shapes by the workbench) checked, classified and meshed as the job's
// MeshSettings say, with the face names of its supports and loads checked against the part.
#pragma once
#include <TopoDS_Shape.hxx>

#include "common/progress.h"
#include "common/types.h"
#include "mesh/two_brep/native_mesher.h"
#include "pipeline/job.h"

namespace topopt::pipeline {

/// The shapes of a job when they come separately (the workbench sends BREP strings); a null
/// part means: read the job's "part" and "nondesign" files.
struct JobShapes {
  TopoDS_Shape part;       ///< Ω
  TopoDS_Shape nondesign;  ///< Ω̄ (a compound of solids), or null for none
};

/// The job's mesh, nodes numbered to follow space (faster solves downstream): the given
/// shapes meshed by mesh_model(); without shapes, the job's "mesh.file" (face names checked
/// against the part when the job names one) or its part files meshed. `run`
/// (optional) gets what the mesher did. Throws Error(InvalidParameter) when there is no part
/// and no mesh file, Error(Io) for an unreadable file, Error(FaceNotFound) for a face the
/// part lacks, and what mesh_model() throws.
TetMesh job_mesh(const Job& job, const JobShapes& shapes = {}, const Progress& progress = {},
                 mesh::MeshRun* run = nullptr);

}  // namespace topopt::pipeline
