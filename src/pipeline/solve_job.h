// The analysis path shared by the CLI (`topopt solve`) and the Python module: a job's mesh,
// its supports and loads, the solve and the result files.
#pragma once
#include <TopoDS_Shape.hxx>
#include <string>
#include <vector>

#include "common/progress.h"
#include "common/types.h"
#include "fem/elasticity.h"
#include "io/job.h"

namespace topopt::pipeline {

/// The mesh of a job: the MSH file of "mesh.file" if given, else the conformal tagged mesh
/// of the part and non-design solids (interim: mesh/gmsh_fragments.h). Checks that supports and loads name faces that
/// exist. Throws Error(Io) for an unreadable file, Error(MeshingFailed) if meshing fails, Error(FaceNotFound) for a
/// face the part lacks.
TetMesh job_mesh(const io::Job& job, const Progress& progress = {});

/// The mesh of a job whose shapes are given (the workbench passes them as BREP strings):
/// checks and classifies them, checks the face names, meshes at the job's mesh size.
TetMesh mesh_job_shapes(const io::Job& job, const TopoDS_Shape& part, const TopoDS_Shape& nondesign,
                        const Progress& progress = {});

/// Results of a linear static analysis, one entry per load case.
struct SolveResult {
  std::vector<std::string> case_names;
  Eigen::MatrixXd U;               ///< (3*#V) by #cases displacements (mm), node-major
  std::vector<double> compliance;  ///< F·U per case (N·mm)
  std::vector<VecXd> von_mises;    ///< #T per case (MPa)
  double seconds_setup = 0, seconds_solve = 0;
};

/// Solves every load case of `job` on `mesh` (one factorisation). `scale` (#T, optional):
/// element stiffness factors. Throws Error(NoSupport) if the supports do not hold the part,
/// Error(InvalidParameter) if the job has no load case.
SolveResult solve_job(const io::Job& job, const TetMesh& mesh, const fem::SolverParams& solver = {},
                      const VecXd& scale = VecXd(), const Progress& progress = {});

/// Writes `dir`/result.vtu (displacement and von Mises per case, domain) and, when
/// `inp_path` is not empty, the problem as a CalculiX deck (first load case). Returns the
/// paths written.
std::vector<std::string> write_solve_outputs(const io::Job& job, const TetMesh& mesh, const SolveResult& r,
                                             const std::string& dir, const std::string& inp_path);

}  // namespace topopt::pipeline
