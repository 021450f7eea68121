// topopt result: the result shape of a finished optimize run at a threshold the user chooses,
// written as STEP and STL without optimising again.
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli/commands.h"
#include "common/error.h"
#include "io/stl.h"
#include "io/vtu.h"
#include "pipeline/job.h"
#include "pipeline/job_mesh.h"
#include "pipeline/optimize_job.h"
#include "pipeline/output_files.h"
#include "pipeline/result_files.h"
#include "result/step_export.h"

namespace topopt::cli {
namespace {

namespace fs = std::filesystem;

const char* kResultUsage =
    "usage: topopt result JOB.json --threshold T [--out-dir DIR] [--step PATH] [--stl PATH]\n"
    "                              [--coarsen F] [--pcurves] [--facets] [--quiet]\n"
    "  The result shape of a finished 'topopt optimize JOB.json' at the density threshold T in\n"
    "  (0, 1), without optimising again: meshes the job as optimize did (the same mesh), reads\n"
    "  SIMP's densities from DIR/density.vtu, then cleans, smooths and checks the shape at T as\n"
    "  optimize does and writes it as one CAD solid (STEP) and as STL.\n"
    "  --threshold  density threshold in (0, 1) (optimize used the one that keeps the volume fraction)\n"
    "  --out-dir    the run's folder (default: the job's output.directory)\n"
    "  --step       STEP file to write (default DIR/result_T.step, T with two decimals)\n"
    "  --stl        STL file to write as well (default: none)\n"
    "  --coarsen    chordal tolerance of the free-form region's coarsening, as a share of its\n"
    "               median edge (default 0.05; 0: every triangle becomes a face)\n"
    "  --pcurves    also write the edges' 2D curves on their planes (about twice the size)\n"
    "  --facets     leave the part's and the non-design solids' curved faces (bores, bosses) as\n"
    "               facets (default: faces on the input's cylinders, cones, spheres and tori)\n"
    "  --quiet      no progress lines";

/// SIMP's element densities of the run in `dir`, checked against the job's mesh.
VecXd run_densities(const std::string& dir, const TetMesh& mesh) {
  const std::string path = (fs::path(dir) / "density.vtu").string();
  if (!fs::exists(path))
    throw Error(ErrorCode::Io, "'" + path + "' does not exist: run 'topopt optimize' on the job first (or give the " +
                                   "run's folder with --out-dir)");
  long points = 0;
  const std::vector<double> density = io::read_vtu_cell_field(path, "density", &points);
  if (static_cast<long>(density.size()) != mesh.T.rows() || points != mesh.V.rows())
    throw Error(ErrorCode::InvalidParameter,
                "'" + path + "' holds " + std::to_string(density.size()) + " tets and " + std::to_string(points) +
                    " nodes, the job's mesh " + std::to_string(mesh.T.rows()) + " and " +
                    std::to_string(mesh.V.rows()) +
                    ": the job's part or mesh settings changed since that run; run 'topopt optimize' again");
  return Eigen::Map<const VecXd>(density.data(), static_cast<long>(density.size()));
}

std::string default_step_path(const std::string& dir, double threshold) {
  std::ostringstream name;
  name << "result_" << std::fixed << std::setprecision(2) << threshold << ".step";
  return (fs::path(dir) / name.str()).string();
}

}  // namespace

int cmd_result(const Args& args) {
  ArgReader a(args, kResultUsage);
  if (a.print_help()) return 0;
  const double threshold = a.number("threshold", -1);
  std::string out = a.option("out-dir"), step = a.option("step"), stl = a.option("stl");
  result::StepExportParams params;
  params.coarsen.tolerance = a.number("coarsen", params.coarsen.tolerance);
  params.pcurves = a.flag("pcurves");
  const bool quiet = a.flag("quiet"), facets = a.flag("facets");
  const std::vector<std::string> pos = a.positionals();
  if (pos.size() != 1) throw Error(ErrorCode::InvalidParameter, "give one job file\n" + a.usage());
  if (!(threshold > 0 && threshold < 1))
    throw Error(ErrorCode::InvalidParameter, "--threshold takes a density in (0, 1), e.g. --threshold 0.4");
  if (params.coarsen.tolerance < 0 || params.coarsen.tolerance > 0.5)
    throw Error(ErrorCode::InvalidParameter, "--coarsen takes a share of the median edge in [0, 0.5], e.g. 0.05");
  pipeline::Job job = pipeline::read_job(pos[0]);
  params = pipeline::step_params(job, params);
  const std::string dir = out.empty() ? job.output.directory : fs::absolute(out).lexically_normal().string();
  if (step.empty()) step = default_step_path(dir, threshold);
  Progress progress;
  progress.report = [quiet](const std::string& stage, double, const std::string& msg) {
    if (!quiet) std::cerr << "[" << stage << "] " << msg << "\n";
  };
  progress.log = [](LogLevel level, const std::string& msg) {
    if (level == LogLevel::Warning) std::cerr << "warning: " << msg << "\n";
  };
  progress.say("mesh", -1, "meshing the job as the run did");
  const TetMesh mesh = pipeline::job_mesh(job, {}, progress);
  const VecXd density = run_densities(dir, mesh);
  progress.say("surface", -1, "extracting the result shape");
  const result::TriSurface s = pipeline::result_surface(
      mesh, density, threshold, job.optimization.simp.volume_fraction,
      pipeline::surface_settings(job.optimization, mesh), nullptr, pipeline::anchor_nodes(mesh, job),
      pipeline::hygiene_params(mesh, job.optimization), nullptr, nullptr, progress);
  if (!stl.empty()) io::write_stl(stl, s.V, s.F);
  progress.say("step", -1, "writing the result as a STEP solid");
  const result::SourceFaces source = facets ? result::SourceFaces() : pipeline::source_faces(job, {}, progress);
  const result::StepExportReport r = result::write_result_step(step, s, params, progress, &source);
  std::cout << "surface: threshold " << threshold << ", " << s.F.rows() << " triangles, volume "
            << std::setprecision(10) << result::check_surface(s.V, s.F).volume << std::setprecision(6) << " mm^3\n"
            << "step: " << r.faces << " faces (" << r.planar_faces << " planar, " << r.analytic_faces
            << " on the input's curved faces, " << r.analytic_refused << " of those left as facets; "
            << r.unmerged_bodies << " bodies rebuilt after OCCT's check refused them, " << r.facet_bodies
            << " of those without the curved faces) from "
            << r.triangles << " triangles, " << r.bytes / 1e6 << " MB, volume " << r.volume << " mm^3 (" << r.seconds
            << " s, " << r.cpu_seconds << " s CPU)\n"
            << "wrote " << step << "\n";
  if (!stl.empty()) std::cout << "wrote " << stl << "\n";
  return 0;
}

}  // namespace topopt::cli
