// Minimum and maximum member size (see member_size.h).
#include "simp/controls/member_size.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/error.h"
#include "common/tet_boundary.h"
#include "common/triangle_closest.h"
#include "mesh/core/spatial_grid.h"
#include "simp/density_filter.h"

namespace topopt::simp {
namespace {

/// The filter's kernel at distance s (in filter radii) from a plate's mid-plane, integrated
/// over the plane: 2π ∫_s^∞ w(r) r dr up to the constant factor, for the radial weight w of the
/// filter with R = 1 (w = e^(−r²/2σ²), σ = 1/3, cut at 1; w = 1 − r; the Helmholtz filter's
/// Green function e^(−r/ℓ)/r).
double plate_kernel(FilterKind kind, double ell, double s) {
  s = std::abs(s);
  if (kind == FilterKind::Helmholtz) return ell * std::exp(-s / ell);
  if (s >= 1) return 0;
  if (kind == FilterKind::Cone) return 1.0 / 6 - s * s / 2 + s * s * s / 3;
  const double var = 1.0 / 9;
  return var * (std::exp(-s * s / (2 * var)) - std::exp(-1 / (2 * var)));
}

/// The cumulative integral of the plate kernel on [−L, L], normalised to 1 at L.
class PlateProfile {
 public:
  PlateProfile(FilterKind kind, bool like_gaussian) {
    const double ell = helmholtz_length(1.0, like_gaussian);
    half_ = kind == FilterKind::Helmholtz ? 14 * ell : 1.0;
    const int n = 20000;
    step_ = 2 * half_ / n;
    cumulative_.assign(n + 1, 0.0);
    double previous = plate_kernel(kind, ell, -half_);
    for (int k = 1; k <= n; ++k) {
      const double now = plate_kernel(kind, ell, -half_ + k * step_);
      cumulative_[k] = cumulative_[k - 1] + 0.5 * (previous + now) * step_;
      previous = now;
    }
    for (double& c : cumulative_) c /= cumulative_.back();
  }
  /// The filtered density at y of a crisp plate of half-thickness a centred at 0.
  double filtered(double a, double y) const { return at(y + a) - at(y - a); }
  double half() const { return half_; }

