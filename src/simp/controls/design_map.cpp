// The controls' map from variables to the design field (see design_map.h).
#include "simp/controls/design_map.h"

#include <numeric>
#include <sstream>

#include "common/error.h"
#include "simp/controls/section_grid.h"
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
  if (!params.ties()) {
    variable_of_.resize(design.size());
    std::iota(variable_of_.begin(), variable_of_.end(), 0);
    num_variables_ = static_cast<int>(design.size());
    return;
  }
  const VecXd all = tet_volumes(mesh);
  volume_.resize(static_cast<long>(design.size()));
  for (size_t i = 0; i < design.size(); ++i) volume_[i] = all[design[i]];
  averaged_ = true;
  if (params.extrude) {
    build_section(mesh, design, params, tolerance);
  } else {
    Tying t = tie_design(design_centroids(mesh, design), params, tolerance);
    variable_of_ = std::move(t.variable_of);
    num_variables_ = t.num_variables;
    summary_ = t.summary;
  }
  class_volume_ = apply_transpose(volume_);
}

void DesignMap::build_section(const TetMesh& mesh, const std::vector<int>& design, const ControlsParams& params,
                              double tolerance) {
  const double n = params.extrusion.norm();
  if (!(n > 1e-12) || !std::isfinite(n))
    throw Error(ErrorCode::InvalidParameter, "the extrusion direction is zero or not finite: give a non-zero vector");
  const Eigen::Vector3d d = params.extrusion / n;
  const Eigen::MatrixX3d c = design_centroids(mesh, design);
  const double h = section_spacing(tolerance);
  const SectionGrid grid(c, d, h);
  const Eigen::SparseMatrix<double> w = grid.interpolation(c);
  // the nodes some centroid reaches are the section's; the other controls tie them (in the plane
  // through the centroids' mean along d, one node spacing the matching distance)
  const VecXd reach = w.transpose() * VecXd::Ones(w.rows());
  std::vector<int> active(grid.num_nodes(), -1), nodes;
  for (int k = 0; k < grid.num_nodes(); ++k)
    if (reach[k] > 0) active[k] = static_cast<int>(nodes.size()), nodes.push_back(k);
  ControlsParams others = params;
  others.extrude = false;
  std::vector<int> class_of(nodes.size());
  std::iota(class_of.begin(), class_of.end(), 0);
  num_variables_ = static_cast<int>(nodes.size());
  std::ostringstream log;
  if (others.ties()) {
    const double mid = c.rows() ? (c * d).mean() : 0;
    Eigen::MatrixX3d at(nodes.size(), 3);
    for (size_t k = 0; k < nodes.size(); ++k) at.row(k) = grid.node_point(nodes[k], mid);
    Tying t = tie_design(at, others, h);
    class_of = std::move(t.variable_of);
    num_variables_ = t.num_variables;
    log << "section nodes: " << t.summary << "; ";
  }
  std::vector<Eigen::Triplet<double>> s;
  s.reserve(w.nonZeros());
  for (int k = 0; k < w.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(w, k); it; ++it)
      s.emplace_back(it.row(), class_of[active[it.col()]], it.value());
  section_.resize(static_cast<long>(design.size()), num_variables_);
  section_.setFromTriplets(s.begin(), s.end());
  extruded_ = true;
  log << "extrusion: a section grid of " << nodes.size() << " nodes " << h << " mm apart; " << num_variables_
      << " variables for " << design.size() << " design elements";
  summary_ = log.str();
}

DesignMap::~DesignMap() = default;

VecXd DesignMap::apply(const VecXd& x) const {
  if (extruded_) return section_ * x;
  VecXd z(variable_of_.size());
  for (size_t i = 0; i < variable_of_.size(); ++i) z[i] = x[variable_of_[i]];
  return z;
}

VecXd DesignMap::apply_transpose(const VecXd& g) const {
  if (extruded_) return section_.transpose() * g;
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
