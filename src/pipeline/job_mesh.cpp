// The mesh of a job (see job_mesh.h).
#include "pipeline/job_mesh.h"

#include "brep/shape_io.h"
#include "brep/topology_index.h"
#include "brep/two_breps.h"
#include "common/error.h"
#include "io/msh.h"
#include "mesh/core/reorder.h"
#include "pipeline/mesh_model.h"

namespace topopt::pipeline {
namespace {

/// "mesh.file": face names are checked against the part itself when the job names one, so
/// that a typo is reported as such and not as "no triangles on that face".
TetMesh read_mesh_file(const Job& job, const Progress& progress) {
  if (!job.part.empty()) {
    const TopoDS_Shape part = brep::read_shape_file(job.part);
    int nondesign_faces = -1;
    if (!job.nondesign.empty())
      nondesign_faces = brep::index_topology(brep::read_shape_file(job.nondesign)).num_faces();
    check_faces(job, brep::index_topology(part).num_faces(), nondesign_faces);
  }
  progress.say("mesh", -1, "reading " + job.mesh.file);
  return io::read_msh(job.mesh.file);
}

TetMesh mesh_shapes(const Job& job, const JobShapes& shapes, const Progress& progress, mesh::MeshRun* run) {
  TopoDS_Shape part = shapes.part, nondesign = shapes.nondesign;
  if (part.IsNull()) {
    if (job.part.empty())
      throw Error(
          ErrorCode::InvalidParameter,
          "job file: 'part' is missing: give the part's STEP/BREP file, or a mesh with \"mesh\": {\"file\": ...}");
    part = brep::read_shape_file(job.part);
    if (!job.nondesign.empty()) nondesign = brep::read_shape_file(job.nondesign);
  }
  progress.say("mesh", -1, "checking the part and the non-design solids");
  const brep::TwoBReps model = brep::load_two_breps(part, nondesign, {}, progress);
  check_faces(job, model.part.num_faces(), model.nondesign.num_faces());
  return mesh_model(model, job.mesh, progress, run);
}

}  // namespace

TetMesh job_mesh(const Job& job, const JobShapes& shapes, const Progress& progress, mesh::MeshRun* run) {
  const bool from_file = shapes.part.IsNull() && !job.mesh.file.empty();
  TetMesh mesh = from_file ? read_mesh_file(job, progress) : mesh_shapes(job, shapes, progress, run);
  // The fronts, Gmsh and other tools number nodes in the order they make them; the solver,
  // filter and surface run faster on a numbering that follows space (bench/simp).
  mesh::reorder_for_locality(mesh);
  return mesh;
}

}  // namespace topopt::pipeline
