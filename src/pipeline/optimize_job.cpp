// The optimisation path of a job (see optimize_job.h).
#include "pipeline/optimize_job.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "common/error.h"
#include "common/number_text.h"
#include "fem/boundary_conditions.h"
#include "io/stl.h"
#include "io/vtu.h"
#include "pipeline/output_files.h"
#include "pipeline/problem_checks.h"
#include "result/curved_faces.h"
#include "result/iso_surface_refine.h"
#include "result/result_check.h"
#include "simp/controls/overhang_carry.h"
#include "simp/controls/overhang_filter.h"
#include "simp/controls/section_grid.h"
#include "simp/density_filter.h"

namespace topopt::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

void write_history_csv(const std::string& path, const simp::SimpResult& simp) {
  std::ofstream f(path);
  f << "iteration,compliance,volume_fraction,change,beta,seconds,grey\n";
  for (const auto& h : simp.history)
    f << h.iteration << "," << h.compliance << "," << h.volume_fraction << "," << h.change << "," << h.beta << ","
      << h.seconds << "," << h.grey << "\n";
  if (!f) throw Error(ErrorCode::Io, "cannot write the iteration history (disk full?)");
}

void write_history_json(const std::string& path, const OptimizeResult& r) {
  json j;
  j["status"] = r.simp.status;
  j["converged"] = r.simp.converged;
  j["ranks"] = r.ranks;
  j["threshold"] = r.threshold;
  j["seconds"] = {{"simp", r.seconds_simp}, {"surface", r.seconds_surface}};
  j["grey"] = r.simp.history.empty() ? 0.0 : r.simp.history.back().grey;
  const result::DesignSurfaceReport& sr = r.surface_report;
  j["surface"] = {{"triangles", r.surface.F.rows()},
                  {"closed", sr.check.closed.closed_manifold()},
                  {"volume", sr.check.closed.volume},
                  {"self_intersections", sr.check.crossings.size()},
                  {"self_intersections_after_smoothing", sr.crossings_smoothed},
                  {"min_angle_free", sr.check.min_angle_free},
                  {"min_angle_faces", sr.check.min_angle_faces},
                  {"min_angle_nondesign", sr.check.min_angle_nondesign},
                  {"collapses", sr.collapses},
                  {"flips", sr.flips},
                  {"moves", sr.moves},
                  {"splits", sr.splits},
                  {"remesh_undone", sr.remesh_undone}};
  const result::HygieneReport& h = r.hygiene;
  json apart = json::array();
  for (const auto& p : h.apart)
    apart.push_back({{"volume", p.volume}, {"nondesign", p.nondesign}, {"removed", p.removed}});
  json bridges = json::array();
  for (const auto& b : h.bridges)
    bridges.push_back({{"nondesign", b.nondesign},
                       {"volume", b.volume},
                       {"length", b.length},
                       {"size", b.size},
                       {"joined", b.joined}});
  const result::MemberEnforcement& m = h.members;
  const json members = {{"size", m.size},
                        {"cell", m.cell},
                        {"smallest_before", m.smallest_before},
                        {"smallest_after", m.smallest_after},
                        {"thinnest_at", m.thinnest_at},
                        {"volume_added", m.volume_added},
                        {"design_volume", m.design_volume},
                        {"tets_added", m.tets_added},
                        {"rounds", m.rounds},
                        {"met", m.met()}};
  j["design"] = {{"pieces", h.pieces},
                 {"min_member", members},
                 {"anchored_pieces", h.anchored_pieces},
                 {"apart", apart},
                 {"bridges", bridges},
                 {"voids_filled", h.voids_filled},
                 {"void_volume_filled", h.void_volume_filled},
                 {"voids_kept", h.voids_kept},
                 {"void_volume_kept", h.void_volume_kept},
                 {"min_feature", h.min_feature},
                 {"min_feature_at", h.min_feature_at},
                 {"warnings", h.warnings}};
  j["history"] = json::array();
  for (const auto& h : r.simp.history)
    j["history"].push_back({{"iteration", h.iteration},
                            {"compliance", h.compliance},
                            {"volume", h.volume_fraction},
                            {"change", h.change},
                            {"beta", h.beta},
                            {"grey", h.grey},
                            {"seconds", h.seconds},
                            {"displacements", h.displacements},
                            {"stress_relaxed", h.stress_relaxed},
                            {"stress_crisp", h.stress_crisp},
                            {"frequency", h.frequency},
                            {"frequency_repeated", h.repeated}});
  std::ofstream f(path);
  f << j.dump(2) << "\n";
  if (!f) throw Error(ErrorCode::Io, "cannot write the iteration history (disk full?)");
}

