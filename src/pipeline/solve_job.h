// The analysis path shared by the CLI (`topopt solve`) and the Python module: the job's
// supports and loads on a mesh (pipeline/job_mesh.h), the solve and the result files.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "common/progress.h"
#include "common/types.h"
#include "fem/elasticity.h"
#include "pipeline/job.h"

namespace topopt::pipeline {

/// Results of a linear static analysis, one entry per load case.
struct SolveResult {
  std::vector<std::string> case_names;
  Eigen::MatrixXd U;               ///< (3*#V) by #cases displacements (mm), node-major
  std::vector<double> compliance;  ///< F·U per case (N·mm)
  std::vector<VecXd> von_mises;    ///< #T per case (MPa)
  double seconds_setup = 0, seconds_solve = 0;
};

/// A solve in place of fem::Elasticity's (dist/dist_run.h: solve_on_ranks under mpirun): given
/// the mesh, material, supports and loads ((3 #V) by #cases), sets U (same shape) and each
/// case's von Mises stress (#T, MPa).
using AnalysisRunner =
    std::function<void(const TetMesh&, const fem::Material&, const fem::Supports&, const Eigen::MatrixXd& loads,
                       Eigen::MatrixXd& U, std::vector<VecXd>& von_mises)>;

/// Solves every load case of `job` on `mesh` (one factorisation). `scale` (#T, optional):
/// element stiffness factors (serial only); runner: the distributed solve (empty: serial).
/// Throws Error(NoSupport) if the supports do not hold the part, Error(InvalidParameter) if the
/// job has no load case.
SolveResult solve_job(const Job& job, const TetMesh& mesh, const fem::SolverParams& solver = {},
                      const VecXd& scale = VecXd(), const Progress& progress = {}, const AnalysisRunner& runner = {});

/// Writes into `dir` (prepared by prepare_output_folder): result.vtu (displacement and von
/// Mises per case, domain) when job.output.vtu, result.inp (the problem as a CalculiX deck,
/// first load case) when job.output.inp; and the deck at `inp_path` too when it is not
/// empty. Each file is written under a temporary name and renamed. Returns the paths written.
std::vector<std::string> write_solve_outputs(const Job& job, const TetMesh& mesh, const SolveResult& r,
                                             const std::string& dir, const std::string& inp_path);

}  // namespace topopt::pipeline
