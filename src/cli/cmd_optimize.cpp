// topopt optimize: mesh → SIMP → result surface for a job file (pipeline::run_job).
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "cli/commands.h"
#include "common/error.h"
#include "pipeline/job.h"
#include "pipeline/output_files.h"
#include "pipeline/run_job.h"
#include "result/iso_surface.h"
#ifdef TOPOPT_WITH_PETSC
#include "dist/dist_run.h"
#endif

namespace topopt::cli {
namespace {

/// Sets options.simp to SIMP on all MPI ranks (session not null) and the ranks it runs on;
/// the per-rank figures go to stats_text.
void use_ranks(const dist::MpiSession* session, const std::string& amg, pipeline::RunOptions& options,
               std::string* stats_text) {
#ifdef TOPOPT_WITH_PETSC
  if (!session) return;
  options.ranks = session->size();
  options.simp = [session, amg, stats_text](
                     const TetMesh& mesh, const fem::Material& material, const fem::Supports& supports,
                     const Eigen::MatrixXd& loads, const std::vector<double>& weights, const simp::SimpParams& params,
                     const Progress& progress, const std::function<void(const simp::IterationRecord&)>& on_iteration,
                     const Eigen::Matrix3Xd& gravity) {
    std::vector<dist::RankStats> stats;
    simp::SimpResult r = dist::optimize_on_ranks(*session, mesh, material, supports, loads, weights, params, progress,
                                                 on_iteration, gravity, dist::amg_named(amg), &stats);
    *stats_text = dist::stats_json(stats);
    return r;
  };
#else
  (void)session, (void)amg, (void)options, (void)stats_text;
#endif
}

}  // namespace

int cmd_optimize(const Args& args, const dist::MpiSession* session) {
  ArgReader a(args,
              "usage: topopt optimize JOB.json [--out-dir DIR] [--quiet] [--verbose] [--stats STATS.json]\n"
              "                             [--amg gamg|boomeramg]\n"
              "  Meshes the part (or reads the job's mesh file), runs SIMP with the job's supports,\n"
              "  loads and \"optimization\" settings (docs/optimization.md), extracts the shape at the\n"
              "  threshold that keeps the volume fraction and smooths it. Writes DIR/density.vtu,\n"
              "  DIR/history.csv, DIR/history.json and DIR/result.stl, then DIR/result.step (the result as\n"
              "  one CAD solid) and DIR/verification.json and .vtu (the result solid meshed and analysed\n"
              "  with the job's supports and loads, next to the crisp design; \"output\": {\"step\": false,\n"
              "  \"verification\": false} skips them). A failed export or verification is a warning: the\n"
              "  other files are written. The whole job is checked, and DIR made and tested, before any work.\n"
              "  --out-dir  output folder (default: the job's output.directory, or out/ beside it)\n"
              "  --quiet    no line per iteration\n"
              "  --verbose  also the solver's timings\n"
              "  --stats    time and peak memory per MPI rank (one entry when serial), JSON\n"
              "  Under mpirun (a build with PETSc) rank 0 reads and meshes the job, then the FE solve\n"
              "  (CG + multigrid), the Helmholtz density filter and the OC update run on all ranks; the files\n"
              "  are the serial run's, written by rank 0 (history.json records \"ranks\"). MMA, the\n"
              "  sensitivity filter and self-weight are serial only.\n"
              "  --amg      the multigrid under mpirun: " TOPOPT_AMG_CHOICES);
  if (a.print_help()) return 0;
  std::string out = a.option("out-dir"), stats = a.option("stats"), amg = amg_option(a);
  bool quiet = a.flag("quiet"), verbose = a.flag("verbose");
  std::vector<std::string> pos = a.positionals();
  if (pos.size() != 1) throw Error(ErrorCode::InvalidParameter, "give one job file\n" + a.usage());
  pipeline::Job job = pipeline::read_job(pos[0]);
  if (!out.empty()) job.output.directory = std::filesystem::absolute(out).lexically_normal().string();
  if (!stats.empty())
    pipeline::prepare_output_folder(std::filesystem::absolute(stats).parent_path().string(), "--stats");
  Progress progress;
  progress.report = [quiet](const std::string& stage, double, const std::string& msg) {
    if (!quiet || stage != "simp") std::cerr << "[" << stage << "] " << msg << "\n";
  };
  progress.log = [verbose](LogLevel level, const std::string& msg) {
    if (verbose || level == LogLevel::Warning)
      std::cerr << (level != LogLevel::Warning ? "  " : "warning: ") << msg << "\n";
  };
  pipeline::RunOptions options;
  options.write_outputs = true;
  std::string stats_text;
  use_ranks(session, amg, options, &stats_text);
  const pipeline::RunResult run = pipeline::run_job(job, {}, progress, {}, options);
  const pipeline::OptimizeResult& r = run.optimization;
  const auto& last = r.simp.history.back();
  const result::ResultCheck& check = r.surface_report.check;
  std::cout << "mesh: " << run.mesh.V.rows() << " nodes, " << run.mesh.T.rows() << " tets (" << run.seconds_mesh
            << " s)\n"
            << std::setprecision(6) << "simp: " << r.simp.status << ", compliance " << last.compliance
            << " N*mm, volume fraction " << last.volume_fraction << " (" << r.seconds_simp << " s)\n"
            << "surface: threshold " << r.threshold << ", " << r.surface.F.rows() << " triangles, "
            << (check.closed.closed_manifold() ? "closed" : "NOT closed") << ", " << check.crossings.size()
            << " self-intersections, smallest angle " << check.min_angle_free << " deg (free-form), volume "
            << check.closed.volume << " mm^3 (" << r.seconds_surface << " s)\n";
  if (run.files.step)
    std::cout << "step: " << run.files.step->faces << " faces (" << run.files.step->planar_faces << " planar), "
              << run.files.step->bytes / 1e6 << " MB (" << run.files.step->seconds << " s, "
              << run.files.step->cpu_seconds << " s CPU)\n";
  if (const auto& v = run.files.verification)
    std::cout << "verification: compliance as built " << v->as_built.compliance << " N*mm on " << v->as_built.tets
              << " tets, crisp design " << v->crisp.compliance << " N*mm (ratio " << v->ratio()
              << "), max displacement " << v->as_built.max_displacement << " mm, max von Mises "
              << v->as_built.max_von_mises << " MPa (" << v->as_built.seconds << " s, " << v->as_built.cpu_seconds
              << " s CPU)\n";
  for (const auto& p : run.written) std::cout << "wrote " << p << "\n";
  if (stats_text.empty()) stats_text = serial_stats_json(run.mesh.T.rows(), r.seconds_simp);
  write_stats_file(stats, stats_text);
  return 0;
}

}  // namespace topopt::cli
