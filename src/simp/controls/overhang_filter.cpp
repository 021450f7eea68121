// The overhang control (see overhang_filter.h).
#include "simp/controls/overhang_filter.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/error.h"
#include "simp/controls/tying.h"
#include "simp/density_filter.h"

namespace topopt::simp {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kSupports = 5;  // the node below and its four neighbours in that layer
/// A node more than this share of whose value comes from non-design elements is printed as
/// it is and carries what stands on it (a dual cell a quarter full of non-design material
/// lies within half a cell of it).
constexpr double kAnchored = 0.25;

[[noreturn]] void bad(const std::string& key, const std::string& what) {
  throw Error(ErrorCode::InvalidParameter, "controls.overhang." + key + " " + what);
}

const OverhangControl& checked(const OverhangControl& p) {
  const OverhangProblem problem = overhang_problem(p);
  if (!problem.key.empty()) bad(problem.key, problem.what);
  return p;
}

/// #T by 3: the centroids of all tets.
Eigen::MatrixX3d all_centroids(const TetMesh& mesh) {
  Eigen::MatrixX3d c = Eigen::MatrixX3d::Zero(mesh.T.rows(), 3);
  for (long t = 0; t < mesh.T.rows(); ++t)
    for (int a = 0; a < 4; ++a) c.row(t) += mesh.V.row(mesh.T(t, a)) / 4;
  return c;
}

}  // namespace

OverhangProblem overhang_problem(const OverhangControl& p) {
  if (!(p.direction.norm() > 0) || !p.direction.allFinite())
    return {"direction", "must be a non-zero vector: the build direction, from the base plate upwards"};
  if (!(p.angle >= 10 && p.angle <= 80))
    return {"angle",
            "must lie in [10, 80] degrees (the smallest self-supporting angle to the base plate; default 45), "
            "not " +
                std::to_string(p.angle)};
  if (!(p.margin >= 0 && p.margin <= 20 && p.angle + p.margin <= 85))
    return {"margin",
            "must lie in [0, 20] degrees with angle + margin <= 85 (the filter prints for angle + margin so "
            "that walls at the limit stay printable; default 20), not " +
                std::to_string(p.margin) + " with angle " + std::to_string(p.angle)};
  if (!(p.xi0 > 0 && p.xi0 < 1)) return {"xi0", "must lie in (0, 1) (default 0.5), not " + std::to_string(p.xi0)};
  if (!(p.exponent + std::log(kSupports) / std::log(p.xi0) >= 1))
    return {"exponent",
            "must exceed 1 + ln 5 / ln(1/xi0) = " + std::to_string(1 - std::log(kSupports) / std::log(p.xi0)) +
                " (default 40), not " + std::to_string(p.exponent)};
  if (!(p.smoothness > 0 && p.smoothness <= 0.01))
    return {"smoothness",
            "must lie in (0, 0.01] (the ε of the smooth minimum; default 1e-4), not " + std::to_string(p.smoothness)};
  if (p.base_face < 0) return {"base_face", "must be a face of the part (1 for Face1), or 0 for its lowest point"};
  return {};
}

double smooth_support(const double* x, int n, double p, double q, double* dx) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += std::pow(std::max(x[i], 0.0), p);
  if (!(s > 1e-300)) {
    std::fill(dx, dx + n, 0.0);
    return 0;
  }
  const double value = std::pow(s, 1 / q);
  for (int i = 0; i < n; ++i) dx[i] = x[i] > 0 ? p / q * value / s * std::pow(x[i], p - 1) : 0.0;
  return value;
}

double smooth_min(double a, double b, double eps, double* da, double* db) {
  const double r = std::sqrt((a - b) * (a - b) + eps);
  *da = 0.5 * (1 - (a - b) / r);
  *db = 0.5 * (1 + (a - b) / r);
  return 0.5 * (a + b - r + std::sqrt(eps));
}

