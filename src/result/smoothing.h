// Staircase removal on the result surface: Taubin's λ|μ smoothing (a low-pass filter that
// does not shrink smooth shapes), on free vertices only, each pair followed by a local volume
// correction so that members a few edges thick do not shrink either.
#pragma once
#include "result/iso_surface.h"
#include "result/overhang_lift.h"

namespace topopt::result {

struct SmoothParams {
  int iterations = 20;  ///< λ|μ pairs
  double lambda = 0.5;  ///< shrinking step
  double mu = -0.53;    ///< inflating step (|μ| > λ)
  /// After each pair the points move back along their normals by the local mean of the offsets
  /// the pair gave them, the mean over this many rings of neighbours (0: no correction). The
  /// pair's pass band (k < 1/λ + 1/μ = 0.11 of the umbrella operator) holds smooth shapes, but
  /// the cross-section of a member a few edges thick is a short ring of points, a high
  /// frequency for the operator, which each pair shrinks although the member is smooth. As an
  /// offset along the normals that shrinking is locally constant, which the mean keeps, while
  /// the ripple the pair removes averages out. Measured on the coarse cantilever at threshold
  /// 0.4 (BENCHMARKS.md, branch bisect3): 60 pairs took 1.4 % of the volume without it, 0.8 %
  /// with 1 ring, 1.1 % with 4.
  int volume_rings = 1;
  /// Vertices on Ω's boundary faces: slide within their face's plane when it is planar
  /// (true), or stay fixed (false). Non-design vertices never move.
  bool slide_on_planar_faces = true;
  /// The finishing of the result surface around the smoothing (design_surface.h): edge flips
  /// and collapses of badly shaped triangles before and after it (remesh, job key
  /// "surface_remesh"), and the smoothing undone where triangles cross (repair,
  /// "surface_repair"). Off only to compare with the surface as it was before issue 19.
  bool remesh = true;
  bool repair = true;
  /// With remesh: crossings kept this share of an edge away from its nodes when the surface is
  /// cut (extract_iso_surface's margin; slivers from crossings next to nodes never appear).
  double crossing_margin = 0.2;
  /// The resolution the surface is cut at (job key "result.resolution"): 1 on the FE mesh, 2 on
  /// the FE mesh with the design tets near the level split once (iso_surface_refine.h).
  int resolution = 1;
  /// The job's overhang control (pipeline::surface_settings fills it): with a build direction the
  /// finished surface's too-flat downward facets are lifted back to the angle (overhang_lift.h).
  BuildDirection build;
  /// The job's extrusion (pipeline::surface_settings fills it): its direction (unit; zero: none)
  /// and the spacing of the section grid (mm) the cut's node densities are fitted on, so that the
  /// result is one extruded shape (simp/controls/section_grid.h).
  Eigen::Vector3d extrusion = Eigen::Vector3d::Zero();
  double extrusion_spacing = 0;
};

/// Smooths s.V in place. Vertices with lock 2 do not move; with lock 1 they move only
/// within the plane of their (planar) Ω face and only along the boundary curve of the cut.
void smooth_surface(TriSurface& s, const SmoothParams& params = {});

}  // namespace topopt::result
