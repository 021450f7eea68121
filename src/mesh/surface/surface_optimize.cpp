// Flips and smoothing of a face's triangles judged on the surface (see surface_optimize.h).
#include "mesh/surface/surface_optimize.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "mesh/core/predicates.h"

namespace topopt::mesh {
namespace {

uint64_t ekey(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

/// Two corners at one point (up to rounding): a triangle of a degenerate edge's strip (a cone's
/// apex, a sphere's pole), whose two apex corners are one node of the surface mesh.
bool collapsed(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double ab = (b - a).squaredNorm(), bc = (c - b).squaredNorm(), ca = (a - c).squaredNorm();
  return std::min({ab, bc, ca}) <= 1e-20 * std::max({ab, bc, ca});
}

/// Smallest angle (degrees) of the 3D triangle abc.
double min_angle(const MatX3d& X, int a, int b, int c) {
  const Eigen::Vector3d p[3] = {X.row(a), X.row(b), X.row(c)};
  if (collapsed(p[0], p[1], p[2])) return 180;  // collapsed onto an apex: not judged
  double m = 180;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
    m = std::min(m, std::atan2(u.cross(v).norm(), u.dot(v)));
  }
  return m * 180 / M_PI;
}

bool ccw(const MatX2d& P, int a, int b, int c) {
  return predicates::orient2d(P.row(a).data(), P.row(b).data(), P.row(c).data()) > 0;
}

/// 3D normals of abc and of the surface agree (guards flips and moves against folds on
/// surfaces that turn a lot within one triangle).
bool faces_out(const MatX3d& X, const MatX3d& N, int a, int b, int c) {
  if (collapsed(X.row(a), X.row(b), X.row(c))) return true;  // no normal: judged in the parameters only
  const Eigen::Vector3d n = (Eigen::Vector3d(X.row(b)) - Eigen::Vector3d(X.row(a)))
                                .cross(Eigen::Vector3d(X.row(c)) - Eigen::Vector3d(X.row(a)));
  const Eigen::Vector3d s = Eigen::Vector3d(N.row(a)) + Eigen::Vector3d(N.row(b)) + Eigen::Vector3d(N.row(c));
  return n.dot(s) > 0.5 * n.norm() * s.norm();
}

/// The triangles around each node as one flat array (CSR), rebuilt per sweep.
class Stars {
 public:
  struct Range {
    const int *b, *e;
    const int* begin() const { return b; }
    const int* end() const { return e; }
    bool empty() const { return b == e; }
  };
  void build(const MatX3i& T, long nt, long n, const std::vector<char>& dead) {
    start_.assign(n + 1, 0);
    for (long t = 0; t < nt; ++t)
      if (dead.empty() || !dead[t])
        for (int k = 0; k < 3; ++k) ++start_[T(t, k) + 1];
    for (long i = 0; i < n; ++i) start_[i + 1] += start_[i];
    items_.resize(start_[n]);
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (long t = 0; t < nt; ++t)
      if (dead.empty() || !dead[t])
        for (int k = 0; k < 3; ++k) items_[fill[T(t, k)]++] = static_cast<int>(t);
  }
  Range operator[](long v) const { return {items_.data() + start_[v], items_.data() + start_[v + 1]}; }