double base_plate_height(const TetMesh& mesh, const Eigen::Vector3d& d, int base_face) {
  if (base_face == 0) return (mesh.V * d).minCoeff();
  double lo = 1e300, hi = -1e300, area = 0;
  const int num_faces = mesh.face.size() ? mesh.face.maxCoeff() : 0;
  for (long f = 0; f < mesh.F.rows(); ++f) {
    if (mesh.face[f] != base_face) continue;
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.dot(d) > -0.999 * n.norm())  // outward normal within 2.6° of -d
      bad("base_face", "= " + std::to_string(base_face) + ": Face" + std::to_string(base_face) +
                           " is not a flat face facing against the build direction; pick the face the part stands "
                           "on, or set controls.overhang.direction to that face's inward normal");
    for (const Eigen::Vector3d* p : {&a, &b, &c}) lo = std::min(lo, p->dot(d)), hi = std::max(hi, p->dot(d));
    area += n.norm() / 2;
  }
  if (!(area > 0))
    throw Error(ErrorCode::FaceNotFound, "controls.overhang.base_face = " + std::to_string(base_face) +
                                             ": the part has no Face" + std::to_string(base_face) +
                                             " (its faces are Face1 … Face" + std::to_string(num_faces) + ")");
  return hi;
}

OverhangFilter::OverhangFilter(const TetMesh& mesh, const std::vector<int>& design, const OverhangControl& params,
                               double cell)
    : params_(checked(params)), d_(params.direction.normalized()) {
  q_ = params_.exponent + std::log(kSupports) / std::log(params_.xi0);
  plate_ = base_plate_height(mesh, d_, params_.base_face);
  build_lattice(mesh, design, cell);
  std::ostringstream log;
  log << "overhang: build direction (" << d_.x() << ", " << d_.y() << ", " << d_.z() << "), " << params_.angle
      << " deg (filtered at " << params_.angle + params_.margin << "), base plate at " << plate_ << " mm"
      << (params_.base_face ? " (Face" + std::to_string(params_.base_face) + ")" : "") << ", lattice "
      << lattice_->nodes_along(0) << " x " << lattice_->nodes_along(1) << " x " << lattice_->nodes_along(2)
      << " nodes, " << cell << " mm across, layers " << cell * std::tan((params_.angle + params_.margin) * kPi / 180)
      << " mm";
  summary_ = log.str();
}

void OverhangFilter::build_lattice(const TetMesh& mesh, const std::vector<int>& design, double cell) {
  Eigen::Vector3d u, v;
  cross_section_basis(d_, u, v);
  Eigen::Matrix3d frame;
  frame << u.transpose(), v.transpose(), d_.transpose();
  const Eigen::Vector3d spacing(cell, cell, cell * std::tan((params_.angle + params_.margin) * kPi / 180));
  const Eigen::MatrixX3d points = mesh.V * frame.transpose();  // #V by 3: (u, v, s)
  const Eigen::Vector3d lo = points.colwise().minCoeff().transpose(), hi = points.colwise().maxCoeff().transpose();
  // a layer of nodes on the plate; layers 0 … base_layers_−1 at or below it
  const int below = std::max(0, static_cast<int>(std::ceil((plate_ - lo[2]) / spacing[2] - 1e-9)));
  base_layers_ = below + 1;
  const Eigen::Vector3d origin(lo[0], lo[1], plate_ - below * spacing[2]);
  std::array<int, 3> n;
  double count = 1;
  for (int a = 0; a < 3; ++a)
    count *= n[a] = static_cast<int>(std::min(1e7, std::floor((hi[a] - origin[a]) / spacing[a]) + 2));
  if (count > 2e7)
    bad("cell", "= " + std::to_string(cell) + " mm makes a lattice of " + std::to_string(static_cast<long>(count)) +
                    " nodes (at most 2e7): use a larger cell");
  std::vector<int> variable(mesh.T.rows(), -1);
  for (size_t i = 0; i < design.size(); ++i) variable[design[i]] = static_cast<int>(i);
  const Eigen::MatrixX3d local = (all_centroids(mesh) * frame.transpose()).rowwise() - origin.transpose();
  lattice_ = std::make_unique<LatticeTransfer>(local, tet_volumes(mesh), variable, static_cast<int>(design.size()),
                                               spacing, n);
  anchored_.resize(lattice_->num_nodes());
  for (long q = 0; q < lattice_->num_nodes(); ++q) anchored_[q] = lattice_->fixed_share()[q] > kAnchored;
  // the design elements of an anchored node's dual cell rest on the solid when they lie more
  // above its elements than beside them; beside or under it a sub-cell shelf of them would hang
  // from the solid's wall unchecked (a ceiling beside a load pad)
  carries_design_.resize(lattice_->num_nodes());
  for (long q = 0; q < lattice_->num_nodes(); ++q) {
    const Eigen::Vector3d o = lattice_->variable_offset().row(q);
    carries_design_[q] = o[2] > o.head<2>().norm();
  }
}

