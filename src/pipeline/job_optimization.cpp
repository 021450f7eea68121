// The "optimization" section of a job (docs/optimization.md): every SIMP setting typed and
// range-checked here, once.
#include "common/error.h"
#include "pipeline/job.h"
#include "pipeline/job_fields.h"

namespace topopt::pipeline {
using nlohmann::json;

namespace {

/// "heaviside": true/null (on, the defaults), false (off) or {"beta_start": 1, "beta_max": 32,
/// "factor": 2, "every": 40, "settle": 2e-3} (on, with those settings).
void parse_heaviside(const Fields& f, simp::ProjectionParams& p) {
  if (!f.has("heaviside")) return;
  const json& h = f.at("heaviside");
  if (h.is_boolean()) {
    p.enabled = h.get<bool>();
    return;
  }
  const Fields sub(h, f.name("heaviside"), {"beta_max", "beta_start", "factor", "every", "settle"},
                   "{\"beta_max\": 32, \"every\": 40} (or true, or false)");
  p.enabled = true;
  p.beta_start = sub.number("beta_start", p.beta_start);
  if (!(p.beta_start >= 1 && p.beta_start <= 1000)) sub.bad("beta_start", "must lie in [1, 1000] (1 is usual)");
  p.beta_max = sub.number("beta_max", p.beta_max);
  if (!(p.beta_max >= p.beta_start && p.beta_max <= 1000))
    sub.bad("beta_max", "must lie in [beta_start, 1000] (32 is usual)");
  p.beta_factor = sub.number("factor", p.beta_factor);
  if (!(p.beta_factor > 1 && p.beta_factor <= 10)) sub.bad("factor", "must lie in (1, 10] (2 is usual)");
  p.max_iterations_per_beta = sub.integer("every", p.max_iterations_per_beta, 1, 10000);
  p.settle_tolerance = sub.number("settle", p.settle_tolerance);
  if (!(p.settle_tolerance > 0 && p.settle_tolerance < 1))
    sub.bad("settle", "must lie in (0, 1) (the relative compliance change per iteration that lets beta rise)");
}

void parse_solver(const Fields& f, fem::SolverParams& s) {
  const std::string kind = f.choice("solver", "auto", {"auto", "direct", "iterative"},
                                    "direct: sparse Cholesky; iterative: multigrid CG; auto: by size");
  s.kind = kind == "direct"      ? fem::SolverKind::Direct
           : kind == "iterative" ? fem::SolverKind::Iterative
                                 : fem::SolverKind::Auto;
  // SIMP needs the displacements to a few digits only: on the rocker (114 k tets) a relative
  // residual of 1e-5 instead of 1e-6 changed no compliance of the 54-iteration history by more
  // than 6e-8 relative, and took 17 % fewer CG iterations (docs/optimization.md).
  s.tolerance = f.number("solver_tolerance", 1e-5);
  if (!(s.tolerance >= 1e-14 && s.tolerance <= 1e-2)) f.bad("solver_tolerance", "must lie in [1e-14, 1e-2]");
  s.recycle_tolerance = s.tolerance;
}

void parse_stopping(const Fields& f, simp::SimpParams& p) {
  p.move = f.number("move", 0.2);
  if (!(p.move > 0 && p.move <= 1)) f.bad("move", "must lie in (0, 1] (the largest change of a density per iteration)");
  p.max_iterations = f.integer("max_iterations", 100, 1, 10000);
  p.tol_change = f.number("tol_change", 0.01);
  if (!(p.tol_change > 0 && p.tol_change <= 1)) f.bad("tol_change", "must lie in (0, 1]");
  p.tol_objective = f.number("tol_objective", 1e-4);
  if (!(p.tol_objective > 0 && p.tol_objective < 1)) f.bad("tol_objective", "must lie in (0, 1)");
}

}  // namespace

OptimizeSettings parse_optimization(const json& section) {
  const Fields f(section, "optimization",
                 {"volume_fraction", "penalty", "emin", "filter", "filter_radius", "sensitivity_filter", "heaviside",
                  "update", "move", "max_iterations", "tol_change", "tol_objective", "threshold", "solver",
                  "solver_tolerance", "smoothing_iterations", "surface_remesh", "surface_repair", "fill_voids"},
                 "{\"volume_fraction\": 0.3}");
  OptimizeSettings s;
  simp::SimpParams& p = s.simp;
  p.volume_fraction = f.number("volume_fraction", 0.3);
  simp::check_volume_fraction(p.volume_fraction, "job file: '" + f.name("volume_fraction") + "'");
  p.law.penalty = f.number("penalty", 3.0);
  if (!(p.law.penalty >= 1 && p.law.penalty <= 10)) f.bad("penalty", "must lie in [1, 10] (3 is usual)");
  p.law.e_min = f.number("emin", 1e-9);
  if (!(p.law.e_min > 0 && p.law.e_min < 0.1)) f.bad("emin", "must lie in (0, 0.1)");
  const std::string filter = f.choice("filter", "auto", {"auto", "gaussian", "cone", "helmholtz"});
  s.filter_automatic = filter == "auto";
  p.filter.kind = filter == "cone"        ? simp::FilterKind::Cone
                  : filter == "helmholtz" ? simp::FilterKind::Helmholtz
                                          : simp::FilterKind::Gaussian;
  p.filter.radius = f.number("filter_radius", 0);
  if (p.filter.radius < 0) f.bad("filter_radius", "must be positive (mm), or 0 for 1.5 x the mean edge length");
  p.sensitivity_filter = f.boolean("sensitivity_filter", false);
  parse_heaviside(f, p.projection);
  p.update = f.choice("update", "oc", {"oc", "mma"}, "optimality criteria or the method of moving asymptotes") == "mma"
                 ? simp::UpdateKind::MMA
                 : simp::UpdateKind::OC;
  parse_solver(f, p.solver);
  parse_stopping(f, p);
  s.threshold = f.number("threshold", -1);
  if (f.has("threshold") && !(s.threshold > 0 && s.threshold < 1))
    f.bad("threshold", "must lie strictly between 0 and 1, or be null for the one that keeps the volume fraction");
  s.smooth.iterations = f.integer("smoothing_iterations", 20, 0, 1000);
  s.smooth.remesh = f.boolean("surface_remesh", true);
  s.smooth.repair = f.boolean("surface_repair", true);
  s.hygiene.fill_voids = f.boolean("fill_voids", true);
  return s;
}

}  // namespace topopt::pipeline
