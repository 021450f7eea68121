// The analysis path of a job (see solve_job.h).
#include "pipeline/solve_job.h"

#include <chrono>
#include <filesystem>

#include "common/error.h"
#include "fem/boundary_conditions.h"
#include "io/inp.h"
#include "io/vtu.h"
#include "pipeline/output_files.h"

namespace topopt::pipeline {
namespace fs = std::filesystem;

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
/// solve_job's answer from a distributed run (the set-up time is the solve's part before it).
SolveResult distributed_solve(const Job& job, const TetMesh& mesh, const fem::Supports& supports,
                              const Eigen::MatrixXd& F, const AnalysisRunner& runner, const Progress& progress) {
  progress.say("solve", -1, "solving " + std::to_string(3 * mesh.V.rows()) + " unknowns on the MPI ranks");
  const auto t0 = std::chrono::steady_clock::now();
  SolveResult r;
  runner(mesh, job.material, supports, F, r.U, r.von_mises);
  r.seconds_solve = seconds_since(t0);
  for (size_t c = 0; c < job.load_cases.size(); ++c) {
    r.case_names.push_back(job.load_cases[c].name);
    r.compliance.push_back(F.col(c).dot(r.U.col(c)));
  }
  return r;
}

}  // namespace

SolveResult solve_job(const Job& job, const TetMesh& mesh, const fem::SolverParams& solver, const VecXd& scale,
                      const Progress& progress, const AnalysisRunner& runner) {
  if (job.load_cases.empty())
    throw Error(ErrorCode::InvalidParameter, "the job has no load case: add \"load_cases\" with at least one load");
  auto t0 = std::chrono::steady_clock::now();
  fem::Supports supports = fem::make_supports(mesh, job.supports);
  Eigen::MatrixXd F = fem::make_loads(mesh, job.material, job.load_cases);
  if (runner) return distributed_solve(job, mesh, supports, F, runner, progress);
  fem::Elasticity fe(mesh, job.material, supports, solver);
  if (scale.size()) fe.set_scale(scale);
  SolveResult r;
  r.seconds_setup = seconds_since(t0);
  progress.say("solve", -1, "solving " + std::to_string(fe.num_dofs()) + " unknowns");
  t0 = std::chrono::steady_clock::now();
  r.U = fe.solve(F, progress);
  r.seconds_solve = seconds_since(t0);
  for (size_t c = 0; c < job.load_cases.size(); ++c) {
    r.case_names.push_back(job.load_cases[c].name);
    r.compliance.push_back(F.col(c).dot(r.U.col(c)));
    r.von_mises.push_back(fe.von_mises(r.U.col(c)));
  }
  return r;
}

std::vector<std::string> write_solve_outputs(const Job& job, const TetMesh& mesh, const SolveResult& r,
                                             const std::string& dir, const std::string& inp_path) {
  std::vector<std::string> written;
  std::vector<io::VtuField> points, cells;
  for (size_t c = 0; c < r.case_names.size(); ++c) {
    io::VtuField u{"displacement_" + r.case_names[c], 3, {}};
    u.values.assign(r.U.col(c).data(), r.U.col(c).data() + r.U.rows());
    points.push_back(std::move(u));
    io::VtuField vm{"von_mises_" + r.case_names[c], 1, {}};
    vm.values.assign(r.von_mises[c].data(), r.von_mises[c].data() + r.von_mises[c].size());
    cells.push_back(std::move(vm));
  }
  if (job.output.vtu)
    written.push_back(write_replacing((fs::path(dir) / "result.vtu").string(),
                                      [&](const std::string& p) { io::write_vtu(p, mesh, points, cells); }));
  std::vector<std::string> decks;
  if (job.output.inp) decks.push_back((fs::path(dir) / "result.inp").string());
  if (!inp_path.empty()) decks.push_back(inp_path);
  if (!decks.empty()) {
    const fem::Supports s = fem::make_supports(mesh, job.supports);
    const Eigen::MatrixXd F = fem::make_loads(mesh, job.material, job.load_cases);
    for (const std::string& deck : decks)
      written.push_back(
          write_replacing(deck, [&](const std::string& p) { io::write_inp(p, mesh, job.material, s, F, 0); }));
  }
  return written;
}

}  // namespace topopt::pipeline
