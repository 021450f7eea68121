// The optimisation path of a job: SIMP on its mesh with its supports, loads and
// "optimization" settings, then the result shape at the volume-matching threshold, smoothed;
// and the files that record it. run_job (run_job.h) is the whole path from the job.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "common/progress.h"
#include "pipeline/job.h"
#include "result/design_hygiene.h"
#include "result/design_surface.h"
#include "result/iso_surface.h"
#include "result/smoothing.h"
#include "simp/optimizer.h"

namespace topopt::result {
class SourceFaces;  // result/step_export_analytic.h
}  // namespace topopt::result

namespace topopt::pipeline {

/// The SIMP run of optimize_job, with simp::optimize's arguments and answer: simp::optimize
/// itself (serial) or the distributed one (dist/dist_run.h: optimize_on_ranks under mpirun).
using SimpRunner =
    std::function<simp::SimpResult(const TetMesh&, const fem::Material&, const fem::Supports&, const Eigen::MatrixXd&,
                                   const std::vector<double>&, const simp::SimpParams&, const Progress&,
                                   const std::function<void(const simp::IterationRecord&)>&, const Eigen::Matrix3Xd&)>;

struct OptimizeResult {
  simp::SimpResult simp;
  double threshold = 0;
  result::TriSurface surface;  ///< smoothed, closed, of the cleaned densities
  VecXd design;                ///< #T element densities after hygiene (what the surface is cut from)
  result::HygieneReport hygiene;
  result::DesignSurfaceReport surface_report;  ///< remeshing, repair and the surface's final check
  double seconds_simp = 0, seconds_surface = 0;
  int ranks = 1;  ///< MPI ranks SIMP ran on (1: serial)
};

/// Runs SIMP on `mesh` with the job's supports, loads and job.optimization, then extracts and
/// smooths the shape. on_iteration gets every iteration. Before SIMP, throws
/// Error(InvalidParameter) for a load case that puts no force on the part or only loads
/// supported nodes, or a filter radius larger than the part, and Error(TooLarge) for a
/// filter that would not fit in memory (problem_checks.h); then what fem and simp throw
/// (NoSupport, Cancelled). runner: the SIMP run (empty: simp::optimize). With
/// job.optimization.keep_loaded_faces, SIMP sees the loaded_face_layer of the loaded and
/// supported faces as non-design (solid, density 1; a warning names the faces). `source`
/// (optional): the input's curved faces (pipeline::source_faces, made once per run by run_job),
/// on whose true surfaces the surface's remeshing puts the points it adds inside them.
OptimizeResult optimize_job(const Job& job, const TetMesh& mesh, const Progress& progress = {},
                            const std::function<void(const simp::IterationRecord&)>& on_iteration = {},
                            const SimpRunner& runner = {}, const result::SourceFaces* source = nullptr);

/// The hygiene of a job's result on `mesh`: settings.hygiene with the bridges' diameter (the
/// non-design solids joined, result::HygieneParams::bridge_size) the minimum member size when
/// set (controls.member.min_size), else the density filter's diameter (twice the radius SIMP
/// uses on this mesh, simp::filter_radius); and that minimum member size held on the crisp
/// design (result::HygieneParams::min_member_size, result/member_enforce.h).
result::HygieneParams hygiene_params(const TetMesh& mesh, const OptimizeSettings& settings);

/// The faces of Ω a support or a force or pressure of `job` acts on (1-based, ascending;
/// gravity has none).
std::vector<int> loaded_faces(const Job& job);

/// keep_loaded_faces: the design tets (domain 0, all tets without tags) with a node on a
/// boundary triangle of one of `faces` (Ω's, 1-based): one layer of tets, what a load or a
/// support there needs of material. Returns #T flags; on_face (optional) gets those of
/// `faces` that have such tets.
std::vector<char> loaded_face_layer(const TetMesh& mesh, const std::vector<int>& faces,
                                    std::vector<int>* on_face = nullptr);

/// The nodes where a support (result::kAnchorSupport) or a force or pressure
/// (result::kAnchorLoad) acts: #V flags, what the design must connect. Gravity acts
/// everywhere and does not count.
std::vector<char> anchor_nodes(const TetMesh& mesh, const Job& job);

/// The surface stage's settings of a job: set.smooth, and with an enabled overhang control its
/// build (result::BuildDirection: the unit direction, the angle, the plate's height on `mesh` by
/// simp::base_plate_height), so that the result surface's too-flat downward facets are lifted
/// back to the angle (result/overhang_lift.h). Every extraction of a job's result (its run,
/// `topopt result`) takes its settings here.
result::SmoothParams surface_settings(const OptimizeSettings& set, const TetMesh& mesh);

/// How a re-extraction of a stored result is made as its run made it (the worker's
/// extract_surface, the threshold slider, the Python module's extract_surface): the surface
/// settings (surface_settings; a control standing the part on a base face that a stored mesh
/// without face numbers cannot place extracts without the overhang lift, with a warning), the
/// hygiene (hygiene_params: fill_voids, the bridges' size) and the anchors (anchor_nodes), all
/// from the study's job.
struct Reextraction {
  result::SmoothParams smooth;
  result::HygieneParams hygiene;
  std::vector<char> anchors;          ///< #V, or empty: the largest piece is kept
  std::vector<std::string> warnings;  ///< where the stored mesh cannot give what the run had
};

/// The Reextraction of `job` (its supports and loads may be empty: only its optimization section
/// is then known) on the stored `mesh`. The anchors need the run's boundary triangles and their
/// face numbers (mesh.F, mesh.face; mesh.nd_face for a non-design face): without them, or when
/// they do not hold a support's or load's face, a job with supports and loads is cleaned keeping
/// the largest piece, and a warning says the shape may differ from the run's.
Reextraction reextraction(const Job& job, const TetMesh& mesh);

/// The result shape of element densities (#T) at a threshold (< 0: the one that keeps
/// `volume_fraction` of the design domain, found on the densities as given), cleaned by
/// result::clean_design at that threshold (anchors: #V, see anchor_nodes; empty: keep the
/// largest piece), then finished: remeshed, smoothed, crossings repaired
/// (result::finish_design_surface), and its pieces checked by the hygiene's rule
/// (result::clean_surface_pieces, the anchors' faces: a piece of design material only that the
/// cut or the smoothing left apart from the loads is taken out, named in `report` and a
/// warning). `threshold_used`, `report`, `design` (#T, the cleaned
/// densities) and `surface_report` are optional outputs; the report's warnings are also given
/// to progress.warn. Throws Error(MeshingFailed) naming the threshold when the finished
/// surface is open or still crosses itself (with smooth.repair off a crossing surface is
/// returned with a warning instead). `source` (optional): the input's curved faces; with it the
/// remeshing may split edges inside Ω's curved faces, the new points on their true surfaces.
result::TriSurface result_surface(const TetMesh& mesh, const VecXd& density, double threshold, double volume_fraction,
                                  const result::SmoothParams& smooth, double* threshold_used = nullptr,
                                  const std::vector<char>& anchors = {}, const result::HygieneParams& hygiene = {},
                                  result::HygieneReport* report = nullptr, VecXd* design = nullptr,
                                  const Progress& progress = {}, result::DesignSurfaceReport* surface_report = nullptr,
                                  const result::SourceFaces* source = nullptr);

/// Writes DIR/density.vtu (fields "density", SIMP's, and "design", after hygiene),
/// DIR/history.csv, DIR/history.json (with the hygiene report under "design") and
/// DIR/result.stl (each under a temporary name, then renamed). `dir` must exist (prepare_output_folder). Returns the
/// paths written.
std::vector<std::string> write_optimize_outputs(const TetMesh& mesh, const OptimizeResult& r, const std::string& dir);

}  // namespace topopt::pipeline
