// Edge collapses on the result's free-form region within a chordal tolerance (see step_coarsen.h).
#include "result/step_coarsen.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

#include "common/closed_surface.h"
#include "common/triangle_closest.h"
#include "result/editable_surface.h"
#include "result/result_check.h"

namespace topopt::result {
namespace {

using Vec3 = Eigen::Vector3d;
using Tri = std::array<int, 3>;

/// The median length of the free-form triangles' edges (0 when there are none).
double median_free_edge(const TriSurface& s) {
  std::vector<double> lengths;
  for (long q = 0; q < s.F.rows(); ++q)
    if (s.tag[q] == 0)
      for (int k = 0; k < 3; ++k) lengths.push_back((s.V.row(s.F(q, k)) - s.V.row(s.F(q, (k + 1) % 3))).norm());
  if (lengths.empty()) return 0;
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  return lengths[lengths.size() / 2];
}

/// The surface under collapse (an EditableSurface: triangles alive or removed, the triangles
/// around each point) and for each triangle the removed points it now stands for (they must
/// stay within the tolerance of it).
class Collapser {
 public:
  Collapser(const TriSurface& s, const CoarsenParams& params, double tolerance)
      : s_(s), params_(params), tolerance_(tolerance), m_(s.F, s.tag, s.V.rows()), stands_for_(s.F.rows()) {}

  /// One sweep over the free-form edges, shortest first; returns the points removed.
  long sweep() {
    std::vector<std::pair<double, std::pair<int, int>>> edges;
    for (int t = 0; t < m_.triangles(); ++t)
      if (m_.alive(t) && m_.tag(t) == 0)
        for (int k = 0; k < 3; ++k) {
          const int a = m_.tri(t)[k], b = m_.tri(t)[(k + 1) % 3];
          edges.push_back({(point(a) - point(b)).norm(), {a, b}});
        }
    std::sort(edges.begin(), edges.end());
    long removed = 0;
    for (const auto& [length, ab] : edges)
      removed += try_collapse(ab.second, ab.first) || try_collapse(ab.first, ab.second);
    return removed;
  }

  /// The surface with the triangles alive.
  TriSurface surface() const {
    TriSurface out = s_;
    m_.live(out.F, out.tag);
    return out;
  }

 private:
  Vec3 point(int i) const { return s_.V.row(i).transpose(); }

  /// True when point b may go: free to move and only free-form triangles around it.
  bool removable(int b) const {
    if (removed_point(b) || s_.lock[b] != 0 || (s_.point_face.size() && s_.point_face[b] != 0)) return false;
    return std::all_of(m_.star(b).begin(), m_.star(b).end(), [&](int t) { return m_.tag(t) == 0; });
  }
  bool removed_point(int i) const { return m_.star(i).empty(); }

  /// Triangle t with point b replaced by a.
  Tri moved(int t, int b, int a) const {
    Tri out = m_.tri(t);
    for (int& v : out)
      if (v == b) v = a;
    return out;
  }

  /// True when triangle `to` (t with b moved onto a) keeps its side and its shape.
  bool shape_kept(int t, const Tri& to, double floor) const {
    const Tri& from = m_.tri(t);
    const Vec3 n0 = (point(from[1]) - point(from[0])).cross(point(from[2]) - point(from[0]));
    const Vec3 n1 = (point(to[1]) - point(to[0])).cross(point(to[2]) - point(to[0]));
    if (n1.norm() <= 1e-12 * std::max(1.0, n0.norm()) || n0.norm() == 0) return false;
    if (n0.normalized().dot(n1.normalized()) < std::cos(params_.max_normal_turn)) return false;
    return min_triangle_angle(s_.V, to[0], to[1], to[2]) >= floor;
  }

  /// The triangle among `kept` nearest to p, and its distance.
  std::pair<int, double> nearest(const Vec3& p, const std::vector<std::pair<int, Tri>>& kept) const {
    std::pair<int, double> best{-1, 1e300};
    for (const auto& [t, tri] : kept) {
      const double d = point_triangle_distance(p, point(tri[0]), point(tri[1]), point(tri[2]));
      if (d < best.second) best = {t, d};
    }
    return best;
  }

