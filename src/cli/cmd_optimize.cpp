// topopt optimize: mesh → SIMP → result surface for a job file (pipeline::run_job).
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "cli/commands.h"
#include "common/error.h"
#include "pipeline/job.h"
#include "pipeline/run_job.h"
#include "result/iso_surface.h"

namespace topopt::cli {

int cmd_optimize(const Args& args) {
  ArgReader a(args,
              "usage: topopt optimize JOB.json [--out-dir DIR] [--quiet] [--verbose]\n"
              "  Meshes the part (or reads the job's mesh file), runs SIMP with the job's supports,\n"
              "  loads and \"optimization\" settings (docs/optimization.md), extracts the shape at the\n"
              "  threshold that keeps the volume fraction and smooths it. Writes DIR/density.vtu,\n"
              "  DIR/history.csv, DIR/history.json and DIR/result.stl. The whole job is checked, and\n"
              "  DIR made and tested, before any work.\n"
              "  --out-dir  output folder (default: the job's output.directory, or out/ beside it)\n"
              "  --quiet    no line per iteration\n"
              "  --verbose  also the solver's timings");
  if (a.print_help()) return 0;
  std::string out = a.option("out-dir");
  bool quiet = a.flag("quiet"), verbose = a.flag("verbose");
  std::vector<std::string> pos = a.positionals();
  if (pos.size() != 1) throw Error(ErrorCode::InvalidParameter, "give one job file\n" + a.usage());
  pipeline::Job job = pipeline::read_job(pos[0]);
  if (!out.empty()) job.output.directory = std::filesystem::absolute(out).lexically_normal().string();
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
  for (const auto& p : run.written) std::cout << "wrote " << p << "\n";
  return 0;
}

}  // namespace topopt::cli
