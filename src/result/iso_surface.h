// The result shape: the region where the node densities reach a threshold, cut out of the
// tagged tet mesh by marching tetrahedra, plus the non-design solids whole. Its boundary is
// a closed, manifold, outward-oriented triangle mesh made of iso-triangles inside design
// tets and the kept parts of Ω's boundary faces.
#pragma once
#include "common/closed_surface.h"
#include "common/types.h"

namespace topopt::result {

/// The result shape's check (closed, manifold, outward, its volume) is the code base's one
/// closed-surface check, common/closed_surface.h, under the names result/ has always offered.
using topopt::check_surface;
using topopt::SurfaceCheck;

/// #V node densities: the volume-weighted mean of the densities of the tets around a node;
/// nodes of non-design tets get 1 so the non-design solids are kept whole. density: #T.
VecXd node_densities(const TetMesh& mesh, const VecXd& density);

/// Volume of {x in design tets : interpolated node density >= threshold} (mm³), exact for
/// the piecewise-linear field.
double kept_design_volume(const TetMesh& mesh, const VecXd& node_density, double threshold);

/// Volume of tet t where the interpolated node density (#V) is at or above `threshold` (mm³,
/// exact for the piecewise-linear field; the whole tet for a non-design tet): what of it the
/// result shape holds.
double kept_tet_volume(const TetMesh& mesh, const VecXd& node_density, double threshold, long t);

/// The threshold in (0, 1) at which the kept design volume equals `volume_fraction` of the
/// design domain's volume, by bisection. Where that lands on a plateau of equal node densities
/// (within 1e-9), the threshold steps just off it (by up to 1e-6) to the side whose volume is
/// nearer: the whole plateau is then in or out, not each node by the filter's rounding.
double threshold_for_volume(const TetMesh& mesh, const VecXd& node_density, double volume_fraction);

/// A triangle surface with a tag per triangle and what may move when smoothing.
struct TriSurface {
  MatX3d V;   ///< #P by 3 points
  MatX3i F;   ///< #Q by 3 triangles, oriented outwards
  VecXi tag;  ///< #Q: 0 iso-surface, f > 0 Ω's face f, -k face of non-design solid k
  /// #P: 0 free (iso-surface inside Ω), 1 on Ω's boundary, 2 on a non-design solid (fixed).
  VecXi lock;
  /// #P: for the points where the iso-surface meets Ω's face f (the cut line), f; else 0.
  VecXi point_face;
  /// Indexed by Ω face number: (n, d) of the face's plane n·x = d when the face is planar,
  /// (0, 0, 0, 0) otherwise.
  std::vector<Eigen::Vector4d> face_plane;
};

/// Marching tetrahedra at `threshold` on the node densities (#V). Returns the closed
/// boundary of the kept region (common/closed_surface.h checks it): iso-triangles in design
/// tets, Ω's boundary triangles (or their kept parts) with their face tags, non-design tets'
/// boundary triangles on Ω, and the void side of faces between design and non-design tets.
/// With margin in [0, 0.5), the level's values at nodes it passes closer than margin × the
/// edge are raised in magnitude (signs kept, so the same topology; one adjusted value per
/// node, used by every triangle) so that every crossing lies at least margin × its edge from
/// both nodes: no needles or caps from crossings next to nodes, at the price of moving the
/// surface by up to margin × the edge length there. A margin below 1e-6 (0: the exact level
/// set) acts as 1e-6: closer crossings cannot be placed apart from their node in double
/// precision (nodes within rounding of the threshold, e.g. a region of equal densities at
/// it, would give folded or degenerate triangles).
TriSurface extract_iso_surface(const TetMesh& mesh, const VecXd& node_density, double threshold, double margin = 0);

}  // namespace topopt::result
