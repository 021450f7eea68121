// The result shape back in CAD: the closed, tagged triangle surface (iso_surface.h) made into
// one OCCT solid and written as STEP. Every triangle belongs to one B-Rep face and every mesh
// edge between two faces to one B-Rep edge shared by both, so the shell is closed by
// construction (no sewing by distance, which is slow and can glue the wrong edges where the
// design is thin). Coplanar neighbouring triangles are one planar face (Ω's planar faces come
// back whole, bounded by the polygon of the kept region) and a straight run of boundary between
// the same two faces one edge, worked out on the triangles before OCCT builds anything
// (step_planar_faces.h), so the cost grows with the surface, not with its square. The free-form
// region stays a shell of planar facets.
#pragma once
#include <string>
#include <vector>

#include "common/progress.h"
#include "result/iso_surface.h"
#include "result/step_coarsen.h"

class TopoDS_Shape;

namespace topopt::result {
class SourceFaces;  // step_export_analytic.h
}

namespace topopt::result {

struct StepExportParams {
  /// Wall-time budget of the child process that builds and writes the solid (<= 0: none): a
  /// backstop for a fault inside OCCT, large enough for a machine whose wall clock runs 20 to
  /// 30 times the CPU time (the rocker needs a few CPU seconds).
  double seconds = 900;
  bool unify = true;  ///< merge coplanar faces and collinear edges (step_planar_faces.h)
  /// Angle (radians) within which two facets count as coplanar when merging. Ω's planar faces
  /// are exactly planar; a small value keeps the free-form region's facets apart.
  double angular_tolerance = 1e-6;
  /// The free-form region's coarsening before it becomes faces (step_coarsen.h;
  /// coarsen.tolerance <= 0: every triangle becomes a face).
  CoarsenParams coarsen;
  /// Write the edges' 2D curves on their planes (STEP PCURVEs). Off: the planes' edges are
  /// written as 3D lines only (a reader computes the 2D curves of a planar face), which
  /// makes the file about half as large.
  bool pcurves = false;
  /// The most triangles that become faces (after coarsening) in the STEP (<= 0: any number):
  /// past it the free-form region is coarsened harder (coarsen_to_budget: the tolerance doubled
  /// up to 1.6 times the median edge, the enclosed volume within 0.5 % of the surface's) until
  /// it fits; when it cannot, result_solid and write_result_step write nothing and throw
  /// Error(TooLarge) naming the job key that raises it (max_triangles_key). A bound on the
  /// file's size and on what a CAD program must read; the export's cost grows linearly.
  long max_triangles = 100000;
};

/// The key of the job's "output" section that sets StepExportParams::max_triangles, as the
/// refusal names it.
inline constexpr const char* max_triangles_key = "step_max_triangles";

/// What the solid written holds, as OCCT's checks found it after building.
struct StepExportReport {
  bool valid = false;      ///< BRepCheck_Analyzer found no fault
  int solids = 0;          ///< solids in the shape (1 when all went well)
  int faces = 0;           ///< B-Rep faces after merging
  int planar_faces = 0;    ///< faces on a Geom_Plane
  int analytic_faces = 0;  ///< faces on a cylinder, cone, sphere or torus (the input's curved faces)
  /// Pieces of the input's curved faces written as facets: their face on the input's surface
  /// could not be made or failed OCCT's check (step_export_analytic.h).
  int analytic_refused = 0;
  long triangles = 0;       ///< triangles that became faces (after coarsening), before merging
  int unmerged_bodies = 0;  ///< bodies written as facets: OCCT's check refused their merged faces
  /// Of those, the bodies written without the input's curved faces (merged planar faces, else a
  /// planar face per triangle): OCCT's check refused the body with its analytic faces too.
  int facet_bodies = 0;
  double volume = 0;        ///< mm³, by OCCT's GProp
  double seconds = 0;       ///< building, checking and writing (wall time)
  double cpu_seconds = 0;   ///< the same in CPU time of the child that did it
  long bytes = 0;           ///< size of the STEP file
};

/// The solid bounded by `s` (closed, outward triangles; s.V #P by 3, s.F #Q by 3): the
/// free-form region coarsened (params.coarsen; `coarsened`, optional: what it did), then with
/// params.unify coplanar neighbouring triangles as one planar face and straight boundary runs
/// as one edge (step_planar_faces.h; a body OCCT's check refuses is built again unmerged, then
/// without the input's curved faces, then as a planar face per triangle, and the first form that
/// passes is kept: coarsened->unmerged_bodies, and coarsened->facet_bodies for the last two),
/// else a planar face per triangle, every face sharing its edges with its neighbours. One solid per body of the surface (result_bodies; a compound of them when
/// there are several, e.g. a detached non-design solid), closed voids as inner shells of the
/// body holding them. Points no triangle uses are ignored. Throws Error(InvalidShape) naming the
/// first triangle without area or an open surface (what to change: the smoothing settings).
/// With `source` (the input's curved analytic faces), the triangles lying on one of them become
/// faces on that original surface (step_export_analytic.h); `analytic_refused` (optional) counts
/// the pieces that stayed facets. `checked_valid` (optional): true when every body passed OCCT's
/// check (BRepCheck_Analyzer) here, as built (with params.unify each body is checked in the form
/// kept; without it nothing is checked and it is false), so that describe_solid need not check the
/// shape again. Runs OCCT in this process: callers with foreign or untrusted surfaces use
/// write_result_step.
TopoDS_Shape result_solid(const TriSurface& s, const StepExportParams& params = {}, CoarsenReport* coarsened = nullptr,
                          const SourceFaces* source = nullptr, int* analytic_refused = nullptr,
                          bool* checked_valid = nullptr);

/// The bodies of the result surface `s`: its pieces (triangles sharing points) that enclose a
/// positive volume (a piece of negative volume is a closed void inside a body).
int result_bodies(const TriSurface& s);

/// The bodies of the result surface `s` (result_bodies), one line each in the order of their
/// first triangle: volume (mm³, closed voids not subtracted), the centre of its bounding box
/// and what it is made of (the design region, which non-design solids), e.g. "body 2: 27 mm³
/// around (21.5, 17.5, 2.5), non-design solid 2 alone". Names the parts of a result the
/// design does not join (a non-design solid held by its own support), in the user's terms.
std::vector<std::string> body_descriptions(const TriSurface& s);

/// Counts the shape's solids, faces and planar faces, checks it (BRepCheck_Analyzer; with
/// `known_valid`, the caller's word that every solid of it passed that check already: not run
/// again) and measures its volume; seconds and bytes are left 0.
StepExportReport describe_solid(const TopoDS_Shape& shape, bool known_valid = false);

/// What OCCT's BRepCheck_Analyzer refuses in `shape`: up to `limit` faults, each as the kind
/// and index of the sub-shape (OCCT's TopExp order), where it lies (centre of its box, for
/// vertices, edges and faces) and the check that failed, e.g. "face 12 near (1, 2, 3):
/// Self Intersecting Wire"; "" when the shape is valid.
std::string solid_faults(const TopoDS_Shape& shape, int limit = 5);

/// Builds result_solid(s) and writes it to `path` as STEP (AP214, mm), in a child process
/// with the time budget params.seconds, so that a fault or a hang inside OCCT costs the
/// export, never the caller. Returns the report of the solid written. Throws Error(TooLarge),
/// writing nothing, when `s` cannot be coarsened within params.max_triangles; Error(Timeout)
/// past the budget, Error(Crashed) when OCCT ends the child, Error(InvalidShape) when the
/// shape is not valid or not one solid per body (result_bodies), Error(Io) when the file cannot be written.
/// A result of several bodies is written as one compound of solids (a STEP reader shows several
/// solids), with a warning through progress naming each body (body_descriptions): the design
/// does not join them, so as made they are separate parts. With `source`, the input's curved
/// analytic faces come back as such (result_solid).
StepExportReport write_result_step(const std::string& path, const TriSurface& s, const StepExportParams& params = {},
                                   const Progress& progress = {}, const SourceFaces* source = nullptr);

}  // namespace topopt::result
