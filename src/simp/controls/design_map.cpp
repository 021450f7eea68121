// The controls' map from variables to the design field (see design_map.h).
#include "simp/controls/design_map.h"

#include <numeric>

#include "simp/controls/tying.h"
#include "simp/density_filter.h"

namespace topopt::simp {

Eigen::MatrixX3d design_centroids(const TetMesh& mesh, const std::vector<int>& design) {
  Eigen::MatrixX3d c(design.size(), 3);
  for (size_t i = 0; i < design.size(); ++i) {
    c.row(i).setZero();
    for (int a = 0; a < 4; ++a) c.row(i) += mesh.V.row(mesh.T(design[i], a)) / 4;
  }
  return c;
}

DesignMap::DesignMap(const TetMesh& mesh, const std::vector<int>& design, const ControlsParams& params,
                     double tolerance) {
  if (params.ties()) {
    Tying t = tie_design(design_centroids(mesh, design), params, tolerance);
    variable_of_ = std::move(t.variable_of);
    num_variables_ = t.num_variables;
    summary_ = t.summary;
    // Not with an extrusion: its classes are columns one `tolerance` (a mean edge) wide, and the
    // mean over them draws the cross-section in squares that coarse — on the cantilever (10 mm
    // tall, four columns) the compliance doubled (489 -> 1000 N·mm) and the design no longer
    // reached the load pad (branch repeat23). There the filter is left to keep the ties as it can.
    averaged_ = !params.extrude;
    if (!averaged_) return;
    const VecXd all = tet_volumes(mesh);
    volume_.resize(static_cast<long>(design.size()));
    for (size_t i = 0; i < design.size(); ++i) volume_[i] = all[design[i]];
    class_volume_ = apply_transpose(volume_);
    return;
  }
  variable_of_.resize(design.size());
  std::iota(variable_of_.begin(), variable_of_.end(), 0);
  num_variables_ = static_cast<int>(design.size());
}

DesignMap::~DesignMap() = default;

VecXd DesignMap::apply(const VecXd& x) const {
  VecXd z(variable_of_.size());
  for (size_t i = 0; i < variable_of_.size(); ++i) z[i] = x[variable_of_[i]];
  return z;
}

VecXd DesignMap::apply_transpose(const VecXd& g) const {
  VecXd out = VecXd::Zero(num_variables_);
  for (size_t i = 0; i < variable_of_.size(); ++i) out[variable_of_[i]] += g[i];
  return out;
}

VecXd DesignMap::orbit_mean(const VecXd& y) const {
  if (!averaged_) return y;
  return apply(apply_transpose(volume_.cwiseProduct(y)).cwiseQuotient(class_volume_));
}

VecXd DesignMap::orbit_mean_transpose(const VecXd& g) const {
  if (!averaged_) return g;
  return volume_.cwiseProduct(apply(apply_transpose(g).cwiseQuotient(class_volume_)));
}

}  // namespace topopt::simp