 private:
  double half_, step_;
  std::vector<double> cumulative_;
  double at(double s) const {  // ∫_{-L}^{s} k, linearly interpolated
    const double u = std::clamp((s + half_) / step_, 0.0, static_cast<double>(cumulative_.size() - 1));
    const size_t k = std::min(static_cast<size_t>(u), cumulative_.size() - 2);
    return cumulative_[k] + (u - k) * (cumulative_[k + 1] - cumulative_[k]);
  }
};

/// The x in [lo, hi] where the increasing (rising = true) or decreasing function f crosses
/// `level`, by bisection.
template <class F>
double crossing(F&& f, double level, double lo, double hi, bool rising) {
  for (int k = 0; k < 80; ++k) {
    const double mid = 0.5 * (lo + hi);
    ((f(mid) < level) == rising ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

RobustThresholds robust_thresholds(double eta, double eta_shift) { return {eta + eta_shift, eta, eta - eta_shift}; }

double robust_size_ratio(FilterKind kind, const RobustThresholds& t, bool like_gaussian) {
  const PlateProfile plate(kind, like_gaussian);
  // the thinnest plate that survives erosion: its filtered peak is η_e
  const double a = crossing([&](double h) { return plate.filtered(h, 0); }, t.eroded, 0, plate.half(), true);
  // its intermediate design: where its filtered density is at least η
  const double y = crossing([&](double s) { return plate.filtered(a, s); }, t.intermediate, 0, 2 * plate.half(), false);
  return 2 * y;
}

double robust_filter_radius(double min_size, FilterKind kind, const RobustThresholds& t, bool like_gaussian) {
  return min_size / robust_size_ratio(kind, t, like_gaussian);
}

std::vector<char> held_nodes(long num_nodes, const std::vector<int>& supported_dofs, const Eigen::MatrixXd& loads) {
  std::vector<char> held(static_cast<size_t>(num_nodes), 0);
  for (int dof : supported_dofs) held[dof / 3] = 1;
  for (long i = 0; i < loads.rows() && i / 3 < num_nodes; ++i)
    if (loads.row(i).cwiseAbs().maxCoeff() > 0) held[i / 3] = 1;
  return held;
}

std::vector<char> thin_part_nodes(const TetMesh& mesh, double thickness) {
  std::vector<char> thin(static_cast<size_t>(mesh.V.rows()), 0);
  if (!(thickness > 0) || mesh.T.rows() == 0) return thin;
  const MatX3i F = boundary_triangles(mesh.T);  // normals point out of the part
  auto corner = [&](long f, int k) -> Eigen::Vector3d { return mesh.V.row(F(f, k)).transpose(); };
  const Eigen::Vector3d origin = mesh.V.colwise().minCoeff().transpose();
  mesh::SpatialGrid<3> grid(origin.data(), thickness / 4);
  for (long f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d lo = corner(f, 0).cwiseMin(corner(f, 1)).cwiseMin(corner(f, 2)),
                          hi = corner(f, 0).cwiseMax(corner(f, 1)).cwiseMax(corner(f, 2));
    grid.insert(static_cast<int>(f), lo.data(), hi.data());
  }
  for (long f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d a = corner(f, 0), b = corner(f, 1), c = corner(f, 2), n = (b - a).cross(c - a);
    if (n.norm() == 0) continue;
    const Eigen::Vector3d p = (a + b + c) / 3, u = -n.normalized(), q = p + thickness * u;
    const Eigen::Vector3d lo = p.cwiseMin(q), hi = p.cwiseMax(q);
    double hit = thickness;  // the first boundary triangle along the inward normal, within `thickness`
    grid.for_each(lo.data(), hi.data(), [&](int g) {
      if (g != f) hit = std::min(hit, ray_triangle_hit(p, u, corner(g, 0), corner(g, 1), corner(g, 2)));
    });
    if (hit < thickness)
      for (int k = 0; k < 3; ++k) thin[F(f, k)] = 1;
  }
  return thin;
}

std::vector<char> unpadded_nodes(const TetMesh& mesh, const std::vector<int>& supported_dofs,
                                 const Eigen::MatrixXd& loads, const MemberSizeParams& p) {
  std::vector<char> out = held_nodes(mesh.V.rows(), supported_dofs, loads);
  if (p.pad_thickness > 0 && p.min_size > 0) {
    const std::vector<char> thin = thin_part_nodes(mesh, p.pad_thickness * p.min_size);
    for (size_t i = 0; i < out.size(); ++i) out[i] |= thin[i];
  }
  return out;
}

void check_member_size(const MemberSizeParams& p, double mesh_size, bool projection) {
  auto bad = [](const std::string& key, const std::string& what) {
    throw Error(ErrorCode::InvalidParameter, "controls." + key + " " + what);
  };
  std::ostringstream h;
  h << mesh_size;
  if (p.min_size > 0) {
    if (p.min_size < 2 * mesh_size)
      bad("min_member_size", "is below two mesh sizes (the mean edge length is " + h.str() +
                                 " mm): raise it, or mesh finer (a member must span at least two elements)");
    if (!(p.eta_shift > 0.05 && p.eta_shift < 0.45))
      bad("min_member_eta_shift", "must lie in (0.05, 0.45) (0.25 is usual)");
    if (!projection) bad("min_member_size", "needs the Heaviside projection: remove \"heaviside\": false");
  }
  if (p.max_size > 0) {
    if (p.max_size < 3 * mesh_size)
      bad("max_member_size", "is below three mesh sizes (the mean edge length is " + h.str() +
                                 " mm): raise it, or mesh finer (the ball around an element must hold several)");
    if (p.min_size > 0 && p.max_size <= p.min_size)
      bad("max_member_size", "must be larger than controls.min_member_size");
    if (!(p.max_solid > 0.5 && p.max_solid < 1))
      bad("max_member_solid", "must lie in (0.5, 1) (0.9 is usual: the largest solid share of a ball)");
    if (!(p.pnorm >= 4 && p.pnorm <= 64)) bad("max_member_pnorm", "must lie in [4, 64] (16 is usual)");
  }
}

LocalVolumeConstraint::LocalVolumeConstraint(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volume,
                                             const MemberSizeParams& params)
    : max_solid_(params.max_solid), pnorm_(params.pnorm) {
  FilterParams fp;
  fp.kind = FilterKind::Cone;
  fp.radius = params.max_size / 2;
  ball_ = std::make_unique<DensityFilter>(mesh, design, volume, fp);
  volume_.resize(static_cast<long>(design.size()));
  for (size_t i = 0; i < design.size(); ++i) volume_[static_cast<long>(i)] = volume[design[i]];
}

LocalVolumeConstraint::~LocalVolumeConstraint() = default;

VecXd LocalVolumeConstraint::local_fractions(const VecXd& rho) const { return ball_->apply(rho); }

double LocalVolumeConstraint::p_mean(const VecXd& g) const {
  return std::pow(volume_.dot(g.array().pow(pnorm_).matrix()) / volume_.sum(), 1.0 / pnorm_);
}

double LocalVolumeConstraint::adapt(const VecXd& rho) {
  const VecXd g = clamped(rho);
  const double largest = g.maxCoeff(), ratio = largest / p_mean(g);
  scale_ = scale_ > 0 ? 0.5 * (scale_ + ratio) : ratio;
  return largest;
}

double LocalVolumeConstraint::evaluate(const VecXd& rho, VecXd* grad) const {
  const VecXd g = clamped(rho);
  const double mean = p_mean(g), c = scale_ > 0 ? scale_ : 1.0;
  if (grad) {  // dM/dg_i = v_i g_i^(P−1) M^(1−P) / Σ v
    const VecXd dm =
        volume_.cwiseProduct(g.array().pow(pnorm_ - 1).matrix()) * (std::pow(mean, 1 - pnorm_) / volume_.sum());
    *grad = ball_->apply_transpose(dm) * (c / max_solid_);
  }
  return c * mean / max_solid_ - 1;
}

}  // namespace topopt::simp
