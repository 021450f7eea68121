// The optimisation path of a job (see optimize_job.h).
#include "pipeline/optimize_job.h"

#include <chrono>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "fem/boundary_conditions.h"
#include "io/stl.h"
#include "io/vtu.h"

namespace topopt::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

[[noreturn]] void bad(const std::string& key, const std::string& what) {
  throw Error(ErrorCode::InvalidParameter, "job file: \"optimization." + key + "\" " + what);
}

double num(const json& o, const char* key, double fallback) {
  if (!o.contains(key) || o[key].is_null()) return fallback;
  if (!o[key].is_number()) bad(key, "must be a number");
  return o[key].get<double>();
}

}  // namespace

OptimizeSettings optimize_settings(const io::Job& job) {
  OptimizeSettings s;
  json o = job.raw.contains("optimization") ? job.raw["optimization"] : json::object();
  if (!o.is_object()) throw Error(ErrorCode::InvalidParameter, "job file: \"optimization\" must be an object");
  auto& p = s.simp;
  p.volume_fraction = num(o, "volume_fraction", 0.3);
  if (!(p.volume_fraction > 0 && p.volume_fraction < 1))
    bad("volume_fraction", "must lie strictly between 0 and 1 (the share of the design domain to keep)");
  p.law.penalty = num(o, "penalty", 3.0);
  if (!(p.law.penalty >= 1 && p.law.penalty <= 10)) bad("penalty", "must lie in [1, 10] (3 is usual)");
  p.law.e_min = num(o, "emin", 1e-9);
  if (!(p.law.e_min > 0 && p.law.e_min < 0.1)) bad("emin", "must lie in (0, 0.1)");
  std::string filter = o.value("filter", "gaussian");
  if (filter == "gaussian")
    p.filter.kind = simp::FilterKind::Gaussian;
  else if (filter == "cone")
    p.filter.kind = simp::FilterKind::Cone;
  else
    bad("filter", "must be \"gaussian\" or \"cone\"");
  p.filter.radius = num(o, "filter_radius", 0);
  if (p.filter.radius < 0) bad("filter_radius", "must be positive (mm), or 0 for automatic");
  p.sensitivity_filter = o.value("sensitivity_filter", false);
  if (o.contains("heaviside") && !o["heaviside"].is_null() && o["heaviside"] != false) {
    p.heaviside = true;
    if (o["heaviside"].is_object()) {
      p.beta_max = num(o["heaviside"], "beta_max", 32);
      p.beta_every = static_cast<int>(num(o["heaviside"], "every", 20));
      if (p.beta_every < 1) bad("heaviside.every", "must be at least 1");
    }
  }
  std::string update = o.value("update", "oc");
  if (update == "oc")
    p.update = simp::UpdateKind::OC;
  else if (update == "mma")
    p.update = simp::UpdateKind::MMA;
  else
    bad("update", "must be \"oc\" or \"mma\"");
  std::string solver = o.value("solver", "auto");
  if (solver == "auto")
    p.solver.kind = fem::SolverKind::Auto;
  else if (solver == "direct")
    p.solver.kind = fem::SolverKind::Direct;
  else if (solver == "iterative")
    p.solver.kind = fem::SolverKind::Iterative;
  else
    bad("solver", "must be \"auto\", \"direct\" (sparse Cholesky) or \"iterative\" (multigrid CG)");
  // SIMP needs the displacements to a few digits only: on the rocker (114 k tets) a relative
  // residual of 1e-5 instead of 1e-6 changed no compliance of the 54-iteration history by more
  // than 6e-8 relative, and took 17 % fewer CG iterations (docs/optimization.md).
  p.solver.tolerance = num(o, "solver_tolerance", 1e-5);
  if (!(p.solver.tolerance >= 1e-14 && p.solver.tolerance <= 1e-2))
    bad("solver_tolerance", "must lie in [1e-14, 1e-2]");
  p.solver.recycle_tolerance = p.solver.tolerance;
  p.move = num(o, "move", 0.2);
  if (!(p.move > 0 && p.move <= 1)) bad("move", "must lie in (0, 1]");
  p.max_iterations = static_cast<int>(num(o, "max_iterations", 100));
  if (p.max_iterations < 1 || p.max_iterations > 10000) bad("max_iterations", "must lie in [1, 10000]");
  p.tol_change = num(o, "tol_change", 0.01);
  p.tol_objective = num(o, "tol_objective", 1e-4);
  s.threshold = num(o, "threshold", -1);
  if (s.threshold >= 1 || s.threshold == 0) bad("threshold", "must lie strictly between 0 and 1, or be null");
  s.smooth.iterations = static_cast<int>(num(o, "smoothing_iterations", 20));
  if (s.smooth.iterations < 0) bad("smoothing_iterations", "must be 0 or more");
  return s;
}