/// Throws Error(MeshingFailed) for a result surface that is not a valid solid (open, or
/// crossing itself after the repair), saying where and what to change; with the repair off
/// (comparison runs) a crossing surface is only warned about.
void refuse_invalid(const result::ResultCheck& c, double threshold, bool repair, const Progress& progress) {
  if (c.valid()) return;
  std::ostringstream m;
  m << "the result shape at threshold " << threshold << " is not a valid solid: ";
  if (!c.closed.closed_manifold() || c.closed.volume <= 0)
    m << c.closed.unpaired_edges << " triangle edges are not shared by exactly two triangles";
  else
    m << c.crossings.size() << (c.crossings.size() >= 1000 ? " or more" : "")
      << " pairs of its triangles cross each other even with the smoothing undone there";
  m << "; try another \"threshold\", fewer \"smoothing_iterations\" or a smaller mesh \"size\"";
  if (!repair && c.closed.closed_manifold()) return progress.warn(m.str() + " (\"surface_repair\" is off)");
  throw Error(ErrorCode::MeshingFailed, m.str());
}

/// Indexed by Ω face number (mesh.face): the anchor flags (result::kAnchorSupport |
/// kAnchorLoad) every node of the face's boundary triangles has, i.e. the supports and loads
/// that act on the whole face; empty when `anchors` (#V) is.
std::vector<char> face_anchor_flags(const TetMesh& mesh, const std::vector<char>& anchors) {
  if (anchors.empty() || mesh.face.size() != mesh.F.rows() || mesh.F.rows() == 0) return {};
  std::vector<char> flags(std::max(0, static_cast<int>(mesh.face.maxCoeff())) + 1, 0), seen(flags.size(), 0);
  for (long q = 0; q < mesh.F.rows(); ++q) {
    const int f = mesh.face[q];
    if (f <= 0) continue;
    const char all = anchors[mesh.F(q, 0)] & anchors[mesh.F(q, 1)] & anchors[mesh.F(q, 2)];
    flags[f] = seen[f] ? static_cast<char>(flags[f] & all) : all;
    seen[f] = 1;
  }
  return flags;
}

/// `mesh` as SIMP sees it under keep_loaded_faces: the loaded_face_layer of the job's loaded
/// and supported faces tagged non-design (one tag after the last non-design solid), with a
/// warning naming the faces. Returns false (and leaves `held` alone) when there is no layer.
bool hold_loaded_faces(const TetMesh& mesh, const Job& job, const Progress& progress, TetMesh& held) {
  std::vector<int> faces;
  const std::vector<char> layer = loaded_face_layer(mesh, loaded_faces(job), &faces);
  const long count = std::count(layer.begin(), layer.end(), 1);
  if (count == 0) return false;
  held = mesh;
  if (held.domain.size() != held.T.rows()) held.domain = VecXi::Zero(held.T.rows());
  const int tag = held.domain.size() ? held.domain.maxCoeff() + 1 : 1;
  for (long t = 0; t < held.T.rows(); ++t)
    if (layer[t]) held.domain[t] = tag;
  std::string names;
  for (size_t i = 0; i < faces.size(); ++i) names += (i ? ", Face" : "Face") + std::to_string(faces[i]);
  progress.warn("the design material on the loaded or supported " + names + " is kept solid (" + std::to_string(count) +
                " tets, one layer) so that the result holds those faces; set \"optimization.keep_loaded_faces\": "
                "false to let the optimisation remove it");
  return true;
}

/// Under an overhang control (controls.overhang), the design tets under the non-design solids'
/// downward faces (simp::carried_tets) tagged non-design in `held` too (made from `mesh` when
/// `holding` is false; holding is then set), so that SIMP keeps them solid and the control's
/// filter builds on them; with a note. Returns the share of `mesh`'s design volume they take.
double hold_carried_tets(const TetMesh& mesh, const simp::OverhangControl& o, const Progress& progress,
                         bool& holding, TetMesh& held) {
  if (!o.enabled) return 0.0;
  const std::vector<char> carried = simp::carried_tets(mesh, o);
  const long count = std::count(carried.begin(), carried.end(), 1);
  if (count == 0) return 0.0;
  if (!holding) held = mesh;
  holding = true;
  const int tag = held.domain.maxCoeff() + 1;
  const VecXd volume = simp::tet_volumes(mesh);
  double design = 0, taken = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (mesh.domain[t] != 0) continue;
    design += volume[t];
    if (carried[t] && held.domain[t] == 0) held.domain[t] = tag, taken += volume[t];
  }
  progress.info("overhang: " + std::to_string(count) +
                " design tets under the non-design solids' downward faces held solid (" +
                number_text(100 * taken / design, 3) +
                " % of the design volume, counted in the volume fraction) so that the design carries those faces");
  return design > 0 ? taken / design : 0.0;
}

