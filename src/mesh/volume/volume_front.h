// 3D advancing front: fills a region bounded by a closed triangle surface with tets, starting
// from any front — the boundary triangles plus the free faces of tets already present inside
// (step 14 of the two-B-Rep method starts from Ω̄'s tets). Every decision goes through the
// exact predicates; existing tets and boundary triangles are never changed.
//
// The engine in three parts (DESIGN.md): the front container with its spatial search and the
// test every new tet passes (TetFront, tet_front.h); the driver of named steps in
// volume_front.cpp — the Delaunay bulk first where it holds the boundary (delaunay_bulk.h),
// then rounds of widening passes (take the smallest front face, try front nodes near the ideal
// point and new points, accept the first valid tet; faces that fail are retried with a wider
// search, a looser quality bound and lower new points), small cavities closed from single
// points (front_cavities.h), and stuck regions re-meshed with a widening neighbourhood; and
// the tet improvement after filling (tet_improve.h: edge removal for rings of 3-7 tets, 2-3
// flips, smoothing and a compass search on the nodes of bad tets, then sliver removal by
// point insertion, which also removes slivers with two faces on the boundary).
#pragma once
#include <functional>

#include "common/progress.h"
#include "common/types.h"

namespace topopt::mesh {

struct VolumeFillParams {
  /// Target edge length at a point; empty: graded from the boundary's (and T0's) edge lengths
  /// by 0.3 per unit distance up to the longest of them (BackgroundSize, background_size.h).
  std::function<double(const double*)> size;
  double min_quality = 0.25;     ///< radius ratio a new tet must reach on the first pass
  int passes = 4;                ///< widening passes over faces that failed
  long max_tets = 20'000'000;    ///< refuse to go beyond (memory)
  int smoothing_iterations = 1;  ///< node smoothing sweeps per round (the worst tet at a node never drops)
  double flip_below = 0.55;      ///< new tets below this radius ratio get edge removal and 2-3 flips (0: none)
  int quality_rounds = 3;        ///< rounds of flips, smoothing and compass search
  bool delaunay_bulk = true;     ///< fill the bulk by Delaunay refinement first (delaunay_bulk.h), the front the rest
  double sliver_below = 0.4;     ///< new tets below this get a compass search on their nodes each round, then sliver
                                 ///< removal by point insertion, worst first, up to 3 times (0: none)
  double sliver_floor = 0.1;     ///< then tets below this get wider cavities re-filled (tet_improve.h; 0: none)
  /// CPU seconds of the calling thread the whole fill (retry and improvement included) may
  /// take before it stops with Error(Timeout); 0: volume_fill_seconds of the tets the front may
  /// make (its budget, proportional to what the size asks for); < 0: no limit.
  double cpu_seconds = 0;
};

/// The automatic time budget of a fill allowed to make up to `tet_budget` tets (fill_volume's:
/// ten times what the size asks for, plus room for a fine boundary): 10 s plus one CPU
/// second per 4 000 tets. The fill makes about 8 000 tets per CPU second with its improvement
/// (result surfaces of the examples, 2026), so a fill that ends normally uses a few per cent of it.
double volume_fill_seconds(long tet_budget);

struct VolumeFillResult {
  MatX3d V;  ///< #V' by 3: the input nodes (unchanged, same indices) then the new ones the tets use
  MatX4i T;  ///< #T' by 4: the new tets only, positively oriented
};

/// Fills the region bounded by F (#F by 3, oriented with normals pointing OUT of the region)
/// on nodes V (#V by 3), around the existing tets T0 (#T0 by 4, kept, may be empty).
/// Never returns a flat or inverted tet (exact orientation, or radius ratio below
/// kFlatRadiusRatio): such a tet is taken out and its cavity re-filled. Throws
/// Error(MeshingFailed) naming where the front could not be closed, where it went on making
/// tets past ten times what its size asks for (expected_tets) without closing, or where a flat
/// tet could not be removed; Error(Timeout) naming the stage past params.cpu_seconds (the
/// shared rule: every mesh ends or fails by name within a budget proportional to its expected
/// tets); Error(Cancelled) when progress says so (both checked in every loop).
VolumeFillResult fill_volume(const MatX3d& V, const MatX3i& F, const MatX4i& T0, const VolumeFillParams& params = {},
                             const Progress& progress = {});

}  // namespace topopt::mesh
