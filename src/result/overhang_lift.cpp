// The last pass of the surface stage under an overhang control (see overhang_lift.h).
#include "result/overhang_lift.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

#include "result/crossing_guard.h"
#include "result/editable_surface.h"
#include "result/result_check.h"

namespace topopt::result {

namespace {

using Tri = EditableSurface::Tri;

constexpr double kDegree = M_PI / 180;

/// Whether triangle t of V rests on the plate: every corner within the plate's tolerance.
bool on_plate(const MatX3d& V, const Tri& t, const BuildDirection& build) {
  for (int v : t)
    if (std::abs(V.row(v).dot(build.direction) - build.plate) > build.plate_tolerance) return false;
  return true;
}

/// The area-weighted excess of triangle t: its area times how far its unit normal's component
/// along −direction exceeds cos_limit (0 for a triangle steep enough, facing up or on the plate).
double excess(const MatX3d& V, const Tri& t, const BuildDirection& build, double cos_limit) {
  const Eigen::Vector3d n = normal_of(V, t);
  const double down = -n.dot(build.direction), twice_area = n.norm();
  if (!(twice_area > 0) || down <= cos_limit * twice_area || on_plate(V, t, build)) return 0;
  return 0.5 * (down - cos_limit * twice_area);  // area · (−n̂·d − cos_limit)
}

/// The pass: points of too-flat facets moved one at a time, each move checked as the header says.
class Lifter {
 public:
  Lifter(TriSurface& s, const BuildDirection& b, const OverhangLiftParams& p)
      : s_(s),
        b_(b),
        p_(p),
        m_(s.F, s.tag, s.V.rows()),
        guard_(s_.V, m_),
        start_(s.V),
        cos_limit_(std::cos((b.angle + p.lift_margin) * kDegree)),
        reach_(s.V.rows(), 0.0) {
    for (int v = 0; v < m_.points(); ++v) {
      double sum = 0;
      const std::vector<int> nb = m_.neighbours(v);
      for (int w : nb) sum += (s_.V.row(v) - s_.V.row(w)).norm();
      reach_[v] = nb.empty() || !on_a_printable_slope(v) ? 0 : p_.reach * sum / static_cast<double>(nb.size());
    }
  }

  /// The whole surface's hanging edges (mm) and lowest points off the plate.
  std::pair<double, long> all_islands() const {
    double hanging = 0;
    long lowest = 0;
    for (int v = 0; v < m_.points(); ++v) {
      if (m_.star(v).empty()) continue;
      lowest += lowest_point(v);
      for (int w : m_.neighbours(v))
        if (w > v) hanging += hanging_length(v, w);
    }
    return {hanging, lowest};
  }

  long run() {
    long moves = 0;
    for (int sweep = 0; sweep < p_.sweeps; ++sweep) {
      long moved = 0;
      for (int v : points_of_flat_facets()) moved += move(v);
      moves += moved;
      if (moved == 0) break;
    }
    return moves;
  }

 private:
  /// The points that may move and lie on a facet with an excess, each once.
  std::vector<int> points_of_flat_facets() const {
    std::vector<char> mark(s_.V.rows(), 0);
    for (int t = 0; t < m_.triangles(); ++t)
      if (m_.alive(t) && excess(s_.V, m_.tri(t), b_, cos_limit_) > 0)
        for (int v : m_.tri(t)) mark[v] = 1;
    std::vector<int> out;
    for (int v = 0; v < static_cast<int>(mark.size()); ++v)
      if (mark[v] && plane_of(v, nullptr)) out.push_back(v);
    return out;
  }

  /// Whether v may move; *normal (when given) gets the normal of the plane it must stay in
  /// (zero for a free point). Free points move; a point of a planar Ω face's cut line moves in the
  /// face's plane; nothing else does.
  bool plane_of(int v, Eigen::Vector3d* normal) const {
    if (normal) normal->setZero();
    if (s_.lock[v] == 0) return true;
    if (s_.lock[v] != 1 || s_.point_face.size() != s_.V.rows()) return false;
    const int f = s_.point_face[v];
    if (f <= 0 || f >= static_cast<int>(s_.face_plane.size()) || s_.face_plane[f].head<3>().norm() == 0) return false;
    for (int t : m_.star(v))
      if (m_.tag(t) != 0 && m_.tag(t) != f) return false;
    if (normal) *normal = s_.face_plane[f].head<3>().normalized();
    return true;
  }

