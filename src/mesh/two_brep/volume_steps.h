// Steps 12-14 of the two-B-Rep method, on any conformal surface mesh of Ω and Ω̄: each
// non-design solid filled from its closed surface (step 12), its tets taken over by Ω
// (step 13), the rest of Ω filled from its boundary around them (step 14). The native mesher
// runs them on its own surfaces; the Gmsh fallback can run them on Gmsh's (a comparison aid).
#pragma once
#include <vector>

#include "common/progress.h"
#include "common/types.h"
#include "mesh/volume/volume_front.h"

namespace topopt::mesh {

/// The tets of Ω made by steps 12-14 on a node pool.
struct TwoBRepVolumes {
  MatX3d V;      ///< #V' by 3: the input nodes first (same indices), then each fill's new nodes in fill order
  MatX4i T;      ///< #T by 4, positively oriented: the non-design solids' tets (solid by solid), then Ω0's
  VecXi domain;  ///< #T: i for the i-th non-design solid (1-based, input order), 0 for the design domain
  double seconds_design = 0;  ///< of which steps 13-14 (the rest is step 12)
};

/// Steps 12-14 on the nodes V (#V by 3). nondesign[i]: the closed surface of the i-th
/// non-design solid (#F_i by 3, normals out of it); part: Ω's boundary (normals out).
/// The solids are filled in parallel on `threads` threads (0: all cores), largest first, on
/// the same snapshot of V; their new nodes and tets are merged in input order. `params` is
/// each fill's (its size, when set, is the graded volume size). Throws
/// Error(MeshingFailed) naming "non-design solid i" or "design domain" where a front could
/// not close; Error(Cancelled) through `progress`.
TwoBRepVolumes fill_two_brep_volumes(const MatX3d& V, const std::vector<MatX3i>& nondesign, const MatX3i& part,
                                     const VolumeFillParams& params, int threads, const Progress& progress = {});

}  // namespace topopt::mesh
