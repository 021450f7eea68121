// Tet quality, measured the way everyone measures it (DESIGN.md): radius ratio
// ρ = 3·r_in/R_circ (1 for the regular tet; Gmsh's "gamma") and dihedral angles.
#pragma once
#include <nlohmann/json.hpp>

#include "common/types.h"

namespace topopt::mesh {

/// A tet whose exact orientation is positive but whose radius ratio is below this counts as
/// flat (degenerate): its volume is at the rounding of its coordinates (radius ratio 1e-39 was
/// seen on a real part), and no solver can use it. The meshers never return one; the
/// conformity check rejects it.
constexpr double kFlatRadiusRatio = 1e-6;

/// Radius ratio 3·r_in/R_circ of one tet (0 for a degenerate one).
double radius_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    const Eigen::Vector3d& d);

/// Smallest and largest dihedral angle of one tet, in degrees.
std::pair<double, double> dihedral_range(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                                         const Eigen::Vector3d& d);

struct QualityReport {
  long tets = 0;
  double min_radius_ratio = 0, mean_radius_ratio = 0;
  double share_radius_ratio_below_01 = 0;     ///< share of tets with ρ < 0.1
  double min_dihedral = 0, max_dihedral = 0;  ///< degrees
  double share_dihedral_below_10 = 0;         ///< share of tets with a dihedral angle < 10°
  nlohmann::json to_json() const;
};

/// Quality of every tet of `mesh`.
QualityReport tet_quality(const TetMesh& mesh);

}  // namespace topopt::mesh
