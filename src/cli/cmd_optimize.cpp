// topopt optimize: mesh → SIMP → result surface for a job file.
#include <chrono>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "cli/commands.h"
#include "common/error.h"
#include "io/job.h"
#include "pipeline/optimize_job.h"
#include "pipeline/solve_job.h"
#include "result/iso_surface.h"

namespace topopt::cli {

int cmd_optimize(const Args& args) {
  ArgReader a(args,
              "usage: topopt optimize JOB.json [--out-dir DIR] [--quiet] [--verbose]\n"
              "  Meshes the part (or reads the job's mesh file), runs SIMP with the job's supports,\n"
              "  loads and \"optimization\" settings (docs/optimization.md), extracts the shape at the\n"
              "  threshold that keeps the volume fraction and smooths it. Writes DIR/density.vtu,\n"
              "  DIR/history.csv, DIR/history.json and DIR/result.stl.\n"
              "  --out-dir  output folder (default: the job's output.directory, or out/ beside it)\n"
              "  --quiet    no line per iteration\n"
              "  --verbose  also the solver's timings");
  if (a.print_help()) return 0;
  std::string out = a.option("out-dir");
  bool quiet = a.flag("quiet"), verbose = a.flag("verbose");
  std::vector<std::string> pos = a.positionals();
  if (pos.size() != 1) throw Error(ErrorCode::InvalidParameter, "give one job file\n" + a.usage());
  io::Job job = io::read_job(pos[0]);
  if (!out.empty()) job.output_dir = std::filesystem::absolute(out).string();
  pipeline::optimize_settings(job);  // report a bad setting before meshing
  Progress progress;
  progress.report = [quiet](const std::string& stage, double, const std::string& msg) {
    if (!quiet || stage != "simp") std::cerr << "[" << stage << "] " << msg << "\n";
  };
  progress.log = [verbose](LogLevel level, const std::string& msg) {
    if (verbose || level == LogLevel::Warning)
      std::cerr << (level != LogLevel::Warning ? "  " : "warning: ") << msg << "\n";
  };
  auto t0 = std::chrono::steady_clock::now();
  TetMesh mesh = pipeline::job_mesh(job, progress);
  double t_mesh = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "mesh: " << mesh.V.rows() << " nodes, " << mesh.T.rows() << " tets (" << t_mesh << " s)\n";
  pipeline::OptimizeResult r = pipeline::optimize_job(job, mesh, progress);
  const auto& last = r.simp.history.back();
  result::SurfaceCheck check = result::check_surface(r.surface.V, r.surface.F);
  std::cout << std::setprecision(6) << "simp: " << r.simp.status << ", compliance " << last.compliance
            << " N*mm, volume fraction " << last.volume_fraction << " (" << r.seconds_simp << " s)\n"
            << "surface: threshold " << r.threshold << ", " << r.surface.F.rows() << " triangles, "
            << (check.closed_manifold() ? "closed" : "NOT closed") << ", volume " << check.volume << " mm^3 ("
            << r.seconds_surface << " s)\n";
  for (const auto& p : pipeline::write_optimize_outputs(mesh, r, job.output_dir)) std::cout << "wrote " << p << "\n";
  return 0;
}

}  // namespace topopt::cli