  /// Removes b by joining it to a when every condition holds; returns whether it did.
  bool try_collapse(int b, int a) {
    if (!removable(b) || removed_point(a)) return false;
    std::vector<std::pair<int, Tri>> kept;
    double floor = params_.min_angle;
    for (int t : m_.star(b)) {
      floor = std::min(floor, min_triangle_angle(s_.V, m_.tri(t)[0], m_.tri(t)[1], m_.tri(t)[2]));
      if (std::find(m_.tri(t).begin(), m_.tri(t).end(), a) == m_.tri(t).end()) kept.push_back({t, moved(t, b, a)});
    }
    // kept.size() < 2: b has three neighbours (a tetrahedron's corner would fold it flat)
    if (!m_.link_condition(a, b) || kept.size() < 2) return false;
    for (const auto& [t, to] : kept)
      if (!shape_kept(t, to, floor)) return false;
    std::vector<int> points{b};
    for (int t : m_.star(b)) points.insert(points.end(), stands_for_[t].begin(), stands_for_[t].end());
    std::vector<int> home;
    for (int p : points) {
      const auto [t, d] = nearest(point(p), kept);
      if (d > tolerance_) return false;
      home.push_back(t);
    }
    commit(b, a, points, home);
    return true;
  }

  /// Joins b to a and hands the points b's triangles stood for (and b) to their nearest kept
  /// triangles `home`.
  void commit(int b, int a, const std::vector<int>& points, const std::vector<int>& home) {
    for (int t : m_.star(b)) stands_for_[t].clear();
    m_.collapse(b, a);
    for (size_t k = 0; k < points.size(); ++k) stands_for_[home[k]].push_back(points[k]);
  }

  const TriSurface& s_;
  const CoarsenParams& params_;
  const double tolerance_;
  EditableSurface m_;
  std::vector<std::vector<int>> stands_for_;
};

}  // namespace

double point_triangle_distance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return (p - closest_on_triangle(p, a, b, c)).norm();
}

TriSurface coarsen_free_form(const TriSurface& s, const CoarsenParams& params, CoarsenReport* report) {
  CoarsenReport r;
  r.triangles_before = r.triangles_after = s.F.rows();
  r.tolerance = params.tolerance * median_free_edge(s);
  if (report) *report = r;
  if (r.tolerance <= 0) return s;
  Collapser collapser(s, params, r.tolerance);
  for (int pass = 0; pass < params.passes; ++pass)
    if (collapser.sweep() == 0) break;
  TriSurface out = collapser.surface();
  r.reverted = !check_result(out, 1).valid();
  if (r.reverted) out = s;
  r.triangles_after = out.F.rows();
  r.volume_change = std::abs(check_surface(out.V, out.F).volume / check_surface(s.V, s.F).volume - 1);
  if (report) *report = r;
  return out;
}

TriSurface coarsen_to_budget(const TriSurface& s, const CoarsenParams& params, const CoarsenBudget& budget,
                             CoarsenReport* report) {
  CoarsenReport r;
  TriSurface out = coarsen_free_form(s, params, &r);
  const auto over = [&](const CoarsenReport& c) { return budget.max_triangles > 0 && c.triangles_after > budget.max_triangles; };
  CoarsenParams harder = params;
  harder.tolerance = params.tolerance > 0 ? params.tolerance : CoarsenParams{}.tolerance;
  int attempts = 1;
  if (r.volume_change > budget.max_volume_change) out = s, r = CoarsenReport{s.F.rows(), s.F.rows()};
  while (over(r) && (harder.tolerance *= 2) <= budget.max_tolerance * (1 + 1e-9)) {
    CoarsenReport next;
    TriSurface candidate = coarsen_free_form(s, harder, &next);
    ++attempts;
    if (next.volume_change > budget.max_volume_change) break;
    if (next.reverted || next.triangles_after >= r.triangles_after) continue;  // crossed itself: the next may not
    out = std::move(candidate), r = next;
  }
  r.attempts = attempts;
  r.fits = !over(r);
  if (report) *report = r;
  return out;
}

}  // namespace topopt::result
