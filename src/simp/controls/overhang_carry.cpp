// The non-design solids' undersides carried under an overhang control (see overhang_carry.h).
#include "simp/controls/overhang_carry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <unordered_map>
#include <utility>

#include "common/face_key.h"

namespace topopt::simp {

namespace {

constexpr double kPi = 3.14159265358979323846;

/// A non-design solid's downward face towards a design tet: its corners and that tet.
struct CarriedFace {
  std::array<int, 3> node;
  long design_tet;
};

bool tagged(const TetMesh& mesh) { return mesh.domain.size() == mesh.T.rows(); }

/// The faces between a non-design and a design tet whose normal out of the solid points against
/// the unit build direction d by more than cos(angle).
std::vector<CarriedFace> carried_faces(const TetMesh& mesh, const OverhangControl& control) {
  std::vector<CarriedFace> out;
  if (!tagged(mesh)) return out;
  const Eigen::Vector3d d = control.direction.normalized();
  const double limit = std::cos(control.angle * kPi / 180);
  std::unordered_map<FaceKey, std::pair<long, int>, FaceKeyHash> first;
  for (long t = 0; t < mesh.T.rows(); ++t)
    for (int i = 0; i < 4; ++i) {
      const int* o = kTetFace[i];
      const FaceKey key = face_key(mesh.T(t, o[0]), mesh.T(t, o[1]), mesh.T(t, o[2]));
      const auto [it, fresh] = first.emplace(key, std::make_pair(t, i));
      if (fresh) continue;
      const long u = it->second.first;
      if ((mesh.domain[t] == 0) == (mesh.domain[u] == 0)) continue;
      const long solid = mesh.domain[t] != 0 ? t : u, design = solid == t ? u : t;
      const Eigen::Vector3d a = mesh.V.row(key[0]), b = mesh.V.row(key[1]), c = mesh.V.row(key[2]);
      Eigen::Vector3d n = (b - a).cross(c - a);
      const Eigen::Vector3d inside = mesh.V.row(mesh.T(solid, 0)) + mesh.V.row(mesh.T(solid, 1)) +
                                     mesh.V.row(mesh.T(solid, 2)) + mesh.V.row(mesh.T(solid, 3));
      if (n.dot(inside / 4 - a) > 0) n = -n;  // out of the solid
      if (n.dot(d) < -limit * n.norm()) out.push_back({key, design});
    }
  return out;
}

/// The distance across the unit direction d from p to the segment a–b.
double distance_across(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                       const Eigen::Vector3d& d) {
  auto flat = [&](const Eigen::Vector3d& x) { return Eigen::Vector3d(x - x.dot(d) * d); };
  const Eigen::Vector3d pa = flat(p - a), ba = flat(b - a);
  const double len2 = ba.squaredNorm();
  const double s = len2 > 0 ? std::clamp(pa.dot(ba) / len2, 0.0, 1.0) : 0.0;
  return (pa - s * ba).norm();
}

/// Whether the line from c along d meets triangle abc (normal n, n·d < 0) at or above c; its
/// height above c in *h.
bool under(const Eigen::Vector3d& c, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& e,
           const Eigen::Vector3d& d, double* h) {
  const Eigen::Vector3d n = (b - a).cross(e - a);
  *h = n.dot(a - c) / n.dot(d);
  if (!(*h >= 0)) return false;
  const Eigen::Vector3d p = c + *h * d;
  const double nn = n.squaredNorm(), tol = -1e-9;
  return (b - a).cross(p - a).dot(n) / nn >= tol && (e - b).cross(p - b).dot(n) / nn >= tol &&
         (a - e).cross(p - e).dot(n) / nn >= tol;
}

/// The carried faces and their outline (their edges that only one of them has), and the funnel
/// under them: a point at height h below the nearest carried face above it, inset by `inset`
/// across the build direction from the outline, lies in it when inset >= h / slope.
struct Funnel {
  std::vector<CarriedFace> faces;
  std::vector<std::pair<int, int>> outline;
  Eigen::Vector3d d;
  double slope = 1;
  Funnel(const TetMesh& mesh, const OverhangControl& control) : faces(carried_faces(mesh, control)) {
    d = control.direction.normalized();
    slope = std::tan((control.angle + control.margin) * kPi / 180);
    std::map<std::pair<int, int>, int> uses;
    for (const CarriedFace& f : faces)
      for (int k = 0; k < 3; ++k) ++uses[std::minmax(f.node[k], f.node[(k + 1) % 3])];
    for (const auto& [edge, count] : uses)
      if (count == 1) outline.push_back(edge);
  }
  /// How far p lies inside the funnel across the build direction (mm; negative outside it), or
  /// -inf when no carried face lies above p.
  double inside(const TetMesh& mesh, const Eigen::Vector3d& p) const {
    double lowest = 1e300;  // the height of the nearest carried face above p
    for (const CarriedFace& f : faces)
      if (double h; under(p, mesh.V.row(f.node[0]), mesh.V.row(f.node[1]), mesh.V.row(f.node[2]), d, &h))
        lowest = std::min(lowest, h);
    if (lowest == 1e300) return -1e300;
    double inset = 1e300;
    for (const auto& [a, b] : outline) inset = std::min(inset, distance_across(p, mesh.V.row(a), mesh.V.row(b), d));
    return inset - lowest / slope;
  }
};

}  // namespace

std::vector<char> carried_tets(const TetMesh& mesh, const OverhangControl& control) {
  std::vector<char> out(mesh.T.rows(), 0);
  const Funnel funnel(mesh, control);
  for (const CarriedFace& f : funnel.faces) out[f.design_tet] = 1;
  if (funnel.faces.empty()) return out;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (mesh.domain[t] != 0 || out[t]) continue;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) c += mesh.V.row(mesh.T(t, a)).transpose() / 4;
    out[t] = funnel.inside(mesh, c) >= 0;
  }
  return out;
}

VecXd carried_level(const TetMesh& mesh, const OverhangControl& control, double ramp) {
  VecXd level = VecXd::Zero(mesh.V.rows());
  const Funnel funnel(mesh, control);
  if (funnel.faces.empty()) return level;
  for (long v = 0; v < mesh.V.rows(); ++v)
    level[v] = std::clamp(1 + funnel.inside(mesh, mesh.V.row(v)) / ramp, 0.0, 1.0);
  return level;
}

}  // namespace topopt::simp
