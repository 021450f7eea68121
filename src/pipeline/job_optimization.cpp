// The "optimization" section of a job (docs/optimization.md): every SIMP setting typed and
// range-checked here, once.
#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>

#include "common/error.h"
#include "pipeline/job.h"
#include "pipeline/job_fields.h"
#include "simp/controls/overhang_filter.h"

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
  p.tol_change = f.number("tol_change", p.tol_change);
  if (!(p.tol_change > 0 && p.tol_change <= 1)) f.bad("tol_change", "must lie in (0, 1]");
  p.tol_objective = f.number("tol_objective", p.tol_objective);
  if (!(p.tol_objective > 0 && p.tol_objective < 1)) f.bad("tol_objective", "must lie in (0, 1)");
}

/// One entry of "displacement_limits": {"faces": ["Face7"], "direction": [0, 0, -1], "limit": 0.5}.
DisplacementSpec parse_displacement_limit(const json& item, const std::string& where) {
  const Fields f(item, where, {"faces", "direction", "limit"},
                 "{\"faces\": [\"Face7\"], \"direction\": [0, 0, -1], \"limit\": 0.5}");
  DisplacementSpec d;
  d.unit.kind = fem::LoadSpec::Kind::Force;
  const std::string form =
      "must be a non-empty list of face names such as [\"Face7\"]: the faces whose mean "
      "displacement is limited";
  if (!f.has("faces") || !f.at("faces").is_array() || f.at("faces").empty()) f.bad("faces", form);
  for (const auto& name : f.at("faces")) {
    if (!name.is_string()) f.bad("faces", form);
    parse_face_name(name.get<std::string>(), d.unit.faces, d.unit.nd_faces);
  }
  const std::array<double, 3> v = f.vec3("direction");
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(n > 0))
    f.bad("direction", "must not be zero: give the direction of the displacement to limit, e.g. [0, 0, -1]");
  d.unit.vector = {v[0] / n, v[1] / n, v[2] / n};
  if (!f.has("limit")) f.bad("limit", "is missing: the largest displacement allowed along the direction, in mm");
  d.limit = f.number("limit", 0);
  if (!(d.limit > 0 && d.limit < 1e6)) f.bad("limit", "must lie in (0, 1e6) mm");
  std::ostringstream s;
  s << where << " (" << f.at("faces").dump() << " along (" << d.unit.vector[0] << ", " << d.unit.vector[1] << ", "
    << d.unit.vector[2] << "))";
  d.name = s.str();
  return d;
}

/// "objective", "compliance_limit", "displacement_limits" and the stress limit's keys; the update defaults to MMA when
/// they ask for more than compliance under a volume fraction, and "oc" is refused then.
void parse_responses(const Fields& f, OptimizeSettings& s) {
  simp::ResponseParams& r = s.simp.responses;
  const std::string objective = f.choice("objective", "compliance", {"compliance", "mass", "frequency"},
                                         "compliance: stiffest design of the volume fraction; mass: lightest design "
                                         "within the limits; frequency: the highest first eigenfrequency of the volume "
                                         "fraction");
  r.objective = objective == "mass"        ? simp::Objective::Mass
                : objective == "frequency" ? simp::Objective::Frequency
                                           : simp::Objective::Compliance;
  r.compliance_limit = f.number("compliance_limit", 0);
  if (f.has("compliance_limit") && !(r.compliance_limit > 0 && r.compliance_limit < 1e15))
    f.bad("compliance_limit", "must be a positive compliance in N·mm (Σ weight × Fᵀu), below 1e15");
  if (f.has("compliance_limit") && r.objective != simp::Objective::Mass)
    f.bad("compliance_limit", "goes with \"objective\": \"mass\" only");
  if (f.has("displacement_limits")) {
    const json& list = f.at("displacement_limits");
    if (!list.is_array()) f.bad("displacement_limits", "must be a list of {\"faces\", \"direction\", \"limit\"}");
    for (size_t i = 0; i < list.size(); ++i)
      s.displacement_limits.push_back(
          parse_displacement_limit(list[i], f.name("displacement_limits") + "[" + std::to_string(i) + "]"));
  }
  r.stress_limit = f.number("stress_limit", 0);
  if (f.has("stress_limit") && !(r.stress_limit > 0 && r.stress_limit < 1e9))
    f.bad("stress_limit",
          "must be a positive von Mises stress in MPa, below 1e9 (e.g. the yield stress / a safety factor)");
  r.stress_pnorm = f.number("stress_pnorm", r.stress_pnorm);
  if (!(r.stress_pnorm >= 2 && r.stress_pnorm <= 64))
    f.bad("stress_pnorm",
          "must lie in [2, 64] (8 is usual; larger follows the largest stress closer but converges worse)");
  r.stress_relaxation = f.number("stress_relaxation", r.stress_relaxation);
  if (!(r.stress_relaxation > 0 && r.stress_relaxation <= 1))
    f.bad("stress_relaxation", "must lie in (0, 1] (0.5 is usual: the exponent q of the relaxed stress ρ^q σ)");
  if (r.objective == simp::Objective::Mass && r.compliance_limit <= 0 && s.displacement_limits.empty() &&
      r.stress_limit <= 0)
    f.bad("objective",
          "\"mass\" needs a limit: add \"compliance_limit\" (N·mm), \"displacement_limits\" or \"stress_limit\" (MPa)");
  const bool beyond =
      r.objective != simp::Objective::Compliance || !s.displacement_limits.empty() || r.stress_limit > 0;
  if (beyond && f.has("update") && s.simp.update == simp::UpdateKind::OC)
    f.bad("update",
          "must be \"mma\" with a mass objective, displacement limits or a stress limit (OC handles one volume "
          "constraint only); leave it out to get MMA");
  if (beyond) s.simp.update = simp::UpdateKind::MMA;
}