  /// Whether the surface around v as the pass found it — the triangles of its star and its
  /// neighbours' stars (its 2-ring) taken as one patch, less those resting on the plate — rises at
  /// least the angle (or faces up). The patch's area vector (the sum of its triangles', which
  /// depends on the patch's rim only, not on where v lies inside it) is the slope at the scale
  /// of the surface's edges, the slope the pass restores v's facets to. A patch flatter than the
  /// angle is a ceiling: tilting its small facets would corrugate it into steep facets that print
  /// on nothing, so its points stay and a flat ceiling cannot be made to look printable, whatever
  /// its ripple. A patch whose area vector vanishes has no slope and stays too.
  bool on_a_printable_slope(int v) const {
    std::vector<int> patch = m_.star(v);
    for (int w : m_.neighbours(v)) patch.insert(patch.end(), m_.star(w).begin(), m_.star(w).end());
    std::sort(patch.begin(), patch.end());
    patch.erase(std::unique(patch.begin(), patch.end()), patch.end());
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (int t : patch)
      if (!on_plate(s_.V, m_.tri(t), b_)) n += normal_of(s_.V, m_.tri(t));
    return n.norm() > 0 && -n.dot(b_.direction) <= std::cos(b_.angle * kDegree) * n.norm();
  }

  /// The summed excess of v's triangles with v at p.
  double star_excess(int v, const Eigen::Vector3d& p) {
    const Eigen::RowVector3d kept = s_.V.row(v);
    s_.V.row(v) = p.transpose();
    double e = 0;
    for (int t : m_.star(v)) e += excess(s_.V, m_.tri(t), b_, cos_limit_);
    s_.V.row(v) = kept;
    return e;
  }

  /// p put back into the plane through v's start with normal n (zero: none) and into the ball of
  /// v's reach around its start.
  Eigen::Vector3d bounded(int v, Eigen::Vector3d p, const Eigen::Vector3d& n) const {
    const Eigen::Vector3d o = start_.row(v).transpose();
    p -= (p - o).dot(n) * n;
    const double r = (p - o).norm();
    return r > reach_[v] ? Eigen::Vector3d(o + (p - o) * (reach_[v] / r)) : p;
  }