/// SIMP's volume fraction of its design domain when the layer of keep_loaded_faces (share
/// `loaded` of the design volume) stays on top of the fraction and the carried tets (share
/// `carried`) are taken out of it: the same material as without them. Throws
/// Error(InvalidParameter) when the carried tets alone take the whole fraction.
double simp_volume_fraction(double volume_fraction, double loaded, double carried) {
  if (carried <= 0) return volume_fraction;
  const double rest = (volume_fraction * (1 - loaded) - carried) / (1 - loaded - carried);
  if (!(rest > 0))
    throw Error(ErrorCode::InvalidParameter,
                "controls.overhang: the design under the non-design solids' downward faces (" +
                    number_text(100 * carried, 3) + " % of the design domain) takes the whole volume "
                    "fraction: raise optimization.volume_fraction or choose a build direction under which those "
                    "faces do not face down");
  return rest;
}

/// The share of `mesh`'s design volume that hold_loaded_faces tagged non-design in `held`.
double held_share(const TetMesh& mesh, const TetMesh& held) {
  const VecXd volume = simp::tet_volumes(mesh);
  const bool tagged = mesh.domain.size() == mesh.T.rows();
  double design = 0, layer = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (tagged && mesh.domain[t] != 0) continue;
    design += volume[t];
    if (held.domain[t] != 0) layer += volume[t];
  }
  return design > 0 ? layer / design : 0.0;
}

}  // namespace

result::HygieneParams hygiene_params(const TetMesh& mesh, const OptimizeSettings& settings) {
  result::HygieneParams h = settings.hygiene;
  const double min_size = settings.simp.controls.member.min_size;
  h.bridge_size = min_size > 0 ? min_size : 2 * simp::filter_radius(mesh, settings.simp.filter);
  h.min_member_size = min_size;
  const simp::OverhangControl& o = settings.simp.controls.overhang;
  if (o.enabled) h.build_direction = o.direction.normalized();
  return h;
}

std::vector<int> loaded_faces(const Job& job) {
  std::vector<int> faces;
  for (const fem::SupportSpec& s : job.supports) faces.insert(faces.end(), s.faces.begin(), s.faces.end());
  for (const fem::LoadCase& lc : job.load_cases)
    for (const fem::LoadSpec& l : lc.items)
      if (l.kind != fem::LoadSpec::Kind::Gravity) faces.insert(faces.end(), l.faces.begin(), l.faces.end());
  std::sort(faces.begin(), faces.end());
  faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
  return faces;
}

std::vector<char> loaded_face_layer(const TetMesh& mesh, const std::vector<int>& faces, std::vector<int>* on_face) {
  const int top = faces.empty() ? 0 : *std::max_element(faces.begin(), faces.end());
  std::vector<char> wanted(top + 1, 0);
  for (int f : faces)
    if (f > 0) wanted[f] = 1;
  std::vector<int> node_face(mesh.V.rows(), 0);  // a wanted face each node lies on, 0 for none
  for (long q = 0; q < mesh.face.size() && q < mesh.F.rows(); ++q)
    if (mesh.face[q] > 0 && mesh.face[q] <= top && wanted[mesh.face[q]])
      for (int k = 0; k < 3; ++k) node_face[mesh.F(q, k)] = mesh.face[q];
  const bool tagged = mesh.domain.size() == mesh.T.rows();
  std::vector<char> layer(mesh.T.rows(), 0), seen(top + 1, 0);
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (tagged && mesh.domain[t] != 0) continue;
    for (int k = 0; k < 4; ++k)
      if (const int f = node_face[mesh.T(t, k)]; f > 0) layer[t] = 1, seen[f] = 1;
  }
  if (on_face) {
    on_face->clear();
    for (int f = 1; f <= top; ++f)
      if (seen[f]) on_face->push_back(f);
  }
  return layer;
}

