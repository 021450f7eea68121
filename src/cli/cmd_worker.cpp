// topopt worker REQUEST.json: runs one request of the FreeCAD workbench in its own process, so
// that a crash, abort or hang of OCCT, Gmsh or our code ends this process and never FreeCAD.
// Progress streams as JSON lines on stdout (cli/worker_channel.h); results go to files.
#include <sys/prctl.h>
#include <unistd.h>
#include <Standard_Failure.hxx>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>

#include "brep/occt_guard.h"
#include "brep/report.h"
#include "brep/shape_io.h"
#include "brep/topology_index.h"
#include "brep/two_breps.h"
#include "cli/commands.h"
#include "cli/worker_channel.h"
#include "common/error.h"
#include "common/tet_boundary.h"
#include "fem/boundary_conditions.h"
#include "io/npy.h"
#include "mesh/core/tet_quality.h"
#include "mesh/surface/surface_check.h"
#include "mesh/surface/surface_mesher.h"
#include "pipeline/job.h"
#include "pipeline/job_mesh.h"
#include "pipeline/optimize_job.h"
#include "pipeline/output_files.h"
#include "pipeline/result_files.h"
#include "pipeline/run_job.h"
#include "pipeline/solve_job.h"
#include "pipeline/surface_job.h"

namespace topopt::cli {
namespace {
namespace fs = std::filesystem;
using json = nlohmann::json;

const char* kUsage =
    "usage: topopt worker REQUEST.json\n"
    "  Runs one request of the FreeCAD workbench out of FreeCAD's process. REQUEST.json:\n"
    "    {\"operation\": \"optimize\" | \"mesh\" | \"info\" | \"surface_mesh\" | \"extract_surface\",\n"
    "     \"job\": {...} (the job, inline: optimize, mesh), \"part\", \"nondesign\": shape files\n"
    "     (BREP/STEP), \"arrays\": {\"nodes\": \"nodes.npy\", ...} (extract_surface: nodes, tets,\n"
    "     domain, densities, and the run's boundary_triangles, boundary_faces,\n"
    "     boundary_nondesign_faces; its \"job\", optional: the study's job, cleaned and finished as\n"
    "     its run was: supports and loads (with the boundary: the pieces kept), the optimization\n"
    "     section's surface settings and hygiene; or that section alone),\n"
    "     \"params\": {...} (info: tolerance;\n"
    "     surface_mesh: size, wall_layers;\n"
    "     extract_surface: threshold, volume_fraction, smoothing_iterations, step: 1 also writes\n"
    "     DIR/result.step, the shape as one CAD solid, its curved faces analytic when \"part\"\n"
    "     is given, join_non_design: 0 leaves the non-design solids apart;\n"
    "     step_max_triangles: its triangle budget as the job's output key, 0: none;\n"
    "     optimize: result_first: 1 writes result.json and prints {\"stage\":\n"
    "     \"result\"} before the verification, result.json again after it),\n"
    "     \"output\": DIR}\n"
    "  Relative paths are taken from REQUEST.json's folder. Prints one JSON object per line:\n"
    "  progress {\"stage\", \"fraction\", \"message\"}, iterations {\"iteration\", \"compliance\",\n"
    "  \"volume\", \"change\", \"seconds\"}, {\"warning\"}, and last {\"done\": true} or {\"error\":\n"
    "  {\"code\", \"message\", \"stage\"}}. Writes DIR/result.json (scalars, history, warnings, and\n"
    "  \"arrays\": the names of the DIR/NAME.npy files written; optimize: \"files\", the result files\n"
    "  written as the job's \"output\" asks: result.step, verification.json, verification.vtu).\n"
    "  TOPOPT_FAULT=STAGE[/WORD]:abort|segv|hang (tests only) makes the worker fail at that stage.";

/// A request as the workbench writes it (see kUsage), with its paths made absolute.
struct Request {
  std::string operation;
  json job;
  std::string part, nondesign;
  std::map<std::string, std::string> arrays;
  json params = json::object();
  fs::path base;  ///< the request file's folder
  fs::path output;
};

/// Reads REQUEST.json; relative paths are taken from its folder, the output folder is created.
/// Throws Error(Io) for a missing file, Error(InvalidParameter) naming a malformed key.
Request read_request(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw Error(ErrorCode::Io, "worker request not found: " + path);
  json j = json::parse(f, nullptr, false);
  if (!j.is_object()) throw Error(ErrorCode::InvalidParameter, "worker request " + path + " is not a JSON object");
  const fs::path base = fs::absolute(path).parent_path();
  auto file = [&](const std::string& key) -> std::string {
    if (!j.contains(key) || j[key].is_null() || j[key] == "") return "";
    if (!j[key].is_string()) throw Error(ErrorCode::InvalidParameter, "worker request: \"" + key + "\" is not a path");
    return (base / j[key].get<std::string>()).string();
  };
  Request r;
  r.base = base;
  r.operation = j.value("operation", "");
  r.job = j.value("job", json());
  r.part = file("part");
  r.nondesign = file("nondesign");
  if (j.contains("arrays") && !j["arrays"].is_object())
    throw Error(ErrorCode::InvalidParameter, "worker request: \"arrays\" must map names to NPY files");
  const json arrays = j.value("arrays", json::object());
  for (const auto& [name, value] : arrays.items()) {
    if (!value.is_string())
      throw Error(ErrorCode::InvalidParameter, "worker request: array \"" + name + "\" is not a path");
    r.arrays[name] = (base / value.get<std::string>()).string();
  }
  r.params = j.value("params", json::object());
  r.output = file("output");
  if (r.output.empty()) throw Error(ErrorCode::InvalidParameter, "worker request: \"output\" folder missing");
  std::error_code ec;
  fs::create_directories(r.output, ec);
  if (ec) throw Error(ErrorCode::Io, "cannot create the output folder " + r.output.string() + ": " + ec.message());
  return r;
}

/// params.KEY as a number (`fallback` when absent); Error(InvalidParameter) if not a number.
double param(const Request& r, const std::string& key, double fallback) {
  if (!r.params.contains(key) || r.params[key].is_null()) return fallback;
  if (!r.params[key].is_number())
    throw Error(ErrorCode::InvalidParameter, "worker request: params." + key + " must be a number");
  return r.params[key].get<double>();
}

/// The NPY file the request gives for array `name`, read.
io::NpyArray array_of(const Request& r, const std::string& name) {
  auto it = r.arrays.find(name);
  if (it == r.arrays.end()) throw Error(ErrorCode::InvalidParameter, "worker request: array \"" + name + "\" missing");
  return io::read_npy(it->second);
}

/// Writes `array` to DIR/NAME.npy and lists NAME in result["arrays"].
template <typename Array>
void put_array(json& result, const fs::path& dir, const std::string& name, const Array& array) {
  io::write_npy((dir / (name + ".npy")).string(), array);
  result["arrays"].push_back(name);
}

/// The tet mesh's arrays under the names the workbench reads (as the Python module's dicts).
void put_tet_mesh(json& result, const fs::path& dir, const TetMesh& mesh) {
  put_array(result, dir, "nodes", mesh.V);
  put_array(result, dir, "tets", mesh.T);
  put_array(result, dir, "domain", mesh.domain);
  put_array(result, dir, "boundary_triangles", mesh.F);
  put_array(result, dir, "boundary_faces", mesh.face);
  put_array(result, dir, "boundary_nondesign_faces", mesh.nd_face);
}

/// The result shape's arrays: surface_points #P x 3, surface_triangles #Q x 3, surface_tags #Q.
void put_result_surface(json& result, const fs::path& dir, const result::TriSurface& s) {
  put_array(result, dir, "surface_points", s.V);
  put_array(result, dir, "surface_triangles", s.F);
  put_array(result, dir, "surface_tags", s.tag);
}

/// The request's part and non-design shapes (null shapes where none is given).
std::pair<TopoDS_Shape, TopoDS_Shape> read_shapes(const Request& r, WorkerChannel& ch) {
  std::pair<TopoDS_Shape, TopoDS_Shape> shapes;
  if (!r.part.empty()) {
    ch.progress("read", 0, "reading the part");
    shapes.first = brep::read_shape_file(r.part, "part");
  }
  if (!r.nondesign.empty()) {
    ch.progress("read", 0.5, "reading the non-design solids");
    shapes.second = brep::read_shape_file(r.nondesign, "non-design input");
  }
  return shapes;
}

/// The request's inline job, parsed and checked as a job file is.
pipeline::Job job_of(const Request& r) {
  if (!r.job.is_object()) throw Error(ErrorCode::InvalidParameter, "worker request: \"job\" must be a JSON object");
  return pipeline::parse_job(r.job.dump(), r.base.string());
}

/// info: the shapes checked and classified; result.json holds {"report"} (topopt info --json).
json op_info(const Request& r, WorkerChannel& ch) {
  auto [part, nd] = read_shapes(r, ch);
  if (part.IsNull()) throw Error(ErrorCode::InvalidParameter, "no part given");
  brep::ClassifyParams params;
  params.tolerance = param(r, "tolerance", -1);
  std::vector<std::string> warnings;
  const brep::TwoBReps two = brep::load_two_breps(part, nd, params, ch.make_progress(warnings));
  return {{"report", brep::two_breps_report(two)}, {"warnings", warnings}};
}

/// surface_mesh: the native surface mesh of the part (nodes, triangles, faces) and its checks.
json op_surface_mesh(const Request& r, WorkerChannel& ch) {
  pipeline::MeshSettings settings;
  settings.size = param(r, "size", 0);
  if (!(settings.size >= 0))
    throw Error(ErrorCode::InvalidParameter, "the mesh size must be positive (mm), or 0 for the default");
  settings.wall_layers = mesh::wall_layers_option(param(r, "wall_layers", 0));
  auto shapes = read_shapes(r, ch);
  if (shapes.first.IsNull()) throw Error(ErrorCode::InvalidParameter, "no shape given");
  std::vector<std::string> warnings;
  const Progress progress = ch.make_progress(warnings);
  const brep::TopologyIndex topo = pipeline::checked_topology(shapes.first, "shape", warnings, {}, progress);
  const pipeline::SurfaceJobResult s = pipeline::surface_job(topo, settings, progress);
  json result = {{"failed_faces", s.mesh.failed_faces},
                 {"failure_reasons", s.mesh.reasons},
                 {"open_edges_per_solid", s.open_edges_per_solid},
                 {"self_intersecting_pairs", s.crossings.size()},
                 {"min_angle", s.quality.min_angle},
                 {"share_below_20deg", s.quality.share_below_20},
                 {"warnings", warnings}};
  ch.progress("write", -1, "writing the results");
  put_array(result, r.output, "nodes", s.mesh.V);
  put_array(result, r.output, "triangles", s.mesh.F);
  put_array(result, r.output, "faces", s.mesh.face);
  return result;
}

/// mesh: the job's conformal tagged tet mesh and its quality figures.
json op_mesh(const Request& r, WorkerChannel& ch) {
  const pipeline::Job job = job_of(r);
  auto [part, nd] = read_shapes(r, ch);
  std::vector<std::string> warnings;
  const TetMesh mesh = pipeline::job_mesh(job, {part, nd}, ch.make_progress(warnings));
  const mesh::QualityReport q = mesh::tet_quality(mesh);
  json result = {
      {"min_radius_ratio", q.min_radius_ratio}, {"mean_radius_ratio", q.mean_radius_ratio}, {"warnings", warnings}};
  ch.progress("write", -1, "writing the results");
  put_tet_mesh(result, r.output, mesh);
  return result;
}

/// The static analysis of the last SIMP iterate for the workbench's FEM result: every tet's
/// stiffness scaled by the SIMP law at its final density, the job's first load case (the
/// workbench writes one). Adds "displacement" (#V by 3, mm) and "von_mises" (#T, MPa). Self
/// weight acts here with every tet's full weight, where SIMP weighed design tets by density.
void put_last_iterate(json& result, const fs::path& dir, const pipeline::Job& job, const TetMesh& mesh,
                      const VecXd& density, WorkerChannel& ch, const Progress& progress) {
  simp::SimpLaw law = job.optimization.simp.law;
  if (law.linear_below == 0 && fem::gravity_of(job.load_cases).size() > 0) law.linear_below = 0.1;  // as SIMP does
  VecXd scale(density.size());
  for (long t = 0; t < density.size(); ++t) scale[t] = law.stiffness(density[t]);
  ch.progress("solve", -1, "analysing the last iterate");
  const pipeline::SolveResult s = pipeline::solve_job(job, mesh, {}, scale, progress);
  const MatX3d u =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(s.U.col(0).data(), mesh.V.rows(), 3);
  put_array(result, dir, "displacement", u);
  put_array(result, dir, "von_mises", s.von_mises[0]);
}

/// result["files"]: the names of the result files written so far into the output folder
/// (pipeline::write_result_files: result.step, verification.json and verification.vtu as the
/// job's "output" asks; each may fail alone with a warning), for the workbench to keep them.
void list_result_files(json& result, const pipeline::ResultFiles& files) {
  result["files"] = json::array();
  for (const std::string& path : files.written) result["files"].push_back(fs::path(path).filename().string());
}

void write_result(const fs::path& dir, const json& result);

/// Result first, verification after (params "result_first": 1, with output.verification):
/// result.step as asked and its verification.json, then result.json and the progress line
/// {"stage": "result"} (the workbench shows the result there), then the verification added to
/// the same report (pipeline::add_verification); result.json is written again at the end with
/// every file.
void put_result_files_first(json& result, const fs::path& dir, const pipeline::Job& job, const pipeline::RunResult& run,
                            std::vector<std::string>& warnings, WorkerChannel& ch, const Progress& progress) {
  pipeline::ResultFiles files =
      pipeline::write_result_step_first(job, run.optimization, dir.string(), {}, progress, run.source);
  list_result_files(result, files);
  result["warnings"] = warnings;
  write_result(dir, result);
  ch.progress("result", -1, "the result is ready: verifying it");
  pipeline::add_verification(files, job, run.mesh, run.optimization, dir.string(), {}, progress);
  list_result_files(result, files);
}

/// optimize: mesh, SIMP and the result shape; iterations are streamed as they come.
json op_optimize(const Request& r, WorkerChannel& ch) {
  const pipeline::Job job = job_of(r);
  // the request's shapes, read once: the mesh, the surface's and result.step's curved faces
  // (run.source) come from them
  const auto [part, nd] = read_shapes(r, ch);
  const pipeline::JobShapes shapes{part, nd};
  std::vector<std::string> warnings;
  const pipeline::RunResult run = pipeline::run_job(job, shapes, ch.make_progress(warnings),
                                                    [&ch](const simp::IterationRecord& rec) { ch.iteration(rec); });
  const pipeline::OptimizeResult& o = run.optimization;
  json history = json::array();
  for (const auto& h : o.simp.history)
    history.push_back({{"iteration", h.iteration},
                       {"compliance", h.compliance},
                       {"volume", h.volume_fraction},
                       {"change", h.change},
                       {"seconds", h.seconds}});
  json result = {{"history", history},
                 {"threshold", o.threshold},
                 {"status", o.simp.status},
                 {"seconds", {o.seconds_simp, o.seconds_surface}},
                 {"warnings", warnings}};
  const Progress progress = ch.make_progress(warnings);
  put_last_iterate(result, r.output, job, run.mesh, o.simp.density, ch, progress);
  ch.progress("write", -1, "writing the results");
  put_tet_mesh(result, r.output, run.mesh);
  put_array(result, r.output, "densities", o.simp.density);
  put_result_surface(result, r.output, o.surface);
  if (job.output.verification && param(r, "result_first", 0) != 0)
    put_result_files_first(result, r.output, job, run, warnings, ch, progress);
  else
    list_result_files(
        result, pipeline::write_result_files(job, run.mesh, run.optimization, r.output, {}, progress, run.source));
  result["warnings"] = warnings;  // with those of the last iterate's analysis and the result files
  return result;
}

/// Index array `a` (#rows by cols) as ints, each in [0, limit). Throws InvalidParameter
/// naming the array, the row and the value.
template <typename Out>
Out indices(const io::NpyArray& a, long cols, const std::string& what, long long limit, const std::string& range) {
  const io::RowMatXl m = io::npy_integer(a, cols, what);
  for (long i = 0; i < m.rows(); ++i)
    for (long k = 0; k < m.cols(); ++k)
      if (m(i, k) < 0 || m(i, k) >= limit)
        throw Error(ErrorCode::InvalidParameter,
                    what + ": row " + std::to_string(i) + " holds " + std::to_string(m(i, k)) + ", outside " + range);
  return m.cast<int>();
}

/// The tet mesh and densities of an extract_surface request, every index and length checked.
std::pair<TetMesh, VecXd> checked_densities(const Request& r) {
  TetMesh mesh;
  mesh.V = io::npy_real(array_of(r, "nodes"), 3, "nodes");
  const long nv = mesh.V.rows();
  mesh.T = indices<MatX4i>(array_of(r, "tets"), 4, "tets", nv, "the node numbers 0.." + std::to_string(nv - 1));
  const long nt = mesh.T.rows();
  if (nt == 0) throw Error(ErrorCode::InvalidParameter, "tets: the mesh has no tets");
  if (r.arrays.count("domain")) {
    mesh.domain = indices<VecXi>(array_of(r, "domain"), 1, "domain", 1LL << 30, "0 and above");
    if (mesh.domain.size() != nt)
      throw Error(ErrorCode::InvalidParameter, "domain: " + std::to_string(mesh.domain.size()) + " tags for " +
                                                   std::to_string(nt) + " tets; one per tet expected");
  } else {
    mesh.domain = VecXi::Zero(nt);
  }
  VecXd density = io::npy_real(array_of(r, "densities"), 1, "densities");
  if (density.size() != nt)
    throw Error(ErrorCode::InvalidParameter, "densities: " + std::to_string(density.size()) + " values for " +
                                                 std::to_string(nt) + " tets; one per tet expected");
  return {mesh, density};
}

/// The run's boundary when the request gives it (arrays boundary_triangles #F x 3 and
/// boundary_faces #F, boundary_nondesign_faces #F optional: what the run's mesh answered), put
/// into `mesh`, every index and length checked. Returns whether it was given.
bool take_boundary(const Request& r, TetMesh& mesh) {
  if (!r.arrays.count("boundary_triangles") && !r.arrays.count("boundary_faces")) return false;
  const long nv = mesh.V.rows();
  mesh.F = indices<MatX3i>(array_of(r, "boundary_triangles"), 3, "boundary_triangles", nv,
                           "the node numbers 0.." + std::to_string(nv - 1));
  const auto numbers = [&](const std::string& name) {
    VecXi v = indices<VecXi>(array_of(r, name), 1, name, 1LL << 30, "0 and above");
    if (v.size() != mesh.F.rows())
      throw Error(ErrorCode::InvalidParameter, name + ": " + std::to_string(v.size()) + " numbers for " +
                                                   std::to_string(mesh.F.rows()) + " boundary triangles");
    return v;
  };
  mesh.face = numbers("boundary_faces");
  if (r.arrays.count("boundary_nondesign_faces")) mesh.nd_face = numbers("boundary_nondesign_faces");
  return true;
}

/// The study's part and non-design shapes when the request gives them (op_optimize's files):
/// their curved faces for the STEP, and, unless the request gave the run's boundary
/// (take_boundary), `mesh`'s boundary triangles numbered by the curved face of the part they lie
/// on, so that the result surface's triangles there carry the tags SourceFaces::classify reads.
/// None without a part.
result::SourceFaces source_faces_for(const Request& r, TetMesh& mesh, bool numbered, WorkerChannel& ch) {
  auto [part, nd] = read_shapes(r, ch);
  if (part.IsNull()) return {};
  result::SourceFaces source(part, nd);
  if (numbered) return source;
  mesh.F = boundary_triangles(mesh.T);
  mesh.face = source.part_face_numbers(mesh.V, mesh.F);
  return source;
}

/// The study's job of an extract_surface request: the whole job the run had (with its supports
/// and loads: the result is then cleaned as the run cleaned it) or its optimization section alone.
pipeline::Job study_job(const Request& r) {
  if (!r.job.is_null() && !(r.job.is_object() && (!r.job.contains("optimization") || r.job["optimization"].is_object())))
    throw Error(ErrorCode::InvalidParameter, "worker request: \"job\" must be a JSON object, its \"optimization\" too");
  if (r.job.is_object() && (r.job.contains("supports") || r.job.contains("load_cases"))) return job_of(r);
  pipeline::Job job;
  job.optimization = pipeline::parse_optimization_text(
      r.job.is_object() && r.job.contains("optimization") ? r.job["optimization"].dump() : "");
  return job;
}

/// extract_surface: the result shape of given densities at a threshold (or volume fraction);
/// with "part" (and "nondesign") its STEP has the input's cylinders, cones, spheres and tori
/// as analytic faces, as optimize's result.step.
json op_extract_surface(const Request& r, WorkerChannel& ch) {
  const double threshold = param(r, "threshold", -1), volume_fraction = param(r, "volume_fraction", -1);
  if (!(threshold > 0 && threshold < 1) && !(volume_fraction > 0 && volume_fraction < 1))
    throw Error(ErrorCode::InvalidParameter, "give a threshold in (0, 1) or a volume fraction in (0, 1)");
  const pipeline::Job job = study_job(r);
  ch.progress("read", 0, "reading the densities");
  auto [mesh, density] = checked_densities(r);
  const bool numbered = take_boundary(r, mesh);
  // the run's surface settings, hygiene and anchors from the study's job, before the part's
  // curved faces number a stored mesh without its boundary
  pipeline::Reextraction run = pipeline::reextraction(job, mesh);
  result::SmoothParams& smooth = run.smooth;
  smooth.iterations = static_cast<int>(param(r, "smoothing_iterations", smooth.iterations));
  if (smooth.iterations < 0 || smooth.iterations > 1000)
    throw Error(ErrorCode::InvalidParameter, "smoothing_iterations must lie in [0, 1000]");
  const result::SourceFaces source = source_faces_for(r, mesh, numbered, ch);
  ch.progress("surface", -1, "extracting the result shape");
  double used = 0;
  result::HygieneReport hygiene;
  // the study's JoinNonDesign when given (1: join), else the job's
  run.hygiene.join_non_design = param(r, "join_non_design", run.hygiene.join_non_design ? 1 : 0) != 0;
  const result::TriSurface s =
      pipeline::result_surface(mesh, density, threshold > 0 && threshold < 1 ? threshold : -1, volume_fraction,
                               smooth, &used, run.anchors, run.hygiene, &hygiene, nullptr, {}, nullptr,
                               source.size() > 0 ? &source : nullptr);
  hygiene.warnings.insert(hygiene.warnings.end(), run.warnings.begin(), run.warnings.end());
  json result = {{"threshold", used}, {"warnings", hygiene.warnings}, {"min_feature", hygiene.min_feature}};
  ch.progress("write", -1, "writing the results");
  put_result_surface(result, r.output, s);
  if (param(r, "step", 0) != 0) {  // the shape at this threshold as one CAD solid, DIR/result.step
    ch.progress("step", -1, "writing the result as a STEP solid");
    result::StepExportParams params;  // the study's budget when it sends one (its job's output.step_max_triangles)
    const double budget = param(r, "step_max_triangles", -1);
    if (budget > 2e9) throw Error(ErrorCode::InvalidParameter, "step_max_triangles must lie in [0, 2000000000]");
    if (budget >= 0) params.max_triangles = static_cast<long>(budget);
    const result::StepExportReport step =
        result::write_result_step((fs::path(r.output) / "result.step").string(), s, params, {}, &source);
    result["step"] = {{"faces", step.faces},
                      {"triangles", step.triangles},
                      {"volume", step.volume},
                      {"bytes", step.bytes},
                      {"seconds", step.seconds}};
    result["files"] = json::array({"result.step"});
  }
  return result;
}

/// Runs the request's operation; returns what goes into result.json.
json run_operation(const Request& r, WorkerChannel& ch) {
  const std::map<std::string, json (*)(const Request&, WorkerChannel&)> ops{{"info", op_info},
                                                                            {"surface_mesh", op_surface_mesh},
                                                                            {"mesh", op_mesh},
                                                                            {"optimize", op_optimize},
                                                                            {"extract_surface", op_extract_surface}};
  auto it = ops.find(r.operation);
  if (it == ops.end())
    throw Error(ErrorCode::InvalidParameter, "worker request: unknown operation '" + r.operation +
                                                 "' (optimize, mesh, info, surface_mesh, extract_surface)");
  json result = it->second(r, ch);
  if (!result.contains("arrays")) result["arrays"] = json::array();
  return result;
}

/// The worker ends with the process that started it (FreeCAD), even if that one is killed.
void end_with_parent() {
  const pid_t parent = ::getppid();
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(1);
}

/// Writes DIR/result.json.
void write_result(const fs::path& dir, const json& result) {
  const std::string path = (dir / "result.json").string();
  std::ofstream f(path);
  f << result.dump(-1, ' ', false, json::error_handler_t::replace) << "\n";
  if (!f) throw Error(ErrorCode::Io, "cannot write " + path);
}

}  // namespace

int cmd_worker(const Args& args) {
  ArgReader a(args, kUsage);
  if (a.print_help()) return 0;
  const std::vector<std::string> pos = a.positionals();
  if (pos.size() != 1) throw Error(ErrorCode::InvalidParameter, "give one request file\n" + a.usage());
  end_with_parent();
  WorkerChannel ch;
  try {
    OCC_CATCH_SIGNALS  // an access violation inside OCCT comes back here as an error line
        ch.inject_at(fault_from_environment());
    const Request r = read_request(pos[0]);
    write_result(r.output, run_operation(r, ch));
    ch.done();
    return 0;
  } catch (const Error& e) {
    ch.error(error_code_name(e.code()), e.what());
  } catch (const Standard_Failure& e) {
    const Error error = brep::occt_error(e, "working on the request");
    ch.error(error_code_name(error.code()), error.what());
  } catch (const std::bad_alloc&) {
    ch.error("TooLarge", "out of memory: use a coarser mesh size");
  } catch (const std::exception& e) {
    ch.error("Internal", std::string("internal error: ") + e.what());
  }
  return 1;
}

}  // namespace topopt::cli