  /// The edges of v's triangles, each once (point pairs, smaller first).
  std::vector<std::array<int, 2>> star_edges(int v) const {
    std::vector<std::array<int, 2>> out;
    for (int t : m_.star(v))
      for (int k = 0; k < 3; ++k) {
        const int a = m_.tri(t)[k], b = m_.tri(t)[(k + 1) % 3];
        out.push_back({std::min(a, b), std::max(a, b)});
      }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  /// The length of edge ab when it hangs: a keel — across it the surface rises on both sides
  /// (both opposite corners above the edge's line, measured along the part of the direction
  /// normal to the edge), its two triangles' summed normal faces down, and the edge itself rises
  /// less than the angle from the plate. Printed, its lowest layer is a line on nothing, however
  /// steep its two triangles are; else 0.
  double hanging_length(int a, int b) const {
    const std::vector<int> e = m_.edge_triangles(a, b);
    if (e.size() != 2) return 0;
    const Eigen::Vector3d pa = s_.V.row(a), pb = s_.V.row(b);
    const double len = (pb - pa).norm();
    if (!(len > 0)) return 0;
    const Eigen::Vector3d u = (pb - pa) / len, d = b_.direction;
    if (std::abs(u.dot(d)) >= std::sin(b_.angle * kDegree)) return 0;  // a steep edge prints
    if ((normal_of(s_.V, m_.tri(e[0])).normalized() + normal_of(s_.V, m_.tri(e[1])).normalized()).dot(d) >= 0) return 0;
    const Eigen::Vector3d across = (d - d.dot(u) * u).normalized();
    for (int t : e) {
      const Eigen::Vector3d c = s_.V.row(m_.third(t, a, b));
      if ((c - pa).dot(across) <= 1e-9 * len) return 0;
    }
    return len;
  }

  /// Whether w is a lowest point off the plate: every neighbour higher along the direction. Such
  /// a point starts an island when printed.
  bool lowest_point(int w) const {
    const double h = s_.V.row(w).dot(b_.direction);
    if (std::abs(h - b_.plate) <= b_.plate_tolerance) return false;
    for (int x : m_.neighbours(w))
      if (s_.V.row(x).dot(b_.direction) <= h) return false;
    return true;
  }

  /// What must not grow when v moves: the hanging edges' length around v and the lowest points
  /// among v and its neighbours.
  std::pair<double, int> islands(int v) const {
    double hanging = 0;
    for (const auto& e : star_edges(v)) hanging += hanging_length(e[0], e[1]);
    int lowest = lowest_point(v);
    for (int w : m_.neighbours(v)) lowest += lowest_point(w);
    return {hanging, lowest};
  }

  /// Whether v at p keeps its triangles' shapes and orientation, makes no keel or lowest point,
  /// and crosses nothing (v stays at p when true).
  bool admissible(int v, const Eigen::Vector3d& p) {
    const Eigen::RowVector3d kept = s_.V.row(v);
    std::vector<double> angle_before;
    std::vector<Eigen::Vector3d> normal_before;
    for (int t : m_.star(v)) {
      angle_before.push_back(min_triangle_angle(s_.V, m_.tri(t)[0], m_.tri(t)[1], m_.tri(t)[2]));
      normal_before.push_back(normal_of(s_.V, m_.tri(t)).normalized());
    }
    const auto [hanging_before, lowest_before] = islands(v);
    s_.V.row(v) = p.transpose();
    const double cos_turn = std::cos(p_.max_normal_turn * kDegree);
    size_t k = 0;
    bool ok = true;
    std::vector<Tri> tris;
    for (int t : m_.star(v)) {
      const double a = min_triangle_angle(s_.V, m_.tri(t)[0], m_.tri(t)[1], m_.tri(t)[2]);
      const Eigen::Vector3d n = normal_of(s_.V, m_.tri(t));
      ok = ok && a >= std::min(p_.min_angle, angle_before[k]) && n.norm() > 0 &&
           n.normalized().dot(normal_before[k]) >= cos_turn;
      tris.push_back(m_.tri(t));
      ++k;
    }
    if (ok) {
      const auto [hanging_after, lowest_after] = islands(v);
      ok = hanging_after <= hanging_before + 1e-12 && lowest_after <= lowest_before;
    }
    if (ok && !guard_.crosses(tris, m_.star(v))) {
      for (int t : m_.star(v)) guard_.add(t);
      return true;
    }
    s_.V.row(v) = kept;
    return false;
  }

  /// Tries to lower the excess around v: along its negative gradient (central differences),
  /// halving the step from v's reach, then along fixed directions. 1 if v moved.
  int move(int v) {
    Eigen::Vector3d n;
    plane_of(v, &n);
    const Eigen::Vector3d p0 = s_.V.row(v).transpose();
    const double e0 = star_excess(v, p0);
    if (e0 <= 0 || reach_[v] <= 0) return 0;
    const double h = 1e-6 * reach_[v];
    Eigen::Vector3d g;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d dk = Eigen::Vector3d::Unit(k) * h;
      g[k] = (star_excess(v, p0 + dk) - star_excess(v, p0 - dk)) / (2 * h);
    }
    g -= g.dot(n) * n;
    std::vector<Eigen::Vector3d> dirs;
    if (g.norm() > 0) dirs.push_back(-g.normalized());
    for (int k = 0; k < 3; ++k) dirs.push_back(Eigen::Vector3d::Unit(k)), dirs.push_back(-Eigen::Vector3d::Unit(k));
    for (const Eigen::Vector3d& dir : dirs)
      for (double step = reach_[v]; step > 1e-3 * reach_[v]; step *= 0.5) {
        const Eigen::Vector3d p = bounded(v, p0 + step * dir, n);
        if ((p - p0).norm() < 1e-9 * reach_[v] || star_excess(v, p) >= e0 - 1e-15) continue;
        if (admissible(v, p)) return 1;
      }
    return 0;
  }

  TriSurface& s_;
  const BuildDirection& b_;
  const OverhangLiftParams& p_;
  EditableSurface m_;
  CrossingGuard guard_;
  MatX3d start_;               ///< where the pass found the points
  double cos_limit_;           ///< cos(angle + lift_margin)
  std::vector<double> reach_;  ///< per point: how far it may go from its start
};

}  // namespace

double too_flat_area(const TriSurface& s, const BuildDirection& build, double angle) {
  if (!build.active()) return 0;
  BuildDirection unit = build;
  unit.direction.normalize();
  const double cos_limit = std::cos(angle * kDegree);
  double area = 0;
  for (long t = 0; t < s.F.rows(); ++t) {
    const Tri tri = {s.F(t, 0), s.F(t, 1), s.F(t, 2)};
    const Eigen::Vector3d n = normal_of(s.V, tri);
    if (n.norm() > 0 && -n.dot(unit.direction) > cos_limit * n.norm() && !on_plate(s.V, tri, unit))
      area += 0.5 * n.norm();
  }
  return area;
}

OverhangLiftReport lift_overhangs(TriSurface& s, const BuildDirection& build, const OverhangLiftParams& params) {
  OverhangLiftReport r;
  if (!build.active()) return r;
  BuildDirection unit = build;
  unit.direction.normalize();
  r.before = too_flat_area(s, unit, unit.angle);
  Lifter lifter(s, unit, params);
  std::tie(r.keels_before, r.lowest_before) = lifter.all_islands();
  r.moves = lifter.run();
  std::tie(r.keels_after, r.lowest_after) = lifter.all_islands();
  r.after = too_flat_area(s, unit, unit.angle);
  return r;
}

}  // namespace topopt::result