std::vector<char> anchor_nodes(const TetMesh& mesh, const Job& job) {
  std::vector<char> anchors(mesh.V.rows(), 0);
  for (int dof : fem::make_supports(mesh, job.supports).dofs) anchors[dof / 3] = result::kAnchorSupport;
  std::vector<fem::LoadCase> cases = job.load_cases;
  for (auto& lc : cases)
    lc.items.erase(std::remove_if(lc.items.begin(), lc.items.end(),
                                  [](const fem::LoadSpec& l) { return l.kind == fem::LoadSpec::Kind::Gravity; }),
                   lc.items.end());
  const Eigen::MatrixXd loads = fem::make_loads(mesh, job.material, cases);
  for (long i = 0; i < loads.rows(); ++i)
    if (loads.row(i).cwiseAbs().maxCoeff() > 0) anchors[i / 3] |= result::kAnchorLoad;
  return anchors;
}

result::SmoothParams surface_settings(const OptimizeSettings& set, const TetMesh& mesh) {
  result::SmoothParams smooth = set.smooth;
  const simp::ControlsParams& c = set.simp.controls;
  if (c.extrude && c.extrusion.norm() > 0) {  // the section grid of simp::DesignMap's spacing
    smooth.extrusion = c.extrusion.normalized();
    smooth.extrusion_spacing = simp::section_spacing(c.tolerance > 0 ? c.tolerance : simp::mean_edge_length(mesh));
  }
  const simp::OverhangControl& o = set.simp.controls.overhang;
  if (!o.enabled) return smooth;
  smooth.build.direction = o.direction.normalized();
  smooth.build.angle = o.angle;
  smooth.build.plate = simp::base_plate_height(mesh, smooth.build.direction, o.base_face);
  smooth.build.margin = o.margin;
  return smooth;
}

namespace {

/// The surface settings of a re-extraction of a stored result (reextraction): surface_settings on
/// `mesh`, without an overhang control's base plate the stored mesh cannot place (said in *warning).
result::SmoothParams stored_surface_settings(OptimizeSettings set, const TetMesh& mesh, std::string* warning) {
  if (warning) warning->clear();
  simp::OverhangControl& o = set.simp.controls.overhang;
  if (o.enabled && o.base_face > 0 && mesh.face.size() == 0) {
    if (warning)
      *warning = "overhang: the stored mesh does not number the part's faces, so the base plate on Face" +
                 std::to_string(o.base_face) +
                 " is unknown here: this shape is extracted without the overhang lift (re-run the study for the "
                 "lifted shape)";
    o.enabled = false;
  }
  return surface_settings(set, mesh);
}

}  // namespace

Reextraction reextraction(const Job& job, const TetMesh& mesh) {
  Reextraction x;
  std::string warning;
  x.smooth = stored_surface_settings(job.optimization, mesh, &warning);
  if (!warning.empty()) x.warnings.push_back(warning);
  x.hygiene = hygiene_params(mesh, job.optimization);
  if (job.supports.empty() && job.load_cases.empty()) return x;  // no anchors asked: the largest piece
  const std::string differ =
      "the result's pieces are cleaned keeping the largest one, not those joined to the supports and loads as "
      "the run did, so this shape may differ from the run's (re-run the study to store its boundary faces)";
  if (mesh.face.size() == 0 || mesh.face.size() != mesh.F.rows()) {
    x.warnings.push_back("the stored mesh does not number the part's faces: " + differ);
    return x;
  }
  try {
    x.anchors = anchor_nodes(mesh, job);
  } catch (const Error& e) {
    x.warnings.push_back(std::string("the supports and loads cannot be placed on the stored mesh (") + e.what() +
                         "): " + differ);
  }
  return x;
}

