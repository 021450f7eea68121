// What SIMP minimises and under which limits (issue 22, "objectives and constraints"): the
// options only, so that optimizer.h can hold them without the responses' machinery.
#pragma once
#include <string>
#include <vector>

#include "common/types.h"
#include "fem/boundary_conditions.h"

namespace topopt::simp {

/// What SIMP minimises.
enum class Objective {
  Compliance,  ///< weighted compliance Σ w_k F_kᵀU_k under the volume fraction (the default)
  Mass,        ///< the design volume (its mass: the material's density is constant) under the limits
  Frequency    ///< maximise the first eigenfrequency under the volume fraction (responses/frequency.h)
};

/// A limit on the displacement of a face along a direction: the area-weighted mean of d·u over
/// the face's nodes, |u_d| <= limit in every load case. Held as the squared ratio
/// (u_d / limit)² <= 1, smooth whatever the sign of the deflection.
struct DisplacementLimit {
  std::string name;  ///< for messages and the history ("Face7 along (0, 0, -1)")
  /// 3#V: the gauge g with u_d = gᵀU, i.e. the nodal loads of a unit total force along the
  /// direction spread over the face by area (fem::make_loads), so gᵀU is the area-weighted mean.
  VecXd gauge;
  double limit = 0;  ///< mm, > 0
};

/// The objective and the constraints beyond the volume fraction.
struct ResponseParams {
  Objective objective = Objective::Compliance;
  /// Mass objective: the weighted compliance may not exceed this (N·mm); <= 0: no such limit.
  double compliance_limit = 0;
  std::vector<DisplacementLimit> displacements;  ///< with either objective
  /// von Mises limit (MPa) in every load case, with either objective; <= 0: none. The stress of
  /// an element is relaxed, ρ̄^q σ0 (σ0 the solid material's stress, q stress_relaxation), so
  /// that void elements carry none, and aggregated over the elements by a p-norm whose scale
  /// follows the largest element stress (adaptive normalisation, Le et al. 2010).
  double stress_limit = 0;
  double stress_pnorm = 8;         ///< P of the p-norm, in [2, 64]: larger follows the maximum closer
  double stress_relaxation = 0.5;  ///< q of the qp-relaxation, in (0, 1]; below the penalty p
  /// Under a stress limit: the load cases SIMP's nodal loads were made from (fem::make_loads).
  /// The crisp design's stress (IterationRecord::stress_crisp) is analysed with them made anew
  /// on its solid tets only (crisp_max_von_mises), so needed then.
  std::vector<fem::LoadCase> load_cases;
  /// Frequency: the subspace iteration stops when the first eigenvalues change by less than this.
  double eigen_tolerance = 1e-10;
  /// True when the problem needs MMA (anything beyond compliance under a volume fraction).
  bool needs_mma() const { return objective != Objective::Compliance || !displacements.empty() || stress_limit > 0; }
};

}  // namespace topopt::simp