result::TriSurface result_surface(const TetMesh& mesh, const VecXd& density, double threshold, double volume_fraction,
                                  const result::SmoothParams& smooth, double* threshold_used) {
  VecXd nd = result::node_densities(mesh, density);
  double t = threshold > 0 ? threshold : result::threshold_for_volume(mesh, nd, volume_fraction);
  if (threshold_used) *threshold_used = t;
  result::TriSurface s = result::extract_iso_surface(mesh, nd, t);
  if (smooth.iterations > 0) result::smooth_surface(s, smooth);
  return s;
}

OptimizeResult optimize_job(const io::Job& job, const TetMesh& mesh, const Progress& progress,
                            const std::function<void(const simp::IterationRecord&)>& on_iteration) {
  OptimizeSettings set = optimize_settings(job);
  if (job.load_cases.empty())
    throw Error(ErrorCode::InvalidParameter, "the job has no load case: add \"load_cases\" with at least one load");
  fem::Supports supports = fem::make_supports(mesh, job.supports);
  // the weight of the design tets follows their density (gravity_of below)
  Eigen::MatrixXd loads = fem::make_loads(mesh, job.material, job.load_cases);
  std::vector<double> weights;
  for (const auto& lc : job.load_cases) weights.push_back(lc.weight);
  OptimizeResult r;
  auto t0 = std::chrono::steady_clock::now();
  r.simp = simp::optimize(mesh, job.material, supports, loads, weights, set.simp, progress, on_iteration,
                          fem::gravity_of(job.load_cases));
  auto t1 = std::chrono::steady_clock::now();
  progress.say("surface", -1, "extracting the result shape");
  r.surface = result_surface(mesh, r.simp.density, set.threshold, set.simp.volume_fraction, set.smooth, &r.threshold);
  auto t2 = std::chrono::steady_clock::now();
  r.seconds_simp = std::chrono::duration<double>(t1 - t0).count();
  r.seconds_surface = std::chrono::duration<double>(t2 - t1).count();
  return r;
}

std::vector<std::string> write_optimize_outputs(const TetMesh& mesh, const OptimizeResult& r, const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(ErrorCode::Io, "cannot create the output folder " + dir + ": " + ec.message());
  std::vector<std::string> out;
  std::string vtu = (fs::path(dir) / "density.vtu").string();
  io::VtuField d{"density", 1,
                 std::vector<double>(r.simp.density.data(), r.simp.density.data() + r.simp.density.size())};
  io::write_vtu(vtu, mesh, {}, {d});
  out.push_back(vtu);
  std::string csv = (fs::path(dir) / "history.csv").string();
  {
    std::ofstream f(csv);
    f << "iteration,compliance,volume_fraction,change,beta,seconds\n";
    for (const auto& h : r.simp.history)
      f << h.iteration << "," << h.compliance << "," << h.volume_fraction << "," << h.change << "," << h.beta << ","
        << h.seconds << "\n";
    if (!f) throw Error(ErrorCode::Io, "cannot write " + csv);
  }
  out.push_back(csv);
  std::string js = (fs::path(dir) / "history.json").string();
  {
    json j;
    j["status"] = r.simp.status;
    j["converged"] = r.simp.converged;
    j["threshold"] = r.threshold;
    j["seconds"] = {{"simp", r.seconds_simp}, {"surface", r.seconds_surface}};
    j["history"] = json::array();
    for (const auto& h : r.simp.history)
      j["history"].push_back({{"iteration", h.iteration},
                              {"compliance", h.compliance},
                              {"volume", h.volume_fraction},
                              {"change", h.change},
                              {"beta", h.beta},
                              {"seconds", h.seconds}});
    std::ofstream f(js);
    f << j.dump(2) << "\n";
    if (!f) throw Error(ErrorCode::Io, "cannot write " + js);
  }
  out.push_back(js);
  std::string stl = (fs::path(dir) / "result.stl").string();
  io::write_stl(stl, r.surface.V, r.surface.F);
  out.push_back(stl);
  return out;
}

}  // namespace topopt::pipeline