/// The direction [x, y, z] at `key` (required): finite and not all zero.
Eigen::Vector3d vector3(const Fields& f, const std::string& key) {
  const std::array<double, 3> v = f.vec3(key);
  if (v[0] == 0 && v[1] == 0 && v[2] == 0) f.bad(key, "must not be [0, 0, 0]: give the direction in model axes");
  return {v[0], v[1], v[2]};
}

/// A list of objects at `key`, each read by `one` (its Fields).
void each_item(const Fields& f, const std::string& key, const std::function<void(const Fields&)>& one,
               const std::vector<std::string>& keys, const std::string& example) {
  if (!f.has(key)) return;
  if (!f.at(key).is_array()) f.bad(key, "must be a list such as [" + example + "]");
  for (size_t i = 0; i < f.at(key).size(); ++i)
    one(Fields(f.at(key)[i], f.name(key) + "[" + std::to_string(i) + "]", keys, example));
}

/// "controls"."draw_direction": {"direction": [x, y, z], "parting_point": [x, y, z] (split
/// casting when given), "cell": mm, "smoothness"} (docs/optimization.md).
void parse_draw_direction(const Fields& controls, simp::DrawDirection& d) {
  if (!controls.has("draw_direction")) return;
  const Fields f(controls.at("draw_direction"), controls.name("draw_direction"),
                 {"direction", "parting_point", "cell", "smoothness"},
                 "{\"direction\": [0, 0, 1], \"parting_point\": [0, 0, 10]}");
  d.enabled = true;
  d.direction = vector3(f, "direction");
  d.split = f.has("parting_point");
  if (d.split) d.parting_point = Eigen::Vector3d(f.vec3("parting_point").data());
  d.cell = f.number("cell", 0);
  if (d.cell < 0) f.bad("cell", "must be positive (mm, the side of the draw grid's cells), or 0 for the tolerance");
  d.smoothness = f.number("smoothness", d.smoothness);
  if (!(d.smoothness > 0 && d.smoothness <= 0.01))
    f.bad("smoothness", "must lie in (0, 0.01] (the ε of the smooth maximum along the columns; 1e-4 is usual)");
}

/// "controls"."overhang": {"direction": [x, y, z], "angle": degrees, "base_face": "FaceN",
/// "margin": degrees, "cell": mm, "exponent", "xi0", "smoothness"} (docs/optimization.md).
void parse_overhang(const Fields& controls, simp::OverhangControl& o) {
  if (!controls.has("overhang")) return;
  const Fields f(controls.at("overhang"), controls.name("overhang"),
                 {"direction", "angle", "margin", "base_face", "cell", "exponent", "xi0", "smoothness"},
                 "{\"direction\": [0, 0, 1], \"angle\": 45, \"base_face\": \"Face5\"}");
  o.enabled = true;
  o.direction = vector3(f, "direction");
  o.angle = f.number("angle", o.angle);
  o.margin = f.number("margin", std::min(o.margin, std::max(0.0, 85 - o.angle)));  // the default fits any angle
  if (f.has("base_face")) {
    std::vector<int> faces, nondesign;
    if (!f.at("base_face").is_string()) f.bad("base_face", "must be a face name such as \"Face5\"");
    parse_face_name(f.at("base_face").get<std::string>(), faces, nondesign);
    if (faces.empty()) f.bad("base_face", "must be a face of the part (\"Face5\"), not of a non-design solid");
    o.base_face = faces[0];
  }
  o.cell = f.number("cell", 0);
  if (o.cell < 0) f.bad("cell", "must be positive (mm, the overhang lattice's spacing), or 0 for the tolerance");
  o.exponent = f.number("exponent", o.exponent);
  o.xi0 = f.number("xi0", o.xi0);
  o.smoothness = f.number("smoothness", o.smoothness);
  // the ranges are the filter's (one place decides); reported under the key's path in the job
  if (const simp::OverhangProblem problem = simp::overhang_problem(o); !problem.key.empty())
    f.bad(problem.key, problem.what);
}