namespace {

/// Under an overhang control (build active), simp::carried_level of the non-design solids'
/// undersides on `mesh`, its ramp a mean edge; empty without one.
VecXd carried_level(const TetMesh& mesh, const result::BuildDirection& build) {
  if (!build.active()) return {};
  simp::OverhangControl c;
  c.enabled = true;
  c.direction = build.direction;
  c.angle = build.angle;
  c.margin = build.margin;
  return simp::carried_level(mesh, c, simp::mean_edge_length(mesh));
}

/// Under an extrusion (smooth.extrusion): the section field of `density` (#T) the result is cut
/// from (simp::fit_section_field); none without one.
std::optional<simp::SectionField> section_field(const TetMesh& mesh, const VecXd& density,
                                                const result::SmoothParams& smooth) {
  if (smooth.extrusion.squaredNorm() == 0) return std::nullopt;
  return simp::fit_section_field(mesh, density, smooth.extrusion, smooth.extrusion_spacing);
}

/// The node densities the result is cut from: result::node_densities of `density` (#T) — under an
/// extrusion the section field's (simp::section_node_densities of `section`, fitted on the same
/// densities), equal along it — at least `carried` (#V, or empty) so that the design holds the
/// non-design solids' undersides to their edges.
VecXd extraction_densities(const TetMesh& mesh, const VecXd& density, const VecXd& carried,
                           const std::optional<simp::SectionField>& section) {
  VecXd nd = result::node_densities(mesh, density);
  if (section) nd = simp::section_node_densities(mesh, *section, nd);
  if (carried.size() == nd.size()) nd = nd.cwiseMax(carried);
  return nd;
}

/// Under an extrusion: the cut's free points moved onto the level t of the section field the cut
/// was made from (simp::snap_to_section_level), so that the surface is one extruded shape up to
/// its chords. Where the moves make triangles cross (a point snapped past its neighbours on a
/// short edge: cross_sweep's studies 7, 13 and 17 did), result::untangle takes them back towards
/// the cut, which crosses nothing.
void snap_to_extrusion(const std::optional<simp::SectionField>& section, double t, result::TriSurface& s) {
  if (!section) return;
  const MatX3d cut = s.V;
  simp::snap_to_section_level(*section, t, s.V, s.lock);
  result::untangle(s, cut);
}

}  // namespace

result::TriSurface result_surface(const TetMesh& mesh, const VecXd& density, double threshold, double volume_fraction,
                                  const result::SmoothParams& smooth, double* threshold_used,
                                  const std::vector<char>& anchors, const result::HygieneParams& hygiene,
                                  result::HygieneReport* report, VecXd* design, const Progress& progress,
                                  result::DesignSurfaceReport* surface_report, const result::SourceFaces* source) {
  const VecXd carried = carried_level(mesh, smooth.build);
  const double t = threshold > 0
                       ? threshold
                       : result::threshold_for_volume(
                             mesh, extraction_densities(mesh, density, carried, section_field(mesh, density, smooth)),
                             volume_fraction);
  if (threshold_used) *threshold_used = t;
  result::HygieneReport found;
  const VecXd cleaned = result::clean_design(mesh, density, t, anchors, hygiene, found);
  for (const std::string& w : found.warnings) progress.warn(w);
  const double margin = smooth.remesh ? smooth.crossing_margin : 0.0;
  const std::optional<simp::SectionField> section = section_field(mesh, cleaned, smooth);
  const VecXd nd = extraction_densities(mesh, cleaned, carried, section);
  result::TriSurface s;
  if (smooth.resolution > 1) {
    const result::RefinedField fine = result::refine_near_level(mesh, nd, t);
    s = result::extract_iso_surface(fine.mesh, fine.node_density, t, margin);
  } else {
    s = result::extract_iso_surface(mesh, nd, t, margin);
  }
  snap_to_extrusion(section, t, s);
  const result::FaceProjector onto = source ? result::curved_face_projector(*source, s) : result::FaceProjector();
  result::DesignSurfaceReport finished = result::finish_design_surface(s, smooth, {}, onto);
  if (smooth.build.active()) {
    std::ostringstream says;
    says << "overhang: the result surface's downward facets rising less than " << smooth.build.angle
         << " deg from the plate lifted from " << finished.lift.before << " to " << finished.lift.after << " mm2 ("
         << finished.lift.moves << " point moves)";
    progress.info(says.str());
  }
  // the finished surface by the hygiene's rule: a piece the cut or the smoothing left apart
  const int added = result::clean_surface_pieces(s, face_anchor_flags(mesh, anchors), found);
  for (size_t k = found.warnings.size() - added; k < found.warnings.size(); ++k) progress.warn(found.warnings[k]);
  if (added > 0) finished.check = result::check_result(s);
  refuse_invalid(finished.check, t, smooth.repair, progress);
  if (surface_report) *surface_report = finished;
  if (report) *report = std::move(found);
  if (design) *design = cleaned;
  return s;
}

