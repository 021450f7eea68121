// The bulk of a volume by Delaunay refinement, for the 3D advancing front to finish (the
// hybrid that Netgen also uses): the Delaunay tetrahedralisation of the boundary's nodes, the
// tets inside the boundary kept where it contains the boundary triangles, and refined by
// inserting circumcentres until the tets meet the size;
// next to the boundary a point's cavity is cut back to what the point sees, so that the
// refinement reaches the boundary instead of leaving it the coarse tets of its own nodes. Where a boundary triangle is
// missing from the tetrahedralisation, every tet that could meet it is left out: the advancing front (volume_front.h)
// fills those holes from their faces, so the boundary is never recovered by flips or Steiner points and the hybrid is
// exactly as reliable as the front alone. Every decision goes through the exact predicates.
#pragma once
#include <array>
#include <functional>
#include <vector>

#include "common/progress.h"
#include "common/types.h"

namespace topopt::mesh {

struct DelaunayBulkParams {
  /// Target edge length at a point, or empty; either way the size grows from the boundary's
  /// edge lengths no faster than 0.4 per unit of distance.
  std::function<double(const double*)> size;
  /// A tet is refined while its circumradius exceeds this × the size (the regular tet of edge
  /// h has 0.61 h; 0.95 gives about as many tets as Gmsh and the front at the same size).
  double refine_above = 0.95;
  long max_tets = 20'000'000;  ///< stop refining beyond (the caller checks memory)
  /// Refinement points next to walls get their cavity cut back to what they see (Tets::insert)
  /// instead of being refused; false refuses them (the bulk before issue 20's fifth pass: the
  /// tets along the boundary then stay as coarse as the boundary nodes' tetrahedralisation).
  bool repair_cavities = true;
  /// Give up before refining (no tets, P as it was) when more than this share of the boundary
  /// triangles is missing from the tetrahedralisation.
  double max_missing_share = 1.0;
};

struct DelaunayBulkResult {
  std::vector<std::array<int, 4>> tets;  ///< positively oriented, inside the boundary
  std::vector<std::array<int, 3>>
      free_faces;              ///< faces of one tet only, turned out of it: boundary triangles and the holes' faces
  long missing_triangles = 0;  ///< boundary triangles the tetrahedralisation lacked
  long points = 0;             ///< points inserted inside
  long repaired = 0;           ///< of those, points whose cavity was cut back to what they see (not all Delaunay)
  long refused_unseen = 0;     ///< refinement points refused: they did not see their cavity even cut back
  long refused_poor = 0;       ///< refinement points refused: their cut-back cavity's star had a tet below 0.02
                               ///< (radius ratio) worse than every tet it would remove
  bool gave_up = false;        ///< over max_missing_share missing: no tets, P as it was
};

/// Tets for the region bounded by B (triangles on nodes P, oriented with normals OUT of the
/// region; closed). New nodes are appended to P (and 4 far nodes that no returned tet uses).
/// The tets leave holes around boundary triangles the tetrahedralisation lacked: the
/// region minus the tets is bounded by those triangles and the tets' free faces.
DelaunayBulkResult delaunay_bulk(std::vector<Eigen::Vector3d>& P, const std::vector<std::array<int, 3>>& B,
                                 const DelaunayBulkParams& params = {}, const Progress& progress = {});

}  // namespace topopt::mesh
