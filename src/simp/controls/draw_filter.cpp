// The draw-direction control (see draw_filter.h).
#include "simp/controls/draw_filter.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/error.h"
#include "simp/controls/design_map.h"

namespace topopt::simp {

namespace {

Eigen::Vector3d unit_direction(const Eigen::Vector3d& d) {
  if (!(d.norm() > 0) || !d.allFinite())
    throw Error(ErrorCode::InvalidParameter,
                "controls.draw_direction.direction must be a non-zero vector (the direction the die is drawn in)");
  return d.normalized();
}

const DrawDirection& checked(const DrawDirection& p) {
  if (!(p.smoothness > 0 && p.smoothness <= 0.01))
    throw Error(
        ErrorCode::InvalidParameter,
        "controls.draw_direction.smoothness must lie in (0, 0.01] (default 1e-4), not " + std::to_string(p.smoothness));
  return p;
}

}  // namespace

double smooth_max(double a, double b, double eps, double* da, double* db) {
  const double r = std::sqrt((a - b) * (a - b) + eps);
  *da = 0.5 * (1 + (a - b) / r);
  *db = 0.5 * (1 - (a - b) / r);
  return 0.5 * (a + b + r - std::sqrt(eps));
}

namespace {

TetCastParams tet_cast_params(const DrawDirection& p) {
  TetCastParams t;
  t.direction = p.direction;
  t.split = p.split;
  t.parting_point = p.parting_point;
  t.smoothness = p.smoothness;
  return t;
}

}  // namespace

DrawFilter::DrawFilter(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volumes,
                       const DrawDirection& params, double cell)
    : params_(checked(params)),
      grid_(design_centroids(mesh, design), volumes, unit_direction(params.direction), cell, params.parting_point,
            true),
      tets_(mesh, design, tet_cast_params(params)) {
  const Eigen::Vector3d d = params.direction.normalized();
  if (params.split) {
    const double s = params.parting_point.dot(d);
    const long k = std::lround((s - grid_.start()) / cell);  // the grid's faces pass through the plane
    parting_layer_ = static_cast<int>(std::clamp<long>(k, 0, grid_.num_layers()));
  }
  std::ostringstream log;
  log << "draw direction (" << d.x() << ", " << d.y() << ", " << d.z() << "), "
      << (params.split ? "split at layer " + std::to_string(parting_layer_) : std::string("one-sided")) << ", grid "
      << grid_.num_columns() << " columns x " << grid_.num_layers() << " layers of " << cell
      << " mm, then on the tets (" << tets_.num_pairs() << " face pairs"
      << (tets_.num_dropped() ? ", " + std::to_string(tets_.num_dropped()) + " dropped in cycles" : std::string())
      << ")";
  summary_ = log.str();
}

VecXd DrawFilter::cumulate(const VecXd& g, VecXd* adjoint) const {
  const int K = grid_.num_layers(), p = parting_layer_;
  const double eps = params_.smoothness;
  VecXd out = g, da = VecXd::Zero(g.size()), db = VecXd::Zero(g.size());
  for (long c = 0; c < grid_.num_columns(); ++c) {
    const long base = c * K;
    for (int k = K - 2; k >= p; --k)  // above the parting plane: from the top down
      out[base + k] = smooth_max(g[base + k], out[base + k + 1], eps, &da[base + k], &db[base + k]);
    for (int k = 1; k < p; ++k)  // below it: from the bottom up
      out[base + k] = smooth_max(g[base + k], out[base + k - 1], eps, &da[base + k], &db[base + k]);
  }
  if (!adjoint) return out;
  VecXd& a = *adjoint;  // d/d out on entry; each step hands its share on to the layer it came from
  VecXd dg = VecXd::Zero(g.size());
  for (long c = 0; c < grid_.num_columns(); ++c) {
    const long base = c * K;
    for (int k = p; k < K; ++k) {
      if (k == K - 1) {
        dg[base + k] += a[base + k];
        continue;
      }
      dg[base + k] += a[base + k] * da[base + k];
      a[base + k + 1] += a[base + k] * db[base + k];
    }
    for (int k = p - 1; k >= 0; --k) {
      if (k == 0) {
        dg[base + k] += a[base + k];
        continue;
      }
      dg[base + k] += a[base + k] * da[base + k];
      a[base + k - 1] += a[base + k] * db[base + k];
    }
  }
  a = dg;
  return out;
}

VecXd DrawFilter::apply(const VecXd& r) const {
  return tets_.apply(grid_.to_elements(cumulate(grid_.to_grid(r), nullptr)));
}

VecXd DrawFilter::apply_transpose(const VecXd& r, const VecXd& g) const {
  const VecXd on_grid = grid_.to_grid(r);
  VecXd adjoint = grid_.to_elements_transpose(tets_.apply_transpose(grid_.to_elements(cumulate(on_grid, nullptr)), g));
  cumulate(on_grid, &adjoint);
  return grid_.to_grid_transpose(adjoint);
}

}  // namespace topopt::simp
