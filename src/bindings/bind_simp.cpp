// Python bindings of the whole run (mesh → SIMP → surface) and of the result surface alone.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <atomic>

#include <limits>

#include "bindings/arguments.h"
#include "bindings/bindings.h"
#include "brep/shape_io.h"
#include "common/error.h"
#include "pipeline/job.h"
#include "pipeline/optimize_job.h"
#include "pipeline/run_job.h"
#include "result/step_export.h"
#include "simp/controls/member_measure.h"

namespace topopt::py {
namespace pyb = pybind11;

namespace {

/// extract_surface: the result shape of given densities (a re-extraction without a re-run).
void bind_extract_surface(pyb::module_& m) {
  m.def(
      "extract_surface",
      [](const pyb::object& nodes_arg, const pyb::object& tets_arg, const pyb::object& domain_arg,
         const pyb::object& density_arg, const pyb::object& threshold_arg, const pyb::object& fraction_arg,
         const pyb::object& smoothing_arg, const pyb::object& optimization_arg) {
        const TetMesh mesh = tet_mesh_arg(nodes_arg, tets_arg, domain_arg);
        const double any = std::numeric_limits<double>::max();  // densities stored by FreeCAD may pass 1 by rounding
        const VecXd density = values_arg(density_arg, "densities", mesh.T.rows(), "tet", -any, any);
        const double threshold = number_arg(threshold_arg, "threshold", -any, any);
        const double volume_fraction = number_arg(fraction_arg, "volume_fraction", -any, any);
        const int smoothing_iterations = int_arg(smoothing_arg, "smoothing_iterations", -1, 10000);
        const std::string optimization = text_arg(optimization_arg, "optimization");
        if (!(threshold > 0 && threshold < 1) && !(volume_fraction > 0 && volume_fraction < 1))
          throw Error(ErrorCode::InvalidParameter, "give a threshold in (0, 1) or a volume fraction in (0, 1)");
        result::TriSurface s;
        {
          pyb::gil_scoped_release release;
          // made as the worker's re-extraction makes it (pipeline::reextraction): the surface
          // settings (its overhang lift) and the hygiene (fill_voids, the bridges' size) from the
          // study's optimization section; no boundary faces here, so the largest piece is kept
          pipeline::Job job;
          job.optimization = pipeline::parse_optimization_text(optimization);
          pipeline::Reextraction run = pipeline::reextraction(job, mesh);
          if (!run.warnings.empty()) throw Error(ErrorCode::InvalidParameter, run.warnings.front());
          if (smoothing_iterations >= 0) run.smooth.iterations = smoothing_iterations;
          s = pipeline::result_surface(mesh, density, threshold > 0 && threshold < 1 ? threshold : -1, volume_fraction,
                                       run.smooth, nullptr, {}, run.hygiene);
        }
        return pyb::make_tuple(s.V, s.F);
      },
      pyb::arg("nodes"), pyb::arg("tets"), pyb::arg("domain"), pyb::arg("densities"), pyb::arg("threshold") = -1.0,
      pyb::arg("volume_fraction") = -1.0, pyb::arg("smoothing_iterations") = -1, pyb::arg("optimization") = "",
      R"doc(The smoothed result shape of element densities at a threshold (or at the threshold that keeps
volume_fraction of the design domain). optimization: the job's "optimization" section as JSON text
("" for the defaults); with an overhang control the too-flat downward facets are lifted as in the
run, and its hygiene settings (fill_voids) are honoured as the run honours them; the largest piece
is kept (no supports and loads are known here). smoothing_iterations: -1 for the section's (20 by default). Returns (points #P x 3, triangles #Q x 3), closed and
oriented outwards.)doc");
}

/// design_report: what the design hygiene finds at a threshold (the workbench's slider).
void bind_design_report(pyb::module_& m) {
  m.def(
      "design_report",
      [](const pyb::object& nodes_arg, const pyb::object& tets_arg, const pyb::object& domain_arg,
         const pyb::object& density_arg, const pyb::object& threshold_arg, const pyb::object& fill_voids_arg) {
        const TetMesh mesh = tet_mesh_arg(nodes_arg, tets_arg, domain_arg);
        const double any = std::numeric_limits<double>::max();
        const VecXd density = values_arg(density_arg, "densities", mesh.T.rows(), "tet", -any, any);
        const double threshold = number_arg(threshold_arg, "threshold", 0, 1);
        if (!(threshold > 0 && threshold < 1))
          throw Error(ErrorCode::InvalidParameter, "the threshold must lie strictly between 0 and 1");
        if (!pyb::isinstance<pyb::bool_>(fill_voids_arg))
          throw Error(ErrorCode::InvalidParameter, "fill_voids must be True or False");
        result::HygieneReport rep;
        result::HygieneParams params;
        params.fill_voids = fill_voids_arg.cast<bool>();
        {
          pyb::gil_scoped_release release;
          result::clean_design(mesh, density, threshold, {}, params, rep);
        }
        pyb::dict d;
        d["pieces"] = rep.pieces;
        d["voids_filled"] = rep.voids_filled;
        d["void_volume_filled"] = rep.void_volume_filled;
        d["voids_kept"] = rep.voids_kept;
        d["void_volume_kept"] = rep.void_volume_kept;
        d["min_feature"] = rep.min_feature;
        d["warnings"] = rep.warnings;
        return d;
      },
      pyb::arg("nodes"), pyb::arg("tets"), pyb::arg("domain"), pyb::arg("densities"), pyb::arg("threshold"),
      pyb::arg("fill_voids") = true,
      R"doc(What the design hygiene finds at a threshold (the one extract_surface cleans with): a dict with
pieces (solid pieces before cleaning), voids_filled, void_volume_filled, voids_kept,
void_volume_kept (mm³), min_feature (mm, thinnest member) and warnings (list of sentences: loose
pieces removed with their volume, non-design solids apart from the largest piece, voids). For
the workbench's threshold slider, so a re-extraction warns as the optimisation did.)doc");
}

/// measure_members: the member sizes of a crisp design (simp/controls/member_measure.h), for the
/// benchmarks of the minimum and maximum member size.
void bind_member_measure(pyb::module_& m) {
  m.def(
      "measure_members",
      [](const pyb::object& nodes_arg, const pyb::object& tets_arg, const pyb::object& domain_arg,
         const pyb::object& solid_arg, const pyb::object& reach_arg, const pyb::object& gaps_arg) {
        const TetMesh mesh = tet_mesh_arg(nodes_arg, tets_arg, domain_arg);
        const VecXd solid = values_arg(solid_arg, "solid", mesh.T.rows(), "tet", 0, 1);
        simp::MemberMeasureParams params;
        params.reach = number_arg(reach_arg, "reach", 0, std::numeric_limits<double>::max());
        if (!pyb::isinstance<pyb::bool_>(gaps_arg)) throw Error(ErrorCode::InvalidParameter, "gaps must be True or False");
        params.gaps = gaps_arg.cast<bool>();
        simp::MemberMeasure mm;
        {
          pyb::gil_scoped_release release;
          mm = simp::measure_members(mesh, solid, params);
        }
        pyb::dict d;
        d["smallest_member"] = mm.smallest_member;
        d["largest_ball"] = mm.largest_ball;
        d["solid_design"] = mm.solid_design;
        d["thickness"] = mm.thickness;
        return d;
      },
      pyb::arg("nodes"), pyb::arg("tets"), pyb::arg("domain"), pyb::arg("solid"), pyb::arg("reach") = 0.0,
      pyb::arg("gaps") = false,
      R"doc(Member sizes of a crisp design (solid: #T, 1 for solid tets, non-design tets 1): a dict with
smallest_member (mm, the thinnest local thickness over the design's solid tets), largest_ball (mm,
the widest inscribed ball), solid_design (count) and thickness (#T, each tet's local thickness, 0
outside the phase). reach (mm): how far from a ball's centre a tet's centroid may lie and still
count in it (a mesh size reads a tet staircase's corners); gaps: measure the void design tets.
The part's faces do not bound the balls (PartFaces::Clipped, the minimum size's measure).)doc");
}

/// One iteration as Python sees it: {"iteration", "compliance", "volume", "change", "seconds",
/// "displacements", "stress_relaxed", "stress_crisp", "frequency", "frequency_repeated"} (per
/// displacement limit, the largest |u| over the load cases, mm; with a stress limit the largest
/// relaxed von Mises stress and the crisp design's largest, MPa, else 0; with the frequency objective the first
/// eigenfrequency in Hz, else 0).
pyb::dict record_dict(const simp::IterationRecord& rec) {
  pyb::dict d;
  d["iteration"] = rec.iteration, d["compliance"] = rec.compliance, d["volume"] = rec.volume_fraction,
  d["change"] = rec.change, d["seconds"] = rec.seconds, d["displacements"] = rec.displacements,
  d["stress_relaxed"] = rec.stress_relaxed, d["stress_crisp"] = rec.stress_crisp, d["frequency"] = rec.frequency,
  d["frequency_repeated"] = rec.repeated;
  return d;
}

}  // namespace

void bind_simp(pyb::module_& m) {
  m.def(
      "run_job",
      [](const pyb::object& job_arg, const pyb::object& part_arg, const pyb::object& nd_arg, pyb::object callback) {
        const std::string part_brep = text_arg(part_arg, "part_brep"), nd_brep = text_arg(nd_arg, "nondesign_brep");
        if (!callback.is_none() && !PyCallable_Check(callback.ptr()))
          throw Error(ErrorCode::InvalidParameter, "callback must be a function taking a dict, or None");
        const pipeline::Job job = pipeline::parse_job(text_arg(job_arg, "job_json"), "");
        // The callback runs with the GIL held; returning True (or raising) cancels.
        std::atomic<bool> stop{false};
        std::string callback_error;
        auto call = [&](pyb::dict d) {
          if (callback.is_none() || stop) return;
          pyb::gil_scoped_acquire gil;
          try {
            pyb::object r = callback(d);
            if (!r.is_none() && r.cast<bool>()) stop = true;
          } catch (const pyb::error_already_set& e) {
            callback_error = e.what();
            stop = true;
          }
        };
        Progress progress;
        progress.cancelled = [&] { return stop.load(); };
        progress.report = [&](const std::string& stage, double fraction, const std::string& message) {
          if (stage == "simp") return;  // iterations come as records below
          pyb::gil_scoped_acquire gil;
          pyb::dict d;
          d["stage"] = stage, d["fraction"] = fraction, d["message"] = message;
          call(d);
        };
        pipeline::RunResult run;
        {
          pyb::gil_scoped_release release;
          pipeline::JobShapes shapes;
          if (job.mesh.file.empty()) {
            if (part_brep.empty()) throw Error(ErrorCode::InvalidParameter, "no part given");
            shapes.part = brep::read_brep_string(part_brep, "part", {}, progress);  // cancellable
            if (!nd_brep.empty()) shapes.nondesign = brep::read_brep_string(nd_brep, "non-design solids", {}, progress);
          }
          run = pipeline::run_job(job, shapes, progress, [&](const simp::IterationRecord& rec) {
            pyb::gil_scoped_acquire gil;
            call(record_dict(rec));
          });
        }
        if (!callback_error.empty())
          throw Error(ErrorCode::Cancelled, "the progress callback raised: " + callback_error);
        const pipeline::OptimizeResult& r = run.optimization;
        pyb::dict out;
        put_tet_mesh(out, run.mesh);
        out["densities"] = r.simp.density;
        out["warnings"] = run.warnings;
        pyb::list hist;
        for (const auto& h : r.simp.history) hist.append(record_dict(h));
        out["history"] = hist;
        out["threshold"] = r.threshold;
        out["surface_points"] = r.surface.V;
        out["surface_triangles"] = r.surface.F;
        out["surface_tags"] = r.surface.tag;
        out["status"] = r.simp.status;
        out["seconds"] = pyb::make_tuple(r.seconds_simp, r.seconds_surface);
        return out;
      },
      pyb::arg("job_json"), pyb::arg("part_brep") = "", pyb::arg("nondesign_brep") = "",
      pyb::arg("callback") = pyb::none(),
      R"doc(Mesh, optimise and extract the result shape.

job_json: job file text (docs/job-format.md; faces by FreeCAD name). part_brep, nondesign_brep:
BREP strings (Shape.exportBrepToString()), unless the job names a mesh file. callback(dict) is
called with {"stage", "fraction", "message"} while meshing and {"iteration", "compliance",
"volume", "change", "seconds", "displacements", "stress_relaxed", "stress_crisp", "frequency",
"frequency_repeated"} after each iteration (displacements: per displacement limit of the job, the
largest |u| over the load cases in mm; stress_relaxed and stress_crisp: with a stress limit, the
largest relaxed von Mises stress and the crisp design's largest in MPa, else 0; frequency: with "objective": "frequency", the first eigenfrequency in Hz, else 0); returning True cancels (TopOptError with
.code "Cancelled"). Returns a dict: nodes #V x 3, tets #T x 4, domain #T, boundary_triangles,
boundary_faces, boundary_nondesign_faces, densities #T, history (list of dicts), threshold,
surface_points #P x 3, surface_triangles #Q x 3, surface_tags #Q, status, seconds (simp,
surface), warnings (list of strings).)doc");
  bind_extract_surface(m);
  bind_design_report(m);
  // the STEP export's own triangle budget (a job without output.step_max_triangles gets it): the
  // workbench's new studies start from it (topopt.app.study.STEP_MAX_TRIANGLES, tested equal)
  m.attr("STEP_MAX_TRIANGLES") = result::StepExportParams{}.max_triangles;
  bind_member_measure(m);
}

}  // namespace topopt::py