OptimizeResult optimize_job(const Job& job, const TetMesh& mesh, const Progress& progress,
                            const std::function<void(const simp::IterationRecord&)>& on_iteration,
                            const SimpRunner& runner, const result::SourceFaces* source) {
  const OptimizeSettings& set = job.optimization;
  if (job.load_cases.empty())
    throw Error(ErrorCode::InvalidParameter, "the job has no load case: add \"load_cases\" with at least one load");
  const fem::Supports supports = fem::make_supports(mesh, job.supports);
  // the weight of the design tets follows their density (gravity_of below)
  const Eigen::MatrixXd loads = fem::make_loads(mesh, job.material, job.load_cases);
  check_loads_reach_the_part(loads, supports, job.load_cases);
  simp::SimpParams simp = set.simp;
  if (simp.responses.stress_limit > 0) simp.responses.load_cases = job.load_cases;
  std::string filter_note;
  simp.filter = chosen_filter(mesh, set.simp.filter, set.filter_automatic, physical_memory_bytes(), &filter_note);
  if (!filter_note.empty()) progress.info(filter_note);
  std::vector<double> weights;
  for (const auto& lc : job.load_cases) weights.push_back(lc.weight);
  for (const DisplacementSpec& d : set.displacement_limits)
    simp.responses.displacements.push_back(
        {d.name, fem::make_loads(mesh, job.material, {fem::LoadCase{d.name, {d.unit}, 1}}).col(0), d.limit});
  OptimizeResult r;
  const auto t0 = std::chrono::steady_clock::now();
  // keep_loaded_faces: the layer on loaded and supported faces non-design for SIMP, and under an
  // overhang control the design carrying the non-design solids' undersides (taken out of the fraction)
  TetMesh held;
  bool holding = set.keep_loaded_faces && hold_loaded_faces(mesh, job, progress, held);
  const double loaded = holding ? held_share(mesh, held) : 0.0;
  const double carried = hold_carried_tets(mesh, set.simp.controls.overhang, progress, holding, held);
  simp.volume_fraction = simp_volume_fraction(set.simp.volume_fraction, loaded, carried);
  r.simp =
      (runner ? runner : SimpRunner(simp::optimize))(holding ? held : mesh, job.material, supports, loads, weights,
                                                     simp, progress, on_iteration, fem::gravity_of(job.load_cases));
  if (const std::string w = not_crisp_warning(r.simp, simp); !w.empty()) progress.warn(w);
  const auto t1 = std::chrono::steady_clock::now();
  progress.say("surface", -1, "extracting the result shape");
  // the shape keeps the volume SIMP ended with (under a mass objective, what the limits left)
  const double simp_kept = simp.responses.objective == simp::Objective::Mass && !r.simp.history.empty()
                               ? r.simp.history.back().volume_fraction
                               : simp.volume_fraction;
  // ... of SIMP's design domain; the layer keep_loaded_faces held solid is design material too
  const double share = holding ? held_share(mesh, held) : 0.0;
  const double kept = simp_kept + (1 - simp_kept) * share;
  r.surface = result_surface(mesh, r.simp.density, set.threshold, kept, surface_settings(set, mesh), &r.threshold,
                             anchor_nodes(mesh, job), hygiene_params(mesh, set), &r.hygiene, &r.design, progress,
                             &r.surface_report, source);
  const auto t2 = std::chrono::steady_clock::now();
  r.seconds_simp = std::chrono::duration<double>(t1 - t0).count();
  r.seconds_surface = std::chrono::duration<double>(t2 - t1).count();
  return r;
}

std::vector<std::string> write_optimize_outputs(const TetMesh& mesh, const OptimizeResult& r, const std::string& dir) {
  const fs::path d(dir);
  std::vector<std::string> out;
  const io::VtuField density{"density", 1,
                             std::vector<double>(r.simp.density.data(), r.simp.density.data() + r.simp.density.size())};
  const io::VtuField design{"design", 1, std::vector<double>(r.design.data(), r.design.data() + r.design.size())};
  out.push_back(write_replacing((d / "density.vtu").string(), [&](const std::string& p) {
    io::write_vtu(p, mesh, {}, {density, design});
  }));
  out.push_back(
      write_replacing((d / "history.csv").string(), [&](const std::string& p) { write_history_csv(p, r.simp); }));
  out.push_back(
      write_replacing((d / "history.json").string(), [&](const std::string& p) { write_history_json(p, r); }));
  out.push_back(write_replacing((d / "result.stl").string(),
                                [&](const std::string& p) { io::write_stl(p, r.surface.V, r.surface.F); }));
  return out;
}

}  // namespace topopt::pipeline