 private:
  std::vector<int> start_, items_;
};

/// The nodes sharing a triangle with v (sorted, once each).
void neighbours(const MatX3i& T, const Stars& star, int v, std::vector<int>& out) {
  out.clear();
  for (int t : star[v])
    for (int j = 0; j < 3; ++j)
      if (T(t, j) != v) out.push_back(T(t, j));
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace

SurfaceOptimizeStats optimize_on_surface(MatX2d& P, MatX3i& T, MatX3d& X, int fixed, const SurfaceEval& eval,
                                         const std::vector<std::array<int, 2>>& constrained, int rounds) {
  SurfaceOptimizeStats st;
  long n = P.rows();
  long nt = T.rows();
  X.resize(n, 3);
  MatX3d N(n, 3);  // surface normals in the parameters' orientation (Xu × Xv)
  std::vector<Eigen::Vector3d> Xu(n), Xv(n);
  auto evaluate = [&](long i) {
    double x[3], du[3], dv[3];
    eval(P.row(i).data(), x, du, dv);
    X.row(i) << x[0], x[1], x[2];
    Xu[i] = Eigen::Vector3d(du[0], du[1], du[2]);
    Xv[i] = Eigen::Vector3d(dv[0], dv[1], dv[2]);
    const Eigen::Vector3d nn = Xu[i].cross(Xv[i]);
    N.row(i) = nn.norm() > 0 ? Eigen::RowVector3d(nn.normalized()) : Eigen::RowVector3d::Zero();
  };
  for (long i = 0; i < n; ++i) evaluate(i);
  // a node's position with what evaluate() derived from it, to put back a move that failed
  struct NodeState {
    Eigen::RowVector2d p;
    Eigen::RowVector3d x, n;
    Eigen::Vector3d u, v;
  };
  auto save = [&](long i) { return NodeState{P.row(i), X.row(i), N.row(i), Xu[i], Xv[i]}; };
  auto restore = [&](long i, const NodeState& s) {
    P.row(i) = s.p, X.row(i) = s.x, N.row(i) = s.n, Xu[i] = s.u, Xv[i] = s.v;
  };
  st.min_angle_before = 180;
  for (long t = 0; t < nt; ++t)
    st.min_angle_before = std::min(st.min_angle_before, min_angle(X, T(t, 0), T(t, 1), T(t, 2)));
  std::unordered_set<uint64_t> locked;
  for (const auto& e : constrained) locked.insert(ekey(e[0], e[1]));

  auto flip_sweep = [&]() {
    long flips = 0;
    for (int sweep = 0; sweep < 6; ++sweep) {
      std::unordered_map<uint64_t, std::array<int, 2>> edge_tris;  // edge -> (t0, t1); -1 if none
      edge_tris.reserve(3 * nt);
      for (int t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
          auto [it, fresh] = edge_tris.try_emplace(ekey(T(t, k), T(t, (k + 1) % 3)), std::array<int, 2>{t, -1});
          if (!fresh) it->second[1] = t;
        }
      std::vector<char> touched(nt, 0);
      long here = 0;
      for (const auto& [key, tt] : edge_tris) {
        const int t0 = tt[0], t1 = tt[1];
        if (t1 < 0 || touched[t0] || touched[t1] || locked.count(key)) continue;
        // t0 = (a, b, c) with the edge a->b, t1 holds b->a and d
        int k0 = 0;
        while (ekey(T(t0, k0), T(t0, (k0 + 1) % 3)) != key) ++k0;
        const int a = T(t0, k0), b = T(t0, (k0 + 1) % 3), c = T(t0, (k0 + 2) % 3);
        int d = -1;
        for (int k = 0; k < 3; ++k)
          if (T(t1, k) != a && T(t1, k) != b) d = T(t1, k);
        if (d < 0 || d == c || locked.count(ekey(c, d))) continue;
        // new pair (c, a, d) and (d, b, c): valid in the parameters, better on the surface
        if (!ccw(P, c, a, d) || !ccw(P, d, b, c)) continue;
        const double before = std::min(min_angle(X, a, b, c), min_angle(X, b, a, d));
        const double after = std::min(min_angle(X, c, a, d), min_angle(X, d, b, c));
        if (after <= before + 0.5) continue;
        if (!faces_out(X, N, c, a, d) || !faces_out(X, N, d, b, c)) continue;
        T.row(t0) << c, a, d;
        T.row(t1) << d, b, c;
        touched[t0] = touched[t1] = 1;
        ++here;
      }
      flips += here;
      if (!here) break;
    }
    return flips;
  };

  auto smooth_sweep = [&]() {
    long moves = 0;
    Stars star;
    star.build(T, nt, n, {});
    std::vector<int> nbr;
    for (long i = fixed; i < n; ++i) {
      if (star[i].empty()) continue;
      neighbours(T, star, static_cast<int>(i), nbr);
      Eigen::Vector3d target = Eigen::Vector3d::Zero();
      for (int j : nbr) target += Eigen::Vector3d(X.row(j));
      target /= static_cast<double>(nbr.size());
      // one Gauss-Newton step back onto the surface: [Xu Xv] d = target - X
      Eigen::Matrix<double, 3, 2> J;
      J << Xu[i], Xv[i];
      const Eigen::Matrix2d JtJ = J.transpose() * J;
      if (std::abs(JtJ.determinant()) < 1e-300) continue;
      const Eigen::Vector2d dlt = JtJ.ldlt().solve(J.transpose() * (target - Eigen::Vector3d(X.row(i))));
      double old_min = 180, old_sum = 0;
      for (int t : star[i]) {
        const double m = min_angle(X, T(t, 0), T(t, 1), T(t, 2));
        old_min = std::min(old_min, m), old_sum += m;
      }
      const NodeState old = save(i);
      bool ok = false;
      for (double step : {1.0, 0.5, 0.25}) {
        P.row(i) = old.p + step * dlt.transpose();
        bool valid = true;
        for (int t : star[i]) valid &= ccw(P, T(t, 0), T(t, 1), T(t, 2));
        if (!valid) continue;
        evaluate(i);
        double new_min = 180, new_sum = 0;
        for (int t : star[i]) {
          const double m = min_angle(X, T(t, 0), T(t, 1), T(t, 2));
          new_min = std::min(new_min, m), new_sum += m;
          valid &= faces_out(X, N, T(t, 0), T(t, 1), T(t, 2));
        }
        // the star's smallest angle rises, or its angles improve on the whole without the
        // smallest dropping below min(before, 30°)
        const bool better = new_min > old_min || (new_sum > old_sum && new_min >= std::min(old_min, 30.0));
        if (valid && better) {
          ok = true;
          break;
        }
      }
      if (ok) {
        ++moves;
      } else {
        restore(i, old);
      }
    }
    return moves;
  };

  // Compass search in the parameters for the position of node i that maximises the smallest
  // angle of its triangles `star` on the surface (every one valid in the parameters and facing
  // out); returns that angle (-1 if the star is invalid where it starts) and whether i moved.
  auto compass_node = [&](int i, const int* star_begin, const int* star_end, bool& any) {
    auto worst = [&]() {
      double w = 180;
      for (const int* q = star_begin; q != star_end; ++q) {
        if (!ccw(P, T(*q, 0), T(*q, 1), T(*q, 2)) || !faces_out(X, N, T(*q, 0), T(*q, 1), T(*q, 2))) return -1.0;
        w = std::min(w, min_angle(X, T(*q, 0), T(*q, 1), T(*q, 2)));
      }
      return w;
    };
    any = false;
    double len = 0;
    int cnt = 0;
    for (const int* q = star_begin; q != star_end; ++q)
      for (int j = 0; j < 3; ++j)
        if (T(*q, j) != i) len += (P.row(T(*q, j)) - P.row(i)).norm(), ++cnt;
    double best = worst();
    if (!cnt || best < 0) return best;
    double step = 0.1 * len / cnt;
    for (int it = 0; it < 30 && step > 1e-3 * len / cnt; ++it) {
      bool moved = false;
      for (int d = 0; d < 4 && !moved; ++d) {
        const NodeState old = save(i);
        P(i, d / 2) += d % 2 ? -step : step;
        evaluate(i);
        const double now = worst();
        if (now > best) {
          best = now, moved = any = true;
        } else {
          restore(i, old);
        }
      }
      if (!moved) step *= 0.5;
    }
    return best;
  };

  // Collapse of an edge: its movable end b goes onto the other end a (or both onto the
  // middle when both may move), kept only if every triangle stays valid in the parameters and
  // the smallest angle of the region rises. Tried on short edges that make needles (the front
  // sometimes leaves an edge much shorter than its neighbours where fronts meet), and on
  // triangles below kBadAngle: each edge of theirs, then each movable corner onto each of its
  // neighbours (a node squeezed against a boundary segment makes a flat cap that no move or
  // flip can open).
  constexpr double kBadAngle = 20;
  // nodes that never move: below `fixed`; the ends of constrained edges (the apex's
  // neighbours on a cone) may move, and go only onto a neighbour that takes their locked edges
  std::vector<char> keep_node(n, 0), pinned(n, 0);
  for (long i = 0; i < fixed; ++i) keep_node[i] = 1;
  for (const auto& e : constrained) pinned[e[0]] = pinned[e[1]] = 1;
  std::vector<char> dead(nt, 0);
  auto collapse_sweep = [&]() {
    long done = 0;
    Stars star;
    star.build(T, nt, n, dead);
    std::vector<char> busy(n, 0);
    std::vector<int> na, nb, region, live;
    std::vector<Eigen::RowVector3i> saved;
    auto try_collapse = [&](int a, int b) {
      // b goes: a node that may move and is not an apex's neighbour if there is one; an apex's
      // neighbour may go too (its locked edges pass to a), unless the edge ab itself is locked
      if (keep_node[b] || (pinned[b] && !pinned[a] && !keep_node[a])) std::swap(a, b);
      if (keep_node[b] || busy[a] || busy[b] || a == b) return false;
      if (pinned[b] && locked.count(ekey(a, b))) return false;
      // link condition: a and b share exactly the two apexes of the edge's triangles
      neighbours(T, star, a, na), neighbours(T, star, b, nb);
      if (!std::binary_search(na.begin(), na.end(), b)) return false;
      int common = 0;
      for (int v : na) common += std::binary_search(nb.begin(), nb.end(), v);
      int shared = 0;
      for (int t : star[b]) shared += (T(t, 0) == a || T(t, 1) == a || T(t, 2) == a);
      if (common != 2 || shared != 2) return false;
      region.assign(star[a].begin(), star[a].end());
      region.insert(region.end(), star[b].begin(), star[b].end());
      std::sort(region.begin(), region.end());
      region.erase(std::unique(region.begin(), region.end()), region.end());
      double before = 180;
      for (int t : region) before = std::min(before, min_angle(X, T(t, 0), T(t, 1), T(t, 2)));
      const NodeState old_a = save(a);
      const Eigen::RowVector2d pa = old_a.p, pb = P.row(b);
      // apply: the edge's two triangles go, b's others now use a
      saved.clear(), live.clear();
      for (int t : region) {
        saved.push_back(T.row(t));
        bool has_a = false, has_b = false;
        for (int j = 0; j < 3; ++j) has_a |= T(t, j) == a, has_b |= T(t, j) == b;
        if (has_a && has_b) {
          dead[t] = 1;
          continue;
        }
        for (int j = 0; j < 3; ++j)
          if (T(t, j) == b) T(t, j) = a;
        live.push_back(t);
      }
      auto region_min = [&]() {
        double w = 180;
        for (int t : live) {
          if (!ccw(P, T(t, 0), T(t, 1), T(t, 2)) || !faces_out(X, N, T(t, 0), T(t, 1), T(t, 2))) return -1.0;
          w = std::min(w, min_angle(X, T(t, 0), T(t, 1), T(t, 2)));
        }
        return w;
      };
      // where a stays: in place, or if it may move, the best of the middle and b's place,
      // then refined by a compass search
      double after = region_min();
      if (!keep_node[a]) {
        Eigen::RowVector2d best_p = pa;
        for (const Eigen::RowVector2d& q : {Eigen::RowVector2d(0.5 * (pa + pb)), pb}) {
          P.row(a) = q;
          evaluate(a);
          const double w = region_min();
          if (w > after) after = w, best_p = q;
        }
        P.row(a) = best_p;
        evaluate(a);
        if (after > 0) {
          bool moved = false;
          after = compass_node(a, live.data(), live.data() + live.size(), moved);
        }
      }
      // a clear gain: 1° (or a quarter of the angle where it is tiny: a node of a sliver face's
      // corner fan, 0.86° -> 1.73°)
      if (after <= before + std::min(1.0, 0.25 * before)) {
        for (size_t k = 0; k < region.size(); ++k) T.row(region[k]) = saved[k], dead[region[k]] = 0;
        restore(a, old_a);
        return false;
      }
      if (pinned[b]) {
        for (int v : nb)
          if (locked.count(ekey(b, v))) locked.insert(ekey(a, v));
        pinned[a] = 1;
      }
      busy[a] = busy[b] = 1;
      for (int v : na) busy[v] = 1;
      for (int v : nb) busy[v] = 1;
      ++done;
      return true;
    };
    std::vector<int> around;
    for (int t0 = 0; t0 < nt; ++t0) {
      if (dead[t0]) continue;
      double l[3];
      for (int k = 0; k < 3; ++k) l[k] = (X.row(T(t0, k)) - X.row(T(t0, (k + 1) % 3))).norm();
      int order[3] = {0, 1, 2};
      std::sort(order, order + 3, [&](int p, int q) { return l[p] < l[q]; });
      const int k = order[0];
      // the triangle's shortest edge, if clearly shorter than the other two
      if (l[k] <= 0.7 * std::min(l[(k + 1) % 3], l[(k + 2) % 3]) && try_collapse(T(t0, k), T(t0, (k + 1) % 3)))
        continue;
      if (min_angle(X, T(t0, 0), T(t0, 1), T(t0, 2)) >= kBadAngle) continue;
      bool gone = false;
      for (int e = 0; e < 3 && !gone; ++e) gone = try_collapse(T(t0, order[e]), T(t0, (order[e] + 1) % 3));
      for (int c = 0; c < 3 && !gone; ++c) {
        const int b = T(t0, c);
        if (keep_node[b] || busy[b]) continue;
        neighbours(T, star, b, around);
        std::sort(around.begin(), around.end(), [&](int p, int q) {
          return (X.row(p) - X.row(b)).squaredNorm() < (X.row(q) - X.row(b)).squaredNorm();
        });
        for (int a : around)
          if ((gone = try_collapse(a, b))) break;
      }
    }
    // drop the removed triangles
    if (done) {
      long w = 0;
      for (long t = 0; t < nt; ++t)
        if (!dead[t]) T.row(w++) = T.row(t);
      T.conservativeResize(w, 3);
      nt = w;
      dead.assign(nt, 0);
    }
    return done;
  };

  // The nodes of the triangles still worst (smallest angle below 40°): a compass search in
  // the parameters for the position that maximises the smallest angle of the node's star on
  // the surface (the centroid rule cannot lift a triangle that leans on a boundary segment)
  auto compass_sweep = [&]() {
    long moves = 0;
    Stars star;
    star.build(T, nt, n, {});
    for (long t = 0; t < nt; ++t) {
      if (min_angle(X, T(t, 0), T(t, 1), T(t, 2)) >= 40) continue;
      for (int k = 0; k < 3; ++k) {
        const int i = T(t, k);
        if (i < fixed || keep_node[i]) continue;
        bool any = false;
        compass_node(i, star[i].begin(), star[i].end(), any);
        moves += any;
      }
    }
    return moves;
  };

  for (int r = 0; r < rounds; ++r) {
    st.flips += flip_sweep();
    st.collapses += collapse_sweep();
    st.moves += smooth_sweep();
  }
  st.flips += flip_sweep();
  // A triangle whose three corners may not move (a corner of the face closed by one triangle
  // between two boundary segments of unequal length, e.g. 1 and 1.25: 39°) gets its longest
  // edge split when that edge is inside the face: a new node at its middle, placed by the
  // compass search, kept when the smallest angle of the four triangles rises.
  auto split_sweep = [&]() {
    std::vector<int> cand;
    for (int t = 0; t < nt; ++t)
      if (keep_node[T(t, 0)] && keep_node[T(t, 1)] && keep_node[T(t, 2)] &&
          min_angle(X, T(t, 0), T(t, 1), T(t, 2)) < 40)
        cand.push_back(t);
    if (cand.empty()) return 0L;
    std::unordered_map<uint64_t, std::array<int, 2>> edge_tris;
    edge_tris.reserve(3 * nt);
    for (int t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) {
        auto [it, fresh] = edge_tris.try_emplace(ekey(T(t, k), T(t, (k + 1) % 3)), std::array<int, 2>{t, -1});
        if (!fresh) it->second[1] = t;
      }
    // room for every candidate's node and two triangles, trimmed afterwards
    const long extra = static_cast<long>(cand.size());
    P.conservativeResize(n + extra, 2), X.conservativeResize(n + extra, 3), N.conservativeResize(n + extra, 3);
    Xu.resize(n + extra), Xv.resize(n + extra), keep_node.resize(n + extra, 0), pinned.resize(n + extra, 0);
    T.conservativeResize(nt + 2 * extra, 3);
    std::vector<char> touched(nt, 0);
    long done = 0;
    for (int t0 : cand) {
      if (touched[t0]) continue;
      double l[3];
      for (int k = 0; k < 3; ++k) l[k] = (X.row(T(t0, k)) - X.row(T(t0, (k + 1) % 3))).norm();
      const int k = l[0] >= l[1] && l[0] >= l[2] ? 0 : (l[1] >= l[2] ? 1 : 2);
      const int a = T(t0, k), b = T(t0, (k + 1) % 3), c = T(t0, (k + 2) % 3);
      if (locked.count(ekey(a, b))) continue;
      const auto it = edge_tris.find(ekey(a, b));
      if (it == edge_tris.end()) continue;
      const int t1 = it->second[0] == t0 ? it->second[1] : it->second[0];
      if (t1 < 0 || touched[t1]) continue;
      int d = -1, holds = 0;
      for (int j = 0; j < 3; ++j) {
        const int v = T(t1, j);
        if (v == a || v == b)
          ++holds;
        else
          d = v;
      }
      if (holds != 2 || d < 0) continue;
      const double before = std::min(min_angle(X, a, b, c), min_angle(X, b, a, d));
      const int bad_before = (min_angle(X, a, b, c) < 20) + (min_angle(X, b, a, d) < 20);
      const int m = static_cast<int>(n);
      P.row(m) = 0.5 * (P.row(a) + P.row(b));
      evaluate(m);
      const Eigen::RowVector3i r0 = T.row(t0), r1 = T.row(t1);
      const int star[4] = {t0, t1, static_cast<int>(nt), static_cast<int>(nt) + 1};
      T.row(t0) << a, m, c;
      T.row(nt) << m, b, c;
      T.row(t1) << b, m, d;
      T.row(nt + 1) << m, a, d;
      bool moved = false;
      const double after = compass_node(m, star, star + 4, moved);
      // and no more triangles below 20° than before (two of 19.9° for one of 12° is no gain
      // for the share of bad triangles)
      int bad_after = 0;
      for (int q : star) bad_after += min_angle(X, T(q, 0), T(q, 1), T(q, 2)) < 20;
      if (after <= before + 0.5 || bad_after > bad_before) {
        T.row(t0) = r0, T.row(t1) = r1;
        continue;
      }
      touched[t0] = touched[t1] = 1;
      ++n, nt += 2, ++done;
    }
    P.conservativeResize(n, 2), X.conservativeResize(n, 3), N.conservativeResize(n, 3);
    Xu.resize(n), Xv.resize(n), keep_node.resize(n), pinned.resize(n);
    T.conservativeResize(nt, 3);
    dead.assign(nt, 0);
    return done;
  };

  for (int r = 0; r < std::min(rounds, 2); ++r) {
    st.moves += compass_sweep();
    st.flips += flip_sweep();
    st.collapses += collapse_sweep();
  }
  if (rounds > 0) {
    st.splits += split_sweep();
    st.flips += flip_sweep();
  }
  st.min_angle_after = 180;
  for (long t = 0; t < nt; ++t)
    st.min_angle_after = std::min(st.min_angle_after, min_angle(X, T(t, 0), T(t, 1), T(t, 2)));
  return st;
}

}  // namespace topopt::mesh
