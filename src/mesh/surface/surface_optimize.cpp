// Flips, collapses, smoothing and splits of a face's triangles judged on the surface (see
// surface_optimize.h).
#include "mesh/surface/surface_optimize.h"

#include <algorithm>
#include <cmath>

#include "mesh/core/predicates.h"
#include "mesh/surface/triangle_stars.h"

namespace topopt::mesh {
namespace {

/// Below this smallest angle (degrees) a triangle's edges and corners are tried for collapses.
constexpr double kBadAngle = 20;

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

/// The nodes sharing a triangle with v (sorted, once each).
void neighbours(const MatX3i& T, const TriangleStars& star, int v, std::vector<int>& out) {
  out.clear();
  for (const int* t = star.begin(v); t != star.end(v); ++t)
    for (int j = 0; j < 3; ++j)
      if (T(*t, j) != v) out.push_back(T(*t, j));
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

}  // namespace

// ------------------------------------------------------------------ state of the surface

SurfaceOptimizer::SurfaceOptimizer(MatX2d& P, MatX3i& T, MatX3d& X, int fixed, const SurfaceEval& eval,
                                   const std::vector<std::array<int, 2>>& constrained)
    : P_(P), T_(T), X_(X), eval_(eval), fixed_(fixed), n_(P.rows()), nt_(T.rows()) {
  X_.resize(n_, 3);
  N_.resize(n_, 3);
  Xu_.resize(n_), Xv_.resize(n_);
  for (long i = 0; i < n_; ++i) evaluate(i);
  for (const auto& e : constrained) locked_.insert(ekey(e[0], e[1]));
  // the ends of constrained edges (the apex's neighbours on a cone) may move, and go only onto
  // a neighbour that takes their locked edges
  keep_node_.assign(n_, 0), pinned_.assign(n_, 0);
  for (long i = 0; i < fixed_; ++i) keep_node_[i] = 1;
  for (const auto& e : constrained) pinned_[e[0]] = pinned_[e[1]] = 1;
  dead_.assign(nt_, 0);
}

inline void SurfaceOptimizer::evaluate(long i) {
  double x[3], du[3], dv[3];
  eval_(P_.row(i).data(), x, du, dv);
  X_.row(i) << x[0], x[1], x[2];
  Xu_[i] = Eigen::Vector3d(du[0], du[1], du[2]);
  Xv_[i] = Eigen::Vector3d(dv[0], dv[1], dv[2]);
  const Eigen::Vector3d nn = Xu_[i].cross(Xv_[i]);
  N_.row(i) = nn.norm() > 0 ? Eigen::RowVector3d(nn.normalized()) : Eigen::RowVector3d::Zero();
}

inline SurfaceOptimizer::NodeState SurfaceOptimizer::save(long i) const {
  return NodeState{P_.row(i), X_.row(i), N_.row(i), Xu_[i], Xv_[i]};
}

inline void SurfaceOptimizer::restore(long i, const NodeState& s) {
  P_.row(i) = s.p, X_.row(i) = s.x, N_.row(i) = s.n, Xu_[i] = s.u, Xv_[i] = s.v;
}

inline double SurfaceOptimizer::triangle_angle(long t) const { return min_angle(X_, T_(t, 0), T_(t, 1), T_(t, 2)); }

// The smallest angle of the triangles [begin, end) on the surface; -1 if one is not
// counter-clockwise in the parameters or does not face out.
inline double SurfaceOptimizer::worst_of(const int* begin, const int* end) const {
  double w = 180;
  for (const int* q = begin; q != end; ++q) {
    if (!ccw(P_, T_(*q, 0), T_(*q, 1), T_(*q, 2)) || !faces_out(X_, N_, T_(*q, 0), T_(*q, 1), T_(*q, 2))) return -1.0;
    w = std::min(w, triangle_angle(*q));
  }
  return w;
}

double SurfaceOptimizer::smallest_angle() const {
  double m = 180;
  for (long t = 0; t < nt_; ++t) m = std::min(m, triangle_angle(t));
  return m;
}

// Undirected edge -> (t0, t1), the triangles on either side (-1: none).
SurfaceOptimizer::EdgeTriangles SurfaceOptimizer::edge_triangles() const {
  EdgeTriangles edge_tris;
  edge_tris.reserve(3 * nt_);
  for (int t = 0; t < nt_; ++t)
    for (int k = 0; k < 3; ++k) {
      auto [it, fresh] = edge_tris.try_emplace(ekey(T_(t, k), T_(t, (k + 1) % 3)), std::array<int, 2>{t, -1});
      if (!fresh) it->second[1] = t;
    }
  return edge_tris;
}

// ------------------------------------------------------------------ flips

long SurfaceOptimizer::flip_edges() {
  long flips = 0;
  for (int sweep = 0; sweep < 6; ++sweep) {
    const EdgeTriangles edge_tris = edge_triangles();
    std::vector<char> touched(nt_, 0);
    long here = 0;
    for (const auto& [key, tt] : edge_tris) {
      const int t0 = tt[0], t1 = tt[1];
      if (t1 < 0 || touched[t0] || touched[t1] || locked_.count(key)) continue;
      if (!try_flip(key, t0, t1)) continue;
      touched[t0] = touched[t1] = 1;
      ++here;
    }
    flips += here;
    if (!here) break;
  }
  return flips;
}

// Flips the edge `key` shared by t0 and t1 when the new pair is valid and better.
bool SurfaceOptimizer::try_flip(uint64_t key, int t0, int t1) {
  // t0 = (a, b, c) with the edge a->b, t1 holds b->a and d
  int k0 = 0;
  while (ekey(T_(t0, k0), T_(t0, (k0 + 1) % 3)) != key) ++k0;
  const int a = T_(t0, k0), b = T_(t0, (k0 + 1) % 3), c = T_(t0, (k0 + 2) % 3);
  int d = -1;
  for (int k = 0; k < 3; ++k)
    if (T_(t1, k) != a && T_(t1, k) != b) d = T_(t1, k);
  if (d < 0 || d == c || locked_.count(ekey(c, d))) return false;
  // new pair (c, a, d) and (d, b, c): valid in the parameters, better on the surface
  if (!ccw(P_, c, a, d) || !ccw(P_, d, b, c)) return false;
  const double before = std::min(min_angle(X_, a, b, c), min_angle(X_, b, a, d));
  const double after = std::min(min_angle(X_, c, a, d), min_angle(X_, d, b, c));
  if (after <= before + 0.5) return false;
  if (!faces_out(X_, N_, c, a, d) || !faces_out(X_, N_, d, b, c)) return false;
  T_.row(t0) << c, a, d;
  T_.row(t1) << d, b, c;
  return true;
}

// ------------------------------------------------------------------ smoothing, compass search

long SurfaceOptimizer::smooth_nodes() {
  long moves = 0;
  const TriangleStars star = triangle_stars(T_, nt_, n_);
  std::vector<int> nbr;
  for (long i = fixed_; i < n_; ++i)
    if (star.size(static_cast<int>(i)) > 0) moves += smooth_node(i, star, nbr);
  return moves;
}

// Node i towards the centre of its neighbours, kept at the first of the steps 1, 1/2, 1/4
// where its star stays valid and gets better.
bool SurfaceOptimizer::smooth_node(long i, const TriangleStars& star, std::vector<int>& nbr) {
  const int* s0 = star.begin(static_cast<int>(i));
  const int* s1 = star.end(static_cast<int>(i));
  neighbours(T_, star, static_cast<int>(i), nbr);
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  for (int j : nbr) target += Eigen::Vector3d(X_.row(j));
  target /= static_cast<double>(nbr.size());
  // one Gauss-Newton step back onto the surface: [Xu Xv] d = target - X
  Eigen::Matrix<double, 3, 2> J;
  J << Xu_[i], Xv_[i];
  const Eigen::Matrix2d JtJ = J.transpose() * J;
  if (std::abs(JtJ.determinant()) < 1e-300) return false;
  const Eigen::Vector2d dlt = JtJ.ldlt().solve(J.transpose() * (target - Eigen::Vector3d(X_.row(i))));
  double old_min = 180, old_sum = 0;
  for (const int* t = s0; t != s1; ++t) {
    const double m = triangle_angle(*t);
    old_min = std::min(old_min, m), old_sum += m;
  }
  const NodeState old = save(i);
  for (double step : {1.0, 0.5, 0.25}) {
    P_.row(i) = old.p + step * dlt.transpose();
    bool valid = true;
    for (const int* t = s0; t != s1; ++t) valid &= ccw(P_, T_(*t, 0), T_(*t, 1), T_(*t, 2));
    if (!valid) continue;
    evaluate(i);
    double new_min = 180, new_sum = 0;
    for (const int* t = s0; t != s1; ++t) {
      const double m = triangle_angle(*t);
      new_min = std::min(new_min, m), new_sum += m;
      valid &= faces_out(X_, N_, T_(*t, 0), T_(*t, 1), T_(*t, 2));
    }
    // the star's smallest angle rises, or its angles improve on the whole without the
    // smallest dropping below min(before, 30°)
    const bool better = new_min > old_min || (new_sum > old_sum && new_min >= std::min(old_min, 30.0));
    if (valid && better) return true;
  }
  restore(i, old);
  return false;
}

// Compass search in the parameters for the position of node i that maximises the smallest
// angle of its triangles [begin, end) on the surface (every one valid in the parameters and
// facing out); returns that angle (-1 if the star is invalid where it starts) and whether i moved.
double SurfaceOptimizer::compass_node(int i, const int* begin, const int* end, bool& moved) {
  moved = false;
  double len = 0;
  int cnt = 0;
  for (const int* q = begin; q != end; ++q)
    for (int j = 0; j < 3; ++j)
      if (T_(*q, j) != i) len += (P_.row(T_(*q, j)) - P_.row(i)).norm(), ++cnt;
  double best = worst_of(begin, end);
  if (!cnt || best < 0) return best;
  double step = 0.1 * len / cnt;
  for (int it = 0; it < 30 && step > 1e-3 * len / cnt; ++it) {
    bool moved_now = false;
    for (int d = 0; d < 4 && !moved_now; ++d) {
      const NodeState old = save(i);
      P_(i, d / 2) += d % 2 ? -step : step;
      evaluate(i);
      const double now = worst_of(begin, end);
      if (now > best) {
        best = now, moved_now = moved = true;
      } else {
        restore(i, old);
      }
    }
    if (!moved_now) step *= 0.5;
  }
  return best;
}

// The nodes of the triangles still worst (smallest angle below 40°): the centroid rule cannot
// lift a triangle that leans on a boundary segment, the compass search can.
long SurfaceOptimizer::compass_search_nodes() {
  long moves = 0;
  const TriangleStars star = triangle_stars(T_, nt_, n_);
  for (long t = 0; t < nt_; ++t) {
    if (triangle_angle(t) >= 40) continue;
    for (int k = 0; k < 3; ++k) {
      const int i = T_(t, k);
      if (i < fixed_ || keep_node_[i]) continue;
      bool any = false;
      compass_node(i, star.begin(i), star.end(i), any);
      moves += any;
    }
  }
  return moves;
}

// ------------------------------------------------------------------ collapses

long SurfaceOptimizer::collapse_edges() {
  const TriangleStars star = triangle_stars(T_, nt_, n_, dead_);
  busy_.assign(n_, 0);
  std::vector<int> around;
  long done = 0;
  for (int t0 = 0; t0 < nt_; ++t0)
    if (!dead_[t0]) done += collapse_around(t0, star, around);
  if (done) drop_dead_triangles();
  return done;
}

// Tries the collapses triangle t0 calls for: its shortest edge if clearly shorter than the
// other two (the front sometimes leaves an edge much shorter than its neighbours where fronts
// meet); below kBadAngle each of its edges, then each movable corner onto each of its
// neighbours, nearest first (a node squeezed against a boundary segment makes a flat cap that
// no move or flip can open). Stops at the first kept.
bool SurfaceOptimizer::collapse_around(int t0, const TriangleStars& star, std::vector<int>& around) {
  double l[3];
  for (int k = 0; k < 3; ++k) l[k] = (X_.row(T_(t0, k)) - X_.row(T_(t0, (k + 1) % 3))).norm();
  int order[3] = {0, 1, 2};
  std::sort(order, order + 3, [&](int p, int q) { return l[p] < l[q]; });
  const int k = order[0];
  if (l[k] <= 0.7 * std::min(l[(k + 1) % 3], l[(k + 2) % 3]) && try_collapse(T_(t0, k), T_(t0, (k + 1) % 3), star))
    return true;
  if (triangle_angle(t0) >= kBadAngle) return false;
  for (int e = 0; e < 3; ++e)
    if (try_collapse(T_(t0, order[e]), T_(t0, (order[e] + 1) % 3), star)) return true;
  for (int c = 0; c < 3; ++c) {
    const int b = T_(t0, c);
    if (keep_node_[b] || busy_[b]) continue;
    neighbours(T_, star, b, around);
    std::sort(around.begin(), around.end(), [&](int p, int q) {
      return (X_.row(p) - X_.row(b)).squaredNorm() < (X_.row(q) - X_.row(b)).squaredNorm();
    });
    for (int a : around)
      if (try_collapse(a, b, star)) return true;
  }
  return false;
}

// Collapse of the edge ab: its movable end b goes onto the other end a (or both onto the
// middle when both may move), kept only if every triangle stays valid in the parameters and
// the smallest angle of the region rises by a clear gain: 1° (or a quarter of the angle where
// it is tiny: a node of a sliver face's corner fan, 0.86° -> 1.73°).
bool SurfaceOptimizer::try_collapse(int a, int b, const TriangleStars& star) {
  // b goes: a node that may move and is not an apex's neighbour if there is one; an apex's
  // neighbour may go too (its locked edges pass to a), unless the edge ab itself is locked
  if (keep_node_[b] || (pinned_[b] && !pinned_[a] && !keep_node_[a])) std::swap(a, b);
  if (!collapse_allowed(a, b, star)) return false;
  Collapse& c = collapse_;
  c.region.assign(star.begin(a), star.end(a));
  c.region.insert(c.region.end(), star.begin(b), star.end(b));
  std::sort(c.region.begin(), c.region.end());
  c.region.erase(std::unique(c.region.begin(), c.region.end()), c.region.end());
  double before = 180;
  for (int t : c.region) before = std::min(before, triangle_angle(t));
  const NodeState old_a = save(a);
  const Eigen::RowVector2d pa = old_a.p, pb = P_.row(b);
  // apply: the edge's two triangles go, b's others now use a
  c.saved.clear(), c.live.clear();
  for (int t : c.region) {
    c.saved.push_back(T_.row(t));
    bool has_a = false, has_b = false;
    for (int j = 0; j < 3; ++j) has_a |= T_(t, j) == a, has_b |= T_(t, j) == b;
    if (has_a && has_b) {
      dead_[t] = 1;
      continue;
    }
    for (int j = 0; j < 3; ++j)
      if (T_(t, j) == b) T_(t, j) = a;
    c.live.push_back(t);
  }
  const double after = place_survivor(a, pa, pb);
  if (after <= before + std::min(1.0, 0.25 * before)) {
    undo_collapse(a, old_a);
    return false;
  }
  commit_collapse(a, b);
  return true;
}

// Whether b may go onto a: b may move, neither is busy in this sweep, a locked edge ab keeps
// an apex's neighbour b, and the link condition holds (a and b share exactly the two apexes
// of the edge's triangles). Leaves their neighbours in collapse_.na and .nb.
bool SurfaceOptimizer::collapse_allowed(int a, int b, const TriangleStars& star) {
  if (keep_node_[b] || busy_[a] || busy_[b] || a == b) return false;
  if (pinned_[b] && locked_.count(ekey(a, b))) return false;
  std::vector<int>&na = collapse_.na, &nb = collapse_.nb;
  neighbours(T_, star, a, na), neighbours(T_, star, b, nb);
  if (!std::binary_search(na.begin(), na.end(), b)) return false;
  int common = 0;
  for (int v : na) common += std::binary_search(nb.begin(), nb.end(), v);
  int shared = 0;
  for (const int* t = star.begin(b); t != star.end(b); ++t)
    shared += (T_(*t, 0) == a || T_(*t, 1) == a || T_(*t, 2) == a);
  return common == 2 && shared == 2;
}

// Where the survivor a stays after a collapse: in place, or if it may move, the best of the
// middle and b's place, then refined by a compass search. Returns the smallest angle of the
// triangles left (collapse_.live), -1 if one is invalid.
double SurfaceOptimizer::place_survivor(int a, const Eigen::RowVector2d& pa, const Eigen::RowVector2d& pb) {
  const std::vector<int>& live = collapse_.live;
  double after = worst_of(live.data(), live.data() + live.size());
  if (keep_node_[a]) return after;
  Eigen::RowVector2d best_p = pa;
  for (const Eigen::RowVector2d& q : {Eigen::RowVector2d(0.5 * (pa + pb)), pb}) {
    P_.row(a) = q;
    evaluate(a);
    const double w = worst_of(live.data(), live.data() + live.size());
    if (w > after) after = w, best_p = q;
  }
  P_.row(a) = best_p;
  evaluate(a);
  if (after > 0) {
    bool moved = false;
    after = compass_node(a, live.data(), live.data() + live.size(), moved);
  }
  return after;
}

void SurfaceOptimizer::undo_collapse(int a, const NodeState& old_a) {
  const Collapse& c = collapse_;
  for (size_t k = 0; k < c.region.size(); ++k) T_.row(c.region[k]) = c.saved[k], dead_[c.region[k]] = 0;
  restore(a, old_a);
}

// A kept collapse: a takes b's locked edges, and the nodes around both wait for the next sweep.
void SurfaceOptimizer::commit_collapse(int a, int b) {
  const Collapse& c = collapse_;
  if (pinned_[b]) {
    for (int v : c.nb)
      if (locked_.count(ekey(b, v))) locked_.insert(ekey(a, v));
    pinned_[a] = 1;
  }
  busy_[a] = busy_[b] = 1;
  for (int v : c.na) busy_[v] = 1;
  for (int v : c.nb) busy_[v] = 1;
}

void SurfaceOptimizer::drop_dead_triangles() {
  long w = 0;
  for (long t = 0; t < nt_; ++t)
    if (!dead_[t]) T_.row(w++) = T_.row(t);
  T_.conservativeResize(w, 3);
  nt_ = w;
  dead_.assign(nt_, 0);
}

// ------------------------------------------------------------------ splits

// A triangle whose three corners may not move (a corner of the face closed by one triangle
// between two boundary segments of unequal length, e.g. 1 and 1.25: 39°) gets its longest
// edge split when that edge is inside the face.
long SurfaceOptimizer::split_fixed_triangles() {
  std::vector<int> cand;
  for (int t = 0; t < nt_; ++t)
    if (keep_node_[T_(t, 0)] && keep_node_[T_(t, 1)] && keep_node_[T_(t, 2)] && triangle_angle(t) < 40)
      cand.push_back(t);
  if (cand.empty()) return 0L;
  const EdgeTriangles edge_tris = edge_triangles();
  // room for every candidate's node and two triangles, trimmed afterwards
  const long extra = static_cast<long>(cand.size());
  resize_nodes(n_ + extra);
  T_.conservativeResize(nt_ + 2 * extra, 3);
  std::vector<char> touched(nt_, 0);
  long done = 0;
  for (int t0 : cand)
    if (!touched[t0]) done += try_split(t0, edge_tris, touched);
  resize_nodes(n_);
  T_.conservativeResize(nt_, 3);
  dead_.assign(nt_, 0);
  return done;
}

// Splits t0's longest edge ab and the triangle t1 beyond it at a new node m (the next free
// row), placed by the compass search; undone unless it gains.
bool SurfaceOptimizer::try_split(int t0, const EdgeTriangles& edge_tris, std::vector<char>& touched) {
  double l[3];
  for (int k = 0; k < 3; ++k) l[k] = (X_.row(T_(t0, k)) - X_.row(T_(t0, (k + 1) % 3))).norm();
  const int k = l[0] >= l[1] && l[0] >= l[2] ? 0 : (l[1] >= l[2] ? 1 : 2);
  const int a = T_(t0, k), b = T_(t0, (k + 1) % 3), c = T_(t0, (k + 2) % 3);
  if (locked_.count(ekey(a, b))) return false;
  const auto it = edge_tris.find(ekey(a, b));
  if (it == edge_tris.end()) return false;
  const int t1 = it->second[0] == t0 ? it->second[1] : it->second[0];
  if (t1 < 0 || touched[t1]) return false;
  int d = -1, holds = 0;
  for (int j = 0; j < 3; ++j) {
    const int v = T_(t1, j);
    if (v == a || v == b)
      ++holds;
    else
      d = v;
  }
  if (holds != 2 || d < 0) return false;
  const double before = std::min(min_angle(X_, a, b, c), min_angle(X_, b, a, d));
  const int bad_before = (min_angle(X_, a, b, c) < 20) + (min_angle(X_, b, a, d) < 20);
  const int m = static_cast<int>(n_);
  P_.row(m) = 0.5 * (P_.row(a) + P_.row(b));
  evaluate(m);
  const Eigen::RowVector3i r0 = T_.row(t0), r1 = T_.row(t1);
  const int star[4] = {t0, t1, static_cast<int>(nt_), static_cast<int>(nt_) + 1};
  T_.row(t0) << a, m, c;
  T_.row(nt_) << m, b, c;
  T_.row(t1) << b, m, d;
  T_.row(nt_ + 1) << m, a, d;
  bool moved = false;
  const double after = compass_node(m, star, star + 4, moved);
  // and no more triangles below 20° than before (two of 19.9° for one of 12° is no gain
  // for the share of bad triangles)
  int bad_after = 0;
  for (int q : star) bad_after += triangle_angle(q) < 20;
  if (after <= before + 0.5 || bad_after > bad_before) {
    T_.row(t0) = r0, T_.row(t1) = r1;
    return false;
  }
  touched[t0] = touched[t1] = 1;
  ++n_, nt_ += 2;
  return true;
}

// Every per-node array to `rows` rows (new nodes may move and are not pinned).
void SurfaceOptimizer::resize_nodes(long rows) {
  P_.conservativeResize(rows, 2), X_.conservativeResize(rows, 3), N_.conservativeResize(rows, 3);
  Xu_.resize(rows), Xv_.resize(rows), keep_node_.resize(rows, 0), pinned_.resize(rows, 0);
}

// ------------------------------------------------------------------ the driver

SurfaceOptimizeStats optimize_on_surface(MatX2d& P, MatX3i& T, MatX3d& X, int fixed, const SurfaceEval& eval,
                                         const std::vector<std::array<int, 2>>& constrained, int rounds) {
  SurfaceOptimizer opt(P, T, X, fixed, eval, constrained);
  SurfaceOptimizeStats st;
  st.min_angle_before = opt.smallest_angle();
  for (int r = 0; r < rounds; ++r) {
    st.flips += opt.flip_edges();
    st.collapses += opt.collapse_edges();
    st.moves += opt.smooth_nodes();
  }
  st.flips += opt.flip_edges();
  for (int r = 0; r < std::min(rounds, 2); ++r) {
    st.moves += opt.compass_search_nodes();
    st.flips += opt.flip_edges();
    st.collapses += opt.collapse_edges();
  }
  if (rounds > 0) {
    st.splits += opt.split_fixed_triangles();
    st.flips += opt.flip_edges();
  }
  st.min_angle_after = opt.smallest_angle();
  return st;
}

}  // namespace topopt::mesh