/// "controls"."min_member_size" and "max_member_size" (mm) with their options (docs/optimization.md).
void parse_member_size(const Fields& f, simp::MemberSizeParams& m) {
  m.min_size = f.number("min_member_size", 0);
  if (f.has("min_member_size") && !(m.min_size > 0 && m.min_size < 1e6))
    f.bad("min_member_size", "must be a positive size in mm (the thinnest member and gap; at least 2 mesh sizes)");
  m.eta_shift = f.number("min_member_eta_shift", m.eta_shift);
  if (!(m.eta_shift > 0.05 && m.eta_shift < 0.45))
    f.bad("min_member_eta_shift", "must lie in (0.05, 0.45) (0.25 is usual)");
  m.max_size = f.number("max_member_size", 0);
  if (f.has("max_member_size") && !(m.max_size > 0 && m.max_size < 1e6))
    f.bad("max_member_size", "must be a positive size in mm (the widest solid ball allowed; at least 3 mesh sizes)");
  if (m.min_size > 0 && m.max_size > 0 && m.max_size <= m.min_size)
    f.bad("max_member_size", "must be larger than min_member_size");
  m.max_solid = f.number("max_member_solid", m.max_solid);
  if (!(m.max_solid > 0.5 && m.max_solid < 1))
    f.bad("max_member_solid", "must lie in (0.5, 1) (0.9 is usual: the largest solid share of a ball)");
  m.pnorm = f.number("max_member_pnorm", m.pnorm);
  if (!(m.pnorm >= 4 && m.pnorm <= 64)) f.bad("max_member_pnorm", "must lie in [4, 64] (16 is usual)");
}

/// "controls": {"symmetry_planes": [{"point", "normal"}], "cyclic": [{"point", "axis",
/// "sectors"}], "patterns": [{"direction", "pitch", "count"}], "extrusion": [x, y, z],
/// "draw_direction": {...}, "overhang": {...}, "tolerance", member sizes} (docs/optimization.md).
void parse_controls(const Fields& opt, simp::ControlsParams& c) {
  if (!opt.has("controls")) return;
  const Fields f(opt.at("controls"), opt.name("controls"),
                 {"symmetry_planes", "cyclic", "patterns", "extrusion", "draw_direction", "overhang", "tolerance",
                  "min_member_size", "min_member_eta_shift", "max_member_size", "max_member_solid", "max_member_pnorm"},
                 "{\"symmetry_planes\": [{\"point\": [0, 0, 0], \"normal\": [0, 1, 0]}]}");
  each_item(
      f, "symmetry_planes",
      [&](const Fields& g) {
        c.mirrors.push_back({Eigen::Vector3d(g.vec3("point").data()), vector3(g, "normal")});
      },
      {"point", "normal"}, "{\"point\": [0, 0, 0], \"normal\": [0, 1, 0]}");
  each_item(
      f, "cyclic",
      [&](const Fields& g) {
        c.cyclic.push_back(
            {Eigen::Vector3d(g.vec3("point").data()), vector3(g, "axis"), g.integer("sectors", 0, 2, 360)});
      },
      {"point", "axis", "sectors"}, "{\"point\": [0, 0, 0], \"axis\": [0, 0, 1], \"sectors\": 6}");
  each_item(
      f, "patterns",
      [&](const Fields& g) {
        const double pitch = g.number("pitch", 0);
        if (!(pitch > 0)) g.bad("pitch", "must be above 0 (mm between copies)");
        c.patterns.push_back({vector3(g, "direction"), pitch, g.integer("count", 0, 2, 10000)});
      },
      {"direction", "pitch", "count"}, "{\"direction\": [1, 0, 0], \"pitch\": 20, \"count\": 3}");
  if (f.has("extrusion")) c.extrude = true, c.extrusion = vector3(f, "extrusion");
  parse_draw_direction(f, c.draw);
  parse_overhang(f, c.overhang);
  c.tolerance = f.number("tolerance", 0);
  if (c.tolerance < 0) f.bad("tolerance", "must be positive (mm), or 0 for the mean edge length");
  parse_member_size(f, c.member);
}