VecXd OverhangFilter::print(const VecXd& g, VecXd* adjoint) const {
  const int ni = lattice_->nodes_along(0), nj = lattice_->nodes_along(1), nk = lattice_->nodes_along(2);
  const long layer = static_cast<long>(ni) * nj;
  VecXd xi = g;
  std::vector<double> d_own(g.size(), 0.0), d_support(g.size() * kSupports, 0.0);
  std::vector<long> support(g.size() * kSupports, -1);
  for (int k = base_layers_; k < nk; ++k)
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i) {
        const long q = k * layer + static_cast<long>(j) * ni + i, below = q - layer;
        if (anchored_[q]) {  // non-design material: printed as it is
          if (carries_design_[q])
            d_own[q] = 1;  // and the design material resting on it
          else
            xi[q] = lattice_->fixed_share()[q];  // the design beside or under it is not carried by it
          continue;
        }
        long* s = &support[q * kSupports];
        int count = 0;
        s[count++] = below;
        if (i > 0) s[count++] = below - 1;
        if (i + 1 < ni) s[count++] = below + 1;
        if (j > 0) s[count++] = below - ni;
        if (j + 1 < nj) s[count++] = below + ni;
        double x[kSupports], dx[kSupports], d_max;
        for (int m = 0; m < count; ++m) x[m] = anchored_[s[m]] ? 1.0 : xi[s[m]];  // non-design: full support
        const double carried = smooth_support(x, count, params_.exponent, q_, dx);
        xi[q] = smooth_min(g[q], carried, params_.smoothness, &d_own[q], &d_max);
        for (int m = 0; m < count; ++m) d_support[q * kSupports + m] = anchored_[s[m]] ? 0.0 : d_max * dx[m];
      }
  if (!adjoint) return xi;
  VecXd& a = *adjoint;  // d/d ξ on entry; each layer hands its share down to its supports
  VecXd dg = VecXd::Zero(g.size());
  for (long q = g.size() - 1; q >= base_layers_ * layer; --q) {
    dg[q] += a[q] * d_own[q];
    for (int m = 0; m < kSupports && support[q * kSupports + m] >= 0; ++m)
      a[support[q * kSupports + m]] += a[q] * d_support[q * kSupports + m];
  }
  dg.head(base_layers_ * layer) += a.head(base_layers_ * layer);
  a = dg;
  return xi;
}

VecXd OverhangFilter::apply(const VecXd& r) const {
  return lattice_->to_elements(print(lattice_->to_grid(r), nullptr));
}

VecXd OverhangFilter::apply_transpose(const VecXd& r, const VecXd& g) const {
  VecXd adjoint = lattice_->to_elements_transpose(g);
  print(lattice_->to_grid(r), &adjoint);
  return lattice_->to_grid_transpose(adjoint);
}

}  // namespace topopt::simp
