// topopt solve: linear elastic analysis of a job file.
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "cli/commands.h"
#include "common/error.h"
#include "pipeline/job.h"
#include "pipeline/job_mesh.h"
#include "pipeline/output_files.h"
#include "pipeline/solve_job.h"
#ifdef TOPOPT_WITH_PETSC
#include "dist/dist_run.h"
#endif

namespace topopt::cli {
namespace {

/// The distributed solve for solve_job under mpirun (nullptr session: none). Its relative
/// residual is 1e-10, so that the displacements match a direct solve to about 1e-8.
pipeline::AnalysisRunner distributed_runner(const dist::MpiSession* session, const std::string& amg,
                                            std::string* stats_text) {
#ifdef TOPOPT_WITH_PETSC
  if (!session) return {};
  return [session, amg, stats_text](const TetMesh& mesh, const fem::Material& material, const fem::Supports& supports,
                                    const Eigen::MatrixXd& loads, Eigen::MatrixXd& U, std::vector<VecXd>& von_mises) {
    dist::DistSolverParams params;
    params.tolerance = 1e-10;
    params.amg = dist::amg_named(amg);
    std::vector<dist::RankStats> stats;
    dist::solve_on_ranks(*session, mesh, material, supports, loads, params, U, von_mises, &stats);
    *stats_text = dist::stats_json(stats);
  };
#else
  (void)session, (void)amg, (void)stats_text;
  return {};
#endif
}

}  // namespace

int cmd_solve(const Args& args, const dist::MpiSession* session) {
  ArgReader a(args,
              "usage: topopt solve JOB.json [--out-dir DIR] [--solver auto|direct|iterative] [--inp FILE]\n"
              "                          [--stats STATS.json] [--amg gamg|boomeramg]\n"
              "  Solves the job's load cases (linear elasticity on tets) and writes DIR/result.vtu\n"
              "  (displacements and von Mises stress per case) for ParaView. The job format is in\n"
              "  docs/job-format.md; the whole job is checked, and DIR made and tested, before any work.\n"
              "  --out-dir  output folder (default: the job's output.directory, or out/ beside it)\n"
              "  --solver   direct (CHOLMOD sparse Cholesky, auto up to 20 000 unknowns) or iterative\n"
              "             (conjugate gradients with smoothed-aggregation multigrid, auto above)\n"
              "  --inp      also write the problem (first load case) as a CalculiX deck, to check\n"
              "             the result with: ccx -i <name without .inp>\n"
              "  --stats    time and peak memory per MPI rank (one entry when serial), JSON\n"
              "  Under mpirun (a build with PETSc) the mesh is read or made on rank 0, distributed, and\n"
              "  solved by CG with algebraic multigrid on all ranks; --solver is ignored.\n"
              "  --amg      the multigrid under mpirun: " TOPOPT_AMG_CHOICES);
  if (a.print_help()) return 0;
  std::string out = a.option("out-dir"), solver = a.option("solver", "auto"), inp = a.option("inp"),
              stats = a.option("stats"), amg = amg_option(a);
  std::vector<std::string> pos = a.positionals();
  if (pos.size() != 1) throw Error(ErrorCode::InvalidParameter, "give one job file\n" + a.usage());
  pipeline::Job job = pipeline::read_job(pos[0]);
  if (!out.empty()) job.output.directory = std::filesystem::absolute(out).lexically_normal().string();
  fem::SolverParams sp;
  if (solver == "direct")
    sp.kind = fem::SolverKind::Direct;
  else if (solver == "iterative")
    sp.kind = fem::SolverKind::Iterative;
  else if (solver != "auto")
    throw Error(ErrorCode::InvalidParameter, "--solver takes auto, direct or iterative");
  pipeline::require_supports_and_loads(job);
  pipeline::prepare_output_folder(job.output.directory, "'output.directory' (or --out-dir)");
  for (const auto& [file, option] : {std::pair{inp, "--inp"}, std::pair{stats, "--stats"}})
    if (!file.empty()) pipeline::prepare_output_folder(std::filesystem::absolute(file).parent_path().string(), option);
  Progress progress;
  progress.report = [](const std::string& stage, double, const std::string& msg) {
    std::cerr << "[" << stage << "] " << msg << "\n";
  };
  progress.log = [](LogLevel, const std::string& msg) { std::cerr << "  " << msg << "\n"; };
  TetMesh mesh = pipeline::job_mesh(job, {}, progress);
  std::cout << "mesh: " << mesh.V.rows() << " nodes, " << mesh.T.rows() << " tets\n";
  std::string stats_text;
  pipeline::SolveResult r =
      pipeline::solve_job(job, mesh, sp, VecXd(), progress, distributed_runner(session, amg, &stats_text));
  std::cout << std::setprecision(6);
  for (size_t c = 0; c < r.case_names.size(); ++c) {
    double umax = 0;
    for (long i = 0; i < mesh.V.rows(); ++i) umax = std::max(umax, r.U.block<3, 1>(3 * i, c).norm());
    std::cout << "load case " << r.case_names[c] << ": compliance " << r.compliance[c] << " N*mm, max displacement "
              << umax << " mm, max von Mises " << r.von_mises[c].maxCoeff() << " MPa\n";
  }
  std::cout << "time: setup " << r.seconds_setup << " s, solve " << r.seconds_solve << " s\n";
  for (const auto& p : pipeline::write_solve_outputs(job, mesh, r, job.output.directory, inp))
    std::cout << "wrote " << p << "\n";
  if (stats_text.empty()) stats_text = serial_stats_json(mesh.T.rows(), r.seconds_setup + r.seconds_solve);
  write_stats_file(stats, stats_text);
  return 0;
}

}  // namespace topopt::cli