/// What the member sizes ask of the other settings: a minimum size sets the filter radius (so
/// "filter_radius" may not be given) and needs the projection; a maximum size needs MMA, the
/// default then.
void settle_member_size(const Fields& f, OptimizeSettings& s) {
  simp::SimpParams& p = s.simp;
  const simp::MemberSizeParams& m = p.controls.member;
  if (m.min_size > 0) {
    if (f.has("filter_radius"))
      f.bad("filter_radius", "must be left out with controls.min_member_size (the size sets the radius)");
    if (!p.projection.enabled)
      f.bad("heaviside", "must be on with controls.min_member_size (the robust formulation projects three designs)");
    p.filter.radius =
        simp::robust_filter_radius(m.min_size, p.filter.kind, simp::robust_thresholds(p.projection.eta, m.eta_shift));
  }
  if (m.max_size > 0) {
    if (f.has("update") && p.update == simp::UpdateKind::OC)
      f.bad("update",
            "must be \"mma\" with controls.max_member_size (a local volume constraint); leave it out to get MMA");
    p.update = simp::UpdateKind::MMA;
  }
}

}  // namespace

OptimizeSettings parse_optimization(const json& section) {
  const Fields f(
      section, "optimization",
      {"volume_fraction", "penalty", "emin", "filter", "filter_radius", "helmholtz_solver", "sensitivity_filter",
       "heaviside", "update", "move", "max_iterations", "tol_change", "tol_objective", "threshold", "solver",
       "solver_tolerance", "early_solver_tolerance", "smoothing_iterations", "surface_remesh", "surface_repair", "fill_voids",
       "keep_loaded_faces",
       // objectives and constraints (parse_responses)
       "objective", "compliance_limit", "displacement_limits", "stress_limit", "stress_pnorm", "stress_relaxation",
       // geometry controls (parse_controls)
       "controls"},
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
  const std::string hs = f.choice("helmholtz_solver", "auto", {"auto", "jacobi", "multigrid"},
                                  "how the Helmholtz filter's CG is preconditioned");
  p.filter.helmholtz_solver = hs == "jacobi"      ? simp::HelmholtzSolver::Jacobi
                              : hs == "multigrid" ? simp::HelmholtzSolver::Multigrid
                                                  : simp::HelmholtzSolver::Auto;
  p.sensitivity_filter = f.boolean("sensitivity_filter", false);
  parse_heaviside(f, p.projection);
  parse_controls(f, p.controls);
  if (p.sensitivity_filter && p.controls.any())
    f.bad("sensitivity_filter", "must be false with geometry controls (they act through the density filter)");
  p.update = f.choice("update", "oc", {"oc", "mma"}, "optimality criteria or the method of moving asymptotes") == "mma"
                 ? simp::UpdateKind::MMA
                 : simp::UpdateKind::OC;
  parse_solver(f, p.solver);
  p.early_solver_tolerance = f.number("early_solver_tolerance", p.early_solver_tolerance);
  if (!(p.early_solver_tolerance >= 1e-14 && p.early_solver_tolerance <= 1e-2))
    f.bad("early_solver_tolerance", "must lie in [1e-14, 1e-2] (the solver's relative residual before the final beta)");
  parse_stopping(f, p);
  parse_responses(f, s);
  settle_member_size(f, s);
  s.threshold = f.number("threshold", -1);
  if (f.has("threshold") && !(s.threshold > 0 && s.threshold < 1))
    f.bad("threshold", "must lie strictly between 0 and 1, or be null for the one that keeps the volume fraction");
  s.smooth.iterations = f.integer("smoothing_iterations", 20, 0, 1000);
  s.smooth.remesh = f.boolean("surface_remesh", true);
  s.smooth.repair = f.boolean("surface_repair", true);
  s.hygiene.fill_voids = f.boolean("fill_voids", true);
  s.keep_loaded_faces = f.boolean("keep_loaded_faces", true);
  return s;
}

}  // namespace topopt::pipeline
