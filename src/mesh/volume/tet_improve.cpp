// Tet improvement: kernels with a check-only mode and their drivers (see tet_improve.h).
#include "mesh/volume/tet_improve.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <unordered_map>

#include "common/cpu_time.h"
#include "common/face_key.h"
#include "mesh/core/predicates.h"
#include "mesh/core/tet_quality.h"

namespace topopt::mesh {

using Vec3 = Eigen::Vector3d;
using predicates::orient3d;

namespace {

double rho(const std::vector<Vec3>& P, const Tet& t) { return radius_ratio(P[t[0]], P[t[1]], P[t[2]], P[t[3]]); }

bool has(const Tet& t, int x) { return t[0] == x || t[1] == x || t[2] == x || t[3] == x; }

double signed_volume(const std::vector<Vec3>& P, const Tet& t) {
  return (P[t[1]] - P[t[0]]).dot((P[t[2]] - P[t[0]]).cross(P[t[3]] - P[t[0]])) / 6;
}

/// Compass search: moves x along ±x, ±y, ±z by `step` while f (which reads x) rises, halving
/// the step when no direction helps, for at most `iterations` tries or until the step is a
/// hundredth of the first. Returns the best f (and f at the start in `first`); x ends at its
/// best position (bit for bit where it was when nothing helped).
template <class F>
double compass_maximise(Vec3& x, double step, int iterations, F&& f, double* first = nullptr) {
  double best = f();
  if (first) *first = best;
  const double smallest = 1e-2 * step;
  for (int it = 0; it < iterations && step > smallest; ++it) {
    bool moved = false;
    for (int d = 0; d < 6 && !moved; ++d) {
      const Vec3 old = x;
      x[d / 2] += (d % 2 ? -step : step);
      const double now = f();
      if (now > best)
        best = now, moved = true;
      else
        x = old;
    }
    if (!moved) step *= 0.5;
  }
  return best;
}

/// The ring of the edge (u, w) in cyclic order, from the tets around it (each gives the pair
/// of its two other nodes); false when they do not close one ring.
bool ring_in_order(const std::vector<Tet>& tets, const std::vector<int>& ring_tets, int u, int w,
                   std::vector<int>& ring, TetSweep::Scratch& scratch) {
  const int k = static_cast<int>(ring_tets.size());
  std::vector<std::array<int, 2>>& pairs = scratch.pairs;
  pairs.clear();
  for (int r : ring_tets) {
    std::array<int, 2> pr{-1, -1};
    int m = 0;
    for (int x : tets[r])
      if (x != u && x != w) pr[m++] = x;
    pairs.push_back(pr);
  }
  ring.assign({pairs[0][0], pairs[0][1]});
  std::vector<char>& used = scratch.used;
  used.assign(k, 0);
  used[0] = 1;
  bool closed = true;
  for (int step = 1; step < k && closed; ++step) {
    closed = false;
    for (int q = 0; q < k; ++q) {
      if (used[q]) continue;
      const int nxt = pairs[q][0] == ring.back() ? pairs[q][1] : (pairs[q][1] == ring.back() ? pairs[q][0] : -1);
      if (nxt < 0) continue;
      used[q] = 1, closed = true;
      if (step < k - 1)
        ring.push_back(nxt);
      else
        closed = nxt == ring.front();
      break;
    }
  }
  return closed && static_cast<int>(ring.size()) == k;
}

/// The fan triangulation of the ring (oriented so that (u, w, r_i, r_i+1) are positive)
/// joined to u and w with the best worst radius ratio above `floor`, from the first ring node
/// that gives it; empty when none is valid and better.
std::vector<Tet> best_fan(const std::vector<Vec3>& P, int u, int w, const std::vector<int>& ring, double floor,
                          double& best_q, std::vector<Tet>& cand) {
  const int k = static_cast<int>(ring.size());
  std::vector<Tet> best;
  best_q = floor;
  for (int apex = 0; apex < k; ++apex) {
    cand.clear();
    double worst = 1;
    bool ok = true;
    for (int m = 1; m + 1 < k && ok; ++m) {
      const int x = ring[apex], y = ring[(apex + m) % k], z = ring[(apex + m + 1) % k];
      // (x, y, z) runs around the edge like the ring: w above it, u below
      const Tet up{x, y, z, w}, down{x, z, y, u};
      ok = orient3d(P[x].data(), P[y].data(), P[z].data(), P[w].data()) > 0 &&
           orient3d(P[x].data(), P[z].data(), P[y].data(), P[u].data()) > 0;
      if (ok) {
        worst = std::min({worst, rho(P, up), rho(P, down)});
        cand.push_back(up), cand.push_back(down);
      }
    }
    if (ok && worst > best_q) best_q = worst, best = cand;
  }
  return best;
}

/// Orients t positively (swapping its last two nodes when negative); false when it is flat.
bool make_positive(const std::vector<Vec3>& P, Tet& t) {
  const int o = orient3d(P[t[0]].data(), P[t[1]].data(), P[t[2]].data(), P[t[3]].data());
  if (o == 0) return false;
  if (o < 0) std::swap(t[2], t[3]);
  return true;
}

/// The worst radius ratio of the tets `ts`, or -1 when one of them is not positive.
double worst_positive(const std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency::Row& ts) {
  double w = 1;
  for (int q : ts) {
    const Tet& x = tets[q];
    if (orient3d(P[x[0]].data(), P[x[1]].data(), P[x[2]].data(), P[x[3]].data()) <= 0) return -1.0;
    w = std::min(w, rho(P, x));
  }
  return w;
}

}  // namespace

TetSweep::TetSweep(std::vector<Vec3>& P_, std::vector<Tet>& tets_)
    : P(P_), tets(tets_), stars(node_stars(P_.size(), tets_)), touched(tets_.size(), 0), locked(P_.size(), 0) {}

void TetSweep::tets_with(int u, int w, int x, std::vector<int>& out) const {
  out.clear();
  for (int t : stars.row(u))
    if (has(tets[t], w) && (x < 0 || has(tets[t], x))) out.push_back(t);
}

void TetSweep::end() {
  size_t kept = 0;
  for (size_t t = 0; t < tets.size(); ++t)
    if (tets[t][0] >= 0 && !(t < retired.size() && retired[t])) tets[kept++] = tets[t];
  tets.resize(kept);
  tets.insert(tets.end(), pending.begin(), pending.end());
  pending.clear();
}

namespace {

/// The best triangulation of the ring (oriented as in best_fan) over all its triangulations,
/// by dynamic programming over its sub-polygons (Klincsek's; Shewchuk's edge removal): each
/// triangle (r_i, r_j, r_l), i < j < l, makes the tets (r_i, r_j, r_l, w) and (r_i, r_l, r_j, u),
/// and a triangulation scores the worst radius ratio of its tets. Returns those tets when the
/// score is valid (every tet positive) and above `floor` (best_q: the score), else empty.
std::vector<Tet> best_triangulation(const std::vector<Vec3>& P, int u, int w, const std::vector<int>& ring, double floor,
                                    double& best_q) {
  const int k = static_cast<int>(ring.size());
  // Q[i][l]: the best worst tet over the sub-polygon r_i..r_l (1 for an edge: no tet), -1 when
  // none is valid; J[i][l]: the apex that gives it
  std::vector<double> Q(k * k, 1.0);
  std::vector<int> J(k * k, -1);
  auto triangle = [&](int i, int j, int l) {
    const int x = ring[i], y = ring[j], z = ring[l];
    if (orient3d(P[x].data(), P[y].data(), P[z].data(), P[w].data()) <= 0 ||
        orient3d(P[x].data(), P[z].data(), P[y].data(), P[u].data()) <= 0)
      return -1.0;
    return std::min(radius_ratio(P[x], P[y], P[z], P[w]), radius_ratio(P[x], P[z], P[y], P[u]));
  };
  for (int gap = 2; gap < k; ++gap)
    for (int i = 0; i + gap < k; ++i) {
      const int l = i + gap;
      double& q = Q[i * k + l];
      q = -1;
      for (int j = i + 1; j < l; ++j) {
        const double sub = std::min(Q[i * k + j], Q[j * k + l]);
        if (sub <= q) continue;
        const double here = std::min(sub, triangle(i, j, l));
        if (here > q) q = here, J[i * k + l] = j;
      }
    }
  best_q = Q[k - 1];
  std::vector<Tet> out;
  if (!(best_q > floor)) return out;
  std::vector<std::array<int, 2>> todo{{0, k - 1}};
  while (!todo.empty()) {
    const auto [i, l] = todo.back();
    todo.pop_back();
    if (l - i < 2) continue;
    const int j = J[i * k + l];
    out.push_back({ring[i], ring[j], ring[l], w});
    out.push_back({ring[i], ring[l], ring[j], u});
    todo.push_back({i, j}), todo.push_back({j, l});
  }
  return out;
}

}  // namespace

TetReplacement plan_remove_edge(const TetSweep& s, int u, int w, bool optimal) {
  TetReplacement r;
  std::vector<int>& ring_tets = s.scratch.tets;
  std::vector<int>& ring = s.scratch.ring;
  s.tets_with(u, w, -1, ring_tets);
  const int k = static_cast<int>(ring_tets.size());
  if (k < 3 || k > (optimal ? kOptimalRing : 7)) return r;
  for (int rt : ring_tets)
    if (s.touched[rt]) return r;
  if (!ring_in_order(s.tets, ring_tets, u, w, ring, s.scratch)) return r;
  if (s.locked[u] || s.locked[w]) return r;
  for (int x : ring)
    if (s.locked[x]) return r;
  if (orient3d(s.P[u].data(), s.P[w].data(), s.P[ring[0]].data(), s.P[ring[1]].data()) < 0)
    std::reverse(ring.begin(), ring.end());
  double before = 1;
  for (int rt : ring_tets) before = std::min(before, rho(s.P, s.tets[rt]));
  double after = before;
  r.new_tets = optimal ? best_triangulation(s.P, u, w, ring, before, after)
                       : best_fan(s.P, u, w, ring, before, after, s.scratch.fan);
  if (r.empty()) return r;
  r.old_tets = ring_tets;
  r.before = before, r.after = after;
  return r;
}

TetReplacement plan_flip23(const TetSweep& s, int t, int face) {
  TetReplacement r;
  const std::vector<Vec3>& P = s.P;
  const Tet& v = s.tets[t];
  const int a = v[kTetFace[face][0]], b = v[kTetFace[face][1]], c = v[kTetFace[face][2]], d = v[face];
  std::vector<int>& around = s.scratch.other;
  s.tets_with(a, b, c, around);
  if (s.touched[t] || around.size() != 2) return r;
  const int t2 = around[0] == t ? around[1] : around[0];
  if (s.touched[t2]) return r;
  int e = -1;
  for (int x : s.tets[t2])
    if (x != a && x != b && x != c) e = x;
  if (e < 0) return r;
  s.tets_with(d, e, -1, around);
  if (!around.empty()) return r;  // the new edge must not exist yet
  for (int x : {a, b, c, d, e})
    if (s.locked[x]) return r;
  const int s1 = orient3d(P[d].data(), P[e].data(), P[a].data(), P[b].data());
  const int s2 = orient3d(P[d].data(), P[e].data(), P[b].data(), P[c].data());
  const int s3 = orient3d(P[d].data(), P[e].data(), P[c].data(), P[a].data());
  if (s1 == 0 || s1 != s2 || s2 != s3) return r;  // the edge de crosses the face's interior
  if (orient3d(P[a].data(), P[b].data(), P[c].data(), P[d].data()) *
          orient3d(P[a].data(), P[b].data(), P[c].data(), P[e].data()) >=
      0)
    return r;
  Tet n1{a, b, d, e}, n2{b, c, d, e}, n3{c, a, d, e};
  if (!make_positive(P, n1) || !make_positive(P, n2) || !make_positive(P, n3)) return r;
  const double before = std::min(rho(P, v), rho(P, s.tets[t2]));
  const double after = std::min({rho(P, n1), rho(P, n2), rho(P, n3)});
  if (after <= before) return r;
  r.old_tets = {t, t2};
  r.new_tets = {n1, n2, n3};
  r.before = before, r.after = after;
  return r;
}

void apply(TetSweep& s, const TetReplacement& r) {
  for (int rt : r.old_tets)
    for (int x : s.tets[rt]) s.locked[x] = 1;
  for (size_t m = 0; m < r.new_tets.size(); ++m) {
    if (m < r.old_tets.size()) {
      s.tets[r.old_tets[m]] = r.new_tets[m];
    } else {
      s.tets.push_back(r.new_tets[m]);
      s.touched.push_back(1);
    }
  }
  for (size_t m = r.new_tets.size(); m < r.old_tets.size(); ++m) s.tets[r.old_tets[m]] = {-1, -1, -1, -1};
  for (int rt : r.old_tets) s.touched[rt] = 1;
}

NodeMove plan_smooth_node(std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency& stars, int v) {
  const Adjacency::Row ts = stars.row(v);
  Vec3 sum = Vec3::Zero();
  int n = 0;
  double worst = 1;
  for (int t : ts) {
    worst = std::min(worst, rho(P, tets[t]));
    for (int w : tets[t])
      if (w != v) sum += P[w], ++n;
  }
  if (!n) return {};
  const Vec3 old = P[v];
  P[v] = sum / n;
  const double now = worst_positive(P, tets, ts);
  NodeMove m{v, old, P[v], worst, now};
  P[v] = old;
  if (now < 0 || now < worst) return {};
  return m;
}

NodeMove plan_search_node(std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency& stars, int v) {
  const Adjacency::Row ts = stars.row(v);
  double len = 0;
  int cnt = 0;
  for (int q : ts)
    for (int x : tets[q])
      if (x != v) len += (P[x] - P[v]).norm(), ++cnt;
  if (!cnt) return {};
  const Vec3 old = P[v];
  double before = 0;
  const double after = compass_maximise(
      P[v], 0.1 * len / cnt, 40, [&]() { return worst_positive(P, tets, ts); }, &before);
  NodeMove m{v, old, P[v], before, after};
  P[v] = old;
  if (!(after > before)) return {};
  return m;
}

std::vector<Vec3> sphere_directions(int n) {
  std::vector<Vec3> d(static_cast<size_t>(std::max(n, 0)));
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1.0 - z * z);
    d[i] = Vec3(r * std::cos(golden * i), r * std::sin(golden * i), z);
  }
  return d;
}

namespace {

/// v's mean edge to the other nodes of its tets (0 when it has none).
double mean_edge_at(const std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency::Row& ts, int v) {
  double len = 0;
  int cnt = 0;
  for (int q : ts)
    for (int x : tets[q])
      if (x != v) len += (P[x] - P[v]).norm(), ++cnt;
  return cnt ? len / cnt : 0.0;
}

/// The worst radius ratio of the tets `ts` (-1 when one of them is not positive) and, in
/// `below`, how many of them are below `floor` (counted up to the first that is not positive).
double worst_and_below(const std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency::Row& ts,
                       double floor, int& below) {
  double w = 1;
  below = 0;
  for (int q : ts) {
    const Tet& x = tets[q];
    if (orient3d(P[x[0]].data(), P[x[1]].data(), P[x[2]].data(), P[x[3]].data()) <= 0) return -1.0;
    const double r = rho(P, x);
    w = std::min(w, r);
    below += r < floor;
  }
  return w;
}

}  // namespace

NodeMove plan_pattern_search(std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency::Row& ball, int v,
                             const PatternSearchParams& params) {
  double step = 0.25 * mean_edge_at(P, tets, ball, v);
  if (!(step > 0)) return {};
  const bool counted = params.floor > 0;
  int below0 = 0, below = 0;
  const double before = worst_and_below(P, tets, ball, params.floor, below0);
  if (counted && before < 0) return {};  // the count below the floor means nothing on a ball not all positive
  const Vec3 old = P[v];
  double best = before;
  for (int it = 0; it < params.tries; ++it) {
    const Vec3 here = P[v];
    Vec3 to = here;
    for (const Vec3& d : params.directions) {
      P[v] = here + step * d;
      if (params.onto && !params.onto(P[v])) continue;
      const double now = worst_and_below(P, tets, ball, params.floor, below);
      if (now > best && (!counted || below <= below0)) best = now, to = P[v];
    }
    P[v] = to;
    if (to == here) step *= 0.5;
  }
  NodeMove m{v, old, P[v], before, best};
  P[v] = old;
  if (!(best > before)) return {};
  return m;
}

NodeMove plan_perturb_node(std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency& stars, int v) {
  PatternSearchParams params;
  params.directions = sphere_directions(kPerturbDirections);
  params.tries = 12;
  return plan_pattern_search(P, tets, stars.row(v), v, params);
}

namespace {

/// The gradient of tet q's radius ratio in the position of its node v, by central differences
/// of step h (P[v] is as it was on return).
Vec3 radius_ratio_gradient(std::vector<Vec3>& P, const Tet& q, int v, double h) {
  Vec3 g;
  const Vec3 at = P[v];
  for (int d = 0; d < 3; ++d) {
    P[v][d] = at[d] + h;
    const double up = rho(P, q);
    P[v][d] = at[d] - h;
    const double down = rho(P, q);
    P[v] = at;
    g[d] = (up - down) / (2 * h);
  }
  return g;
}

/// The ascent directions at v's position: the gradient of each tet of ts within kActiveBand of
/// `worst` (unit), and their sum (unit) when there are several.
std::vector<Vec3> ascent_directions(std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency::Row& ts, int v,
                                    double worst, double h) {
  std::vector<Vec3> dirs;
  Vec3 sum = Vec3::Zero();
  for (int q : ts) {
    if (rho(P, tets[q]) > worst + kActiveBand) continue;
    const Vec3 g = radius_ratio_gradient(P, tets[q], v, h);
    const double n = g.norm();
    if (!(n > 0)) continue;
    dirs.push_back(g / n);
    sum += g / n;
  }
  if (dirs.size() > 1 && sum.norm() > 1e-12) dirs.push_back(sum.normalized());
  return dirs;
}

}  // namespace

NodeMove plan_optimise_node(std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency& stars, int v) {
  const Adjacency::Row ts = stars.row(v);
  const double len = mean_edge_at(P, tets, ts, v);
  if (!(len > 0)) return {};
  const Vec3 old = P[v];
  const double before = worst_positive(P, tets, ts);
  if (before < 0) return {};
  double best = before;
  for (int it = 0; it < 30; ++it) {
    const Vec3 here = P[v];
    Vec3 to = here;
    double gained = best;
    for (const Vec3& d : ascent_directions(P, tets, ts, v, best, 1e-6 * len)) {
      // line search: the first step, halving from len / 5, that raises the worst
      for (double step = 0.2 * len, k = 0; k < 12; step *= 0.5, ++k) {
        P[v] = here + step * d;
        const double now = worst_positive(P, tets, ts);
        if (now > best) {
          if (now > gained) gained = now, to = P[v];
          break;
        }
      }
      P[v] = here;
    }
    if (to == here) break;
    P[v] = to, best = gained;
  }
  NodeMove m{v, old, P[v], before, best};
  P[v] = old;
  if (!(best > before)) return {};
  return m;
}

void apply(std::vector<Vec3>& P, const NodeMove& m) { P[m.v] = m.to; }

namespace {

/// The faces of the cavity's tets that only one of them has, each turned out of its tet.
std::vector<Tri> cavity_faces(const std::vector<Tet>& tets, const std::vector<int>& cavity) {
  std::unordered_map<FaceKey, std::pair<int, Tri>, FaceKeyHash> count;
  for (int c : cavity)
    for (const auto& o : kTetFace) {
      const Tri f{tets[c][o[0]], tets[c][o[1]], tets[c][o[2]]};
      auto [it, fresh] = count.emplace(face_key(f[0], f[1], f[2]), std::make_pair(1, f));
      if (!fresh) ++it->second.first;
    }
  std::vector<Tri> faces;
  for (const auto& [k, cf] : count)
    if (cf.first == 1) faces.push_back(cf.second);
  return faces;
}

}  // namespace

CavityStar plan_refill_cavity(TetSweep& s, std::vector<int> cavity, double bad, const Vec3* start) {
  std::vector<Vec3>& P = s.P;
  std::sort(cavity.begin(), cavity.end());
  double old_worst = 1;
  int old_bad = 0;
  for (int c : cavity) {
    if (s.touched[c]) return {};
    for (int x : s.tets[c])
      if (s.locked[x]) return {};
    const double r = rho(P, s.tets[c]);
    old_worst = std::min(old_worst, r);
    old_bad += r < kSliverShare * bad;
  }
  CavityStar star;
  star.faces = cavity_faces(s.tets, cavity);
  if (star.faces.empty()) return {};
  Vec3 centre = Vec3::Zero();
  double len = 0;
  for (const Tri& f : star.faces) {
    for (int x : f) centre += P[x];
    len += (P[f[0]] - P[f[1]]).norm();
  }
  centre /= 3.0 * static_cast<double>(star.faces.size());
  len /= static_cast<double>(star.faces.size());
  // score of the star from x: its worst radius ratio where x sees every face (each face turns
  // out of the cavity, so a star tet (f, x) is positive when x is inside); elsewhere -1 plus
  // the most negative height of x over a face (in units of the mean edge), which leads the
  // search into the cavity's kernel
  P.push_back(start ? *start : centre);
  const int id = static_cast<int>(P.size()) - 1;
  auto star_score = [&]() {
    double w = 1, hmin = 0;
    bool sees = true;
    for (const Tri& f : star.faces) {
      if (orient3d(P[f[0]].data(), P[f[2]].data(), P[f[1]].data(), P[id].data()) <= 0) {
        const Vec3 n = (P[f[2]] - P[f[0]]).cross(P[f[1]] - P[f[0]]);
        const double nn = n.norm();
        hmin = std::min(hmin, nn > 0 ? n.dot(P[id] - P[f[0]]) / nn : -len);
        sees = false;
      } else if (sees) {
        w = std::min(w, radius_ratio(P[f[0]], P[f[2]], P[f[1]], P[id]));
      }
    }
    return sees ? w : -1 + std::min(hmin, 0.0) / len - 1e-9;
  };
  const double best = compass_maximise(P[id], 0.15 * len, 100, star_score);
  // and no more slivers (below kSliverShare × bad) than the cavity had: lifting the worst
  // alone could leave more than it removed, for the next sweep to find (on NIST 6 the sweeps
  // grew the tets below 0.1 from 5 500 to 9 000)
  int new_bad = 0;
  double star_volume = 0;
  if (best > old_worst)
    for (const Tri& f : star.faces) {
      new_bad += radius_ratio(P[f[0]], P[f[2]], P[f[1]], P[id]) < kSliverShare * bad;
      star_volume += signed_volume(P, {f[0], f[2], f[1], id});
    }
  star.point = P[id];
  P.pop_back();
  if (!(best > old_worst) || new_bad > old_bad) return {};
  // a point that sees every face tiles a cavity of positive tets exactly; one holding a flat or
  // inverted tet has faces that overlap, and its star would cover part of it twice: the star
  // must have the cavity's volume
  double cavity_volume = 0;
  for (int c : cavity) cavity_volume += signed_volume(P, s.tets[c]);
  if (!(std::abs(star_volume - cavity_volume) <= 1e-9 * std::abs(cavity_volume))) return {};
  star.cavity = std::move(cavity);
  star.gain = best - old_worst;
  return star;
}

void apply(TetSweep& s, const CavityStar& c) {
  s.P.push_back(c.point);
  const int id = static_cast<int>(s.P.size()) - 1;
  if (s.retired.size() < s.tets.size()) s.retired.resize(s.tets.size(), 0);
  for (int t : c.cavity) {
    s.retired[t] = s.touched[t] = 1;
    for (int x : s.tets[t]) s.locked[x] = 1;
  }
  for (const Tri& f : c.faces) s.pending.push_back({f[0], f[2], f[1], id});
}

// ---- drivers

namespace {

/// The edge removal or 2-3 flip at tet t: the first that improves (its edges, then its faces),
/// or with `best` the one of them all whose new worst radius ratio is highest. `wide`: edge
/// removal over all triangulations of rings up to kOptimalRing, and multi-face removal (which
/// includes the 2-3 flip) at its faces.
TetReplacement plan_reconnection(const TetSweep& s, int t, bool best, bool wide) {
  const Tet v = s.tets[t];
  TetReplacement r;
  auto consider = [&r, best](TetReplacement c) {
    if (!c.empty() && (r.empty() || (best && c.after > r.after))) r = std::move(c);
  };
  for (int i = 0; i < 4 && (best || r.empty()); ++i)
    for (int j = i + 1; j < 4 && (best || r.empty()); ++j) consider(plan_remove_edge(s, v[i], v[j], wide));
  for (int fi = 0; fi < 4 && (best || r.empty()); ++fi) consider(wide ? plan_remove_faces(s, t, fi) : plan_flip23(s, t, fi));
  return r;
}

}  // namespace

long flip_bad_tets(std::vector<Vec3>& P, std::vector<Tet>& tets, double bad, bool best, bool wide) {
  long flips = 0;
  for (int sweep = 0; sweep < 4; ++sweep) {
    long here = 0;
    TetSweep s(P, tets);
    const size_t n0 = tets.size();
    for (size_t t = 0; t < n0; ++t) {
      if (s.touched[t] || rho(P, tets[t]) >= bad) continue;
      const TetReplacement r = plan_reconnection(s, static_cast<int>(t), best, wide);
      if (r.empty()) continue;
      apply(s, r);
      ++here;
    }
    s.end();
    flips += here;
    if (!here) break;
  }
  return flips;
}

void smooth_nodes(std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency& stars, int first_new,
                  int iterations) {
  for (int it = 0; it < iterations; ++it)
    for (int v = first_new; v < static_cast<int>(P.size()); ++v) {
      const NodeMove m = plan_smooth_node(P, tets, stars, v);
      if (!m.empty()) apply(P, m);
    }
}

void search_nodes_of_bad_tets(std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency& stars, int first_new,
                              double bad) {
  std::vector<char> seen(P.size(), 0);
  for (const Tet& t : tets) {
    if (rho(P, t) >= bad) continue;
    for (int v : t) {
      if (v < first_new || seen[v]) continue;
      seen[v] = 1;
      const NodeMove m = plan_search_node(P, tets, stars, v);
      if (!m.empty()) apply(P, m);
    }
  }
}

namespace {

/// The cavities tried around tet t: the tets around each of its edges, then t with its face
/// neighbours, then with one more layer of them.
std::vector<std::vector<int>> candidate_cavities(const TetSweep& s, int t) {
  std::vector<std::vector<int>> options;
  const Tet v = s.tets[t];
  std::vector<int> ring;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      s.tets_with(v[i], v[j], -1, ring);
      options.push_back(ring);
    }
  std::vector<int> layer{t};
  for (int l = 0; l < 2; ++l) {
    std::vector<int> more;
    for (int c : layer)
      for (const auto& o : kTetFace) {  // the tets across c's faces
        const int a = s.tets[c][o[0]], b = s.tets[c][o[1]], d = s.tets[c][o[2]];
        for (int q : s.stars.row(a))
          if (q != c && has(s.tets[q], b) && has(s.tets[q], d)) more.push_back(q);
      }
    layer.insert(layer.end(), more.begin(), more.end());
    std::sort(layer.begin(), layer.end());
    layer.erase(std::unique(layer.begin(), layer.end()), layer.end());
    options.push_back(layer);
  }
  return options;
}

}  // namespace

namespace {

/// The wider cavities around tet t: the stars of its nodes, the stars of both ends of each of
/// its edges, and t with three layers of face neighbours (each sorted, without repeats).
std::vector<std::vector<int>> wide_cavities(const TetSweep& s, int t) {
  std::vector<std::vector<int>> options;
  const Tet v = s.tets[t];
  auto add = [&options](std::vector<int> c) {
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
    options.push_back(std::move(c));
  };
  for (int i = 0; i < 4; ++i) {
    const Adjacency::Row star = s.stars.row(v[i]);
    add(std::vector<int>(star.begin(), star.end()));
  }
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) {
      std::vector<int> both(s.stars.row(v[i]).begin(), s.stars.row(v[i]).end());
      both.insert(both.end(), s.stars.row(v[j]).begin(), s.stars.row(v[j]).end());
      add(std::move(both));
    }
  std::vector<int> layer{t};
  for (int l = 0; l < 3; ++l) {
    for (int c : std::vector<int>(layer))
      for (const auto& o : kTetFace) {
        const int a = s.tets[c][o[0]], b = s.tets[c][o[1]], d = s.tets[c][o[2]];
        for (int q : s.stars.row(a))
          if (q != c && has(s.tets[q], b) && has(s.tets[q], d)) layer.push_back(q);
      }
    std::sort(layer.begin(), layer.end());
    layer.erase(std::unique(layer.begin(), layer.end()), layer.end());
  }
  add(std::move(layer));
  return options;
}

/// The tets below `floor`, worst first, as (radius ratio, tet).
std::vector<std::pair<double, size_t>> tets_below(const std::vector<Vec3>& P, const std::vector<Tet>& tets,
                                                  double floor) {
  std::vector<std::pair<double, size_t>> order;
  for (size_t t = 0; t < tets.size(); ++t)
    if (tets[t][0] >= 0) {
      const double r = rho(P, tets[t]);
      if (r < floor) order.push_back({r, t});
    }
  std::sort(order.begin(), order.end());
  return order;
}

}  // namespace

namespace {

/// The tet across face `face` (0..3, opposite that node) of tet c by the sweep's stars, or -1
/// when none holds it (a face on the boundary of the tets).
int across(const TetSweep& s, int c, int face) {
  const int a = s.tets[c][kTetFace[face][0]], b = s.tets[c][kTetFace[face][1]], d = s.tets[c][kTetFace[face][2]];
  for (int q : s.stars.row(a))
    if (q != c && has(s.tets[q], b) && has(s.tets[q], d)) return q;
  return -1;
}

/// The replacement of a sandwich (the faces of `ring`'s triangulation, each with a tet to u and
/// one to w: old_tets) by the tets (x, y, u, w) around the new edge uw, one per edge (x, y) of
/// the ring; empty unless they are all positive with one orientation of the ring, fill the old
/// tets' volume (uw crosses the sandwich once) and raise the worst radius ratio.
TetReplacement sandwich_replacement(const std::vector<Vec3>& P, const std::vector<Tet>& tets,
                                    const std::vector<int>& ring, const std::vector<int>& old_tets, int u, int w) {
  TetReplacement r;
  const int k = static_cast<int>(ring.size());
  const int turn = orient3d(P[ring[0]].data(), P[ring[1]].data(), P[u].data(), P[w].data());
  if (turn == 0) return r;
  double before = 1, volume = 0, after = 1;
  for (int q : old_tets) before = std::min(before, rho(P, tets[q])), volume += signed_volume(P, tets[q]);
  std::vector<Tet> fresh;
  double fresh_volume = 0;
  for (int m = 0; m < k; ++m) {
    const int x = ring[m], y = ring[(m + 1) % k];
    if (orient3d(P[x].data(), P[y].data(), P[u].data(), P[w].data()) != turn) return r;
    fresh.push_back(turn > 0 ? Tet{x, y, u, w} : Tet{y, x, u, w});
    after = std::min(after, rho(P, fresh.back()));
    fresh_volume += signed_volume(P, fresh.back());
  }
  if (!(after > before) || !(std::abs(fresh_volume - volume) <= 1e-9 * std::abs(volume))) return r;
  r.old_tets = old_tets, r.new_tets = std::move(fresh), r.before = before, r.after = after;
  return r;
}

}  // namespace

TetReplacement plan_remove_faces(const TetSweep& s, int t, int face) {
  const Tet& v = s.tets[t];
  const int u = v[face];
  const int q = s.touched[t] ? -1 : across(s, t, face);
  if (q < 0 || s.touched[q]) return {};
  int w = -1;
  for (int x : s.tets[q])
    if (!has(v, x)) w = x;
  std::vector<int> uw;
  s.tets_with(u, w, -1, uw);
  if (!uw.empty() || s.locked[u] || s.locked[w]) return {};  // the new edge must not exist yet
  // the sandwich: the ring of its faces' triangulation (a disc: each face added shares one
  // edge with it and brings a new node) and its tets, two per face
  std::vector<int> ring{v[kTetFace[face][0]], v[kTetFace[face][1]], v[kTetFace[face][2]]};
  std::vector<int> old{t, q}, with_u, with_w;
  for (int x : ring)
    if (s.locked[x]) return {};
  TetReplacement best = sandwich_replacement(s.P, s.tets, ring, old, u, w);
  while (old.size() < 2 * static_cast<size_t>(kSandwichFaces)) {
    // grow across the ring edge whose face gives the best replacement (or the first growable)
    TetReplacement grown;
    int at = -1, node = -1, tu = -1, tw = -1;
    for (int m = 0; m < static_cast<int>(ring.size()); ++m) {
      const int x = ring[m], y = ring[(m + 1) % ring.size()];
      s.tets_with(x, y, u, with_u);
      if (with_u.size() != 2) continue;
      const int cu = std::find(old.begin(), old.end(), with_u[0]) == old.end() ? with_u[0] : with_u[1];
      if (std::find(old.begin(), old.end(), cu) != old.end() || s.touched[cu]) continue;
      int z = -1;
      for (int y2 : s.tets[cu])
        if (y2 != x && y2 != y && y2 != u) z = y2;
      if (z == w || s.locked[z] || std::find(ring.begin(), ring.end(), z) != ring.end()) continue;
      s.tets_with(x, y, z, with_w);
      int cw = -1;
      for (int c : with_w)
        if (has(s.tets[c], w) && !s.touched[c]) cw = c;
      if (cw < 0) continue;
      std::vector<int> r2 = ring, o2 = old;
      r2.insert(r2.begin() + m + 1, z);
      o2.push_back(cu), o2.push_back(cw);
      TetReplacement c = sandwich_replacement(s.P, s.tets, r2, o2, u, w);
      if (at < 0 || (!c.empty() && (grown.empty() || c.after > grown.after)))
        grown = std::move(c), at = m, node = z, tu = cu, tw = cw;
    }
    if (at < 0) break;
    ring.insert(ring.begin() + at + 1, node);
    old.push_back(tu), old.push_back(tw);
    if (!grown.empty() && (best.empty() || grown.after > best.after)) best = std::move(grown);
  }
  return best;
}

namespace {

/// Where a Steiner point may take sliver t out: its circumcentre (when within its longest
/// edge of its centroid: a sliver's lies near its middle), and, for each face of t on the
/// boundary of the tets, the point on the face's inward normal (towards t's fourth node) from
/// the face's centroid at kSteinerHeight of its mean edge — a flat tet on the chords of a
/// curved face is replaced by tets standing on its boundary faces.
std::vector<Vec3> steiner_points(const TetSweep& s, int t) {
  const Tet& v = s.tets[t];
  const std::vector<Vec3>& P = s.P;
  std::vector<Vec3> out;
  const Vec3 centroid = (P[v[0]] + P[v[1]] + P[v[2]] + P[v[3]]) / 4;
  const Vec3 u = P[v[1]] - P[v[0]], w = P[v[2]] - P[v[0]], z = P[v[3]] - P[v[0]];
  const double det = 2 * u.dot(w.cross(z));
  double longest = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) longest = std::max(longest, (P[v[i]] - P[v[j]]).norm());
  if (det != 0) {
    const Vec3 c =
        P[v[0]] + (u.squaredNorm() * w.cross(z) + w.squaredNorm() * z.cross(u) + z.squaredNorm() * u.cross(w)) / det;
    if ((c - centroid).norm() <= longest) out.push_back(c);
  }
  for (int f = 0; f < 4; ++f) {
    if (across(s, t, f) >= 0) continue;
    const Vec3& a = P[v[kTetFace[f][0]]];
    const Vec3& b = P[v[kTetFace[f][1]]];
    const Vec3& c = P[v[kTetFace[f][2]]];
    Vec3 n = (b - a).cross(c - a);
    if (n.norm() == 0) continue;
    n.normalize();
    if (n.dot(P[v[f]] - a) < 0) n = -n;
    const double edge = ((a - b).norm() + (b - c).norm() + (c - a).norm()) / 3;
    out.push_back((a + b + c) / 3 + kSteinerHeight * edge * n);
  }
  return out;
}

/// The conflict cavity of point x at tet t: t and the tets reached from it across faces
/// whose circumsphere holds x strictly (insphere; the tets are positive), untouched ones
/// only, at most kConflictTets of them (ascending).
std::vector<int> conflict_cavity(const TetSweep& s, int t, const Vec3& x) {
  std::vector<int> cavity{t};
  for (size_t k = 0; k < cavity.size() && cavity.size() < kConflictTets; ++k)
    for (int f = 0; f < 4 && cavity.size() < kConflictTets; ++f) {
      const int q = across(s, cavity[k], f);
      if (q < 0 || s.touched[q] || std::find(cavity.begin(), cavity.end(), q) != cavity.end()) continue;
      const Tet& y = s.tets[q];
      if (predicates::insphere(s.P[y[0]].data(), s.P[y[1]].data(), s.P[y[2]].data(), s.P[y[3]].data(), x.data()) > 0)
        cavity.push_back(q);
    }
  std::sort(cavity.begin(), cavity.end());
  return cavity;
}

/// The best refill of tet t (the highest gain in radius ratio below `bad`) among its
/// candidate cavities, with `wide` also the wider ones and the conflict cavities of its
/// Steiner points (each re-filled from a search started at its point); empty when none helps.
CavityStar best_refill(TetSweep& s, int t, double bad, bool wide) {
  CavityStar best;
  auto consider = [&](std::vector<int> cavity, const Vec3* start) {
    CavityStar star = plan_refill_cavity(s, std::move(cavity), bad, start);
    if (!star.empty() && star.gain > best.gain) best = std::move(star);
  };
  for (std::vector<int>& c : candidate_cavities(s, t)) consider(std::move(c), nullptr);
  if (!wide) return best;
  for (std::vector<int>& c : wide_cavities(s, t)) consider(std::move(c), nullptr);
  for (const Vec3& x : steiner_points(s, t)) consider(conflict_cavity(s, t, x), &x);
  return best;
}

/// One sweep of cavity refills over the tets of `order` (worst first): each not yet touched
/// and with no locked node gets its best refill (best_refill). Returns the refills applied.
long refill_sweep(TetSweep& s, std::vector<Tet>& tets, const std::vector<std::pair<double, size_t>>& order, double bad,
                  bool wide) {
  long done = 0;
  for (const auto& [r0, t] : order) {
    if (s.touched[t]) continue;
    bool skip = false;
    for (int x : tets[t]) skip |= s.locked[x] != 0;
    if (skip) continue;
    const CavityStar best = best_refill(s, static_cast<int>(t), bad, wide);
    if (best.empty()) continue;
    apply(s, best);
    ++done;
  }
  return done;
}

}  // namespace

long remove_tets_below(std::vector<Vec3>& P, std::vector<Tet>& tets, double floor, int sweeps,
                       const Progress& progress) {
  long done = 0;
  const double bad = floor / kSliverShare;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    progress.check_cancel("volume meshing (sliver removal)");
    const std::vector<std::pair<double, size_t>> order = tets_below(P, tets, floor);
    if (order.empty()) break;
    TetSweep s(P, tets);
    done += refill_sweep(s, tets, order, bad, true);
    if (s.pending.empty()) break;
    s.end();
  }
  return done;
}

namespace {

/// The tets of v's ball below `floor` with v at `x` (P[v] is as it was on return).
int ball_below(std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency::Row& ts, int v, const Vec3& x,
               double floor) {
  const Vec3 at = P[v];
  P[v] = x;
  int n = 0;
  for (int q : ts) n += rho(P, tets[q]) < floor;
  P[v] = at;
  return n;
}

/// Node v of a tet below `floor` to the best of the compass search's, the optimisation's and
/// (when those leave its ball below floor) the perturbation's positions, then optimised again
/// from there — each move only when it leaves no more tets of the ball below floor than
/// there were (raising the worst alone can bring more of them below it); true when it moved.
bool move_sliver_node(std::vector<Vec3>& P, const std::vector<Tet>& tets, const Adjacency& stars, int v, double floor) {
  const Adjacency::Row ts = stars.row(v);
  const int below = ball_below(P, tets, ts, v, P[v], floor);
  NodeMove m;
  int m_below = below;
  auto consider = [&](const NodeMove& c) {
    if (c.empty()) return;
    const int n = ball_below(P, tets, ts, v, c.to, floor);
    if (n > below) return;
    if (m.empty() || n < m_below || (n == m_below && c.after > m.after)) m = c, m_below = n;
  };
  consider(plan_search_node(P, tets, stars, v));
  consider(plan_optimise_node(P, tets, stars, v));
  if (m.empty() || m.after < floor) consider(plan_perturb_node(P, tets, stars, v));
  if (m.empty()) return false;
  mesh::apply(P, m);  // qualified: std::apply would be found by ADL too
  const NodeMove polish = plan_optimise_node(P, tets, stars, v);
  if (!polish.empty() && ball_below(P, tets, ts, v, polish.to, floor) <= m_below) mesh::apply(P, polish);
  return true;
}

}  // namespace

long perturb_sliver_nodes(std::vector<Vec3>& P, const std::vector<Tet>& tets, int first_new, double floor,
                          bool optimise) {
  const Adjacency stars = node_stars(P.size(), tets);
  std::vector<char> seen(P.size(), 0);
  long moved = 0;
  for (const auto& [r0, t] : tets_below(P, tets, floor))
    for (int v : tets[t]) {
      if (v < first_new || seen[v]) continue;
      seen[v] = 1;
      if (optimise) {
        moved += move_sliver_node(P, tets, stars, v, floor);
        continue;
      }
      NodeMove m = plan_search_node(P, tets, stars, v);
      if (m.empty()) m = plan_perturb_node(P, tets, stars, v);
      if (m.empty()) continue;
      mesh::apply(P, m);  // qualified: std::apply would be found by ADL too
      ++moved;
    }
  return moved;
}

long remove_slivers(std::vector<Vec3>& P, std::vector<Tet>& tets, int first_new, double floor, int rounds,
                    const Progress& progress) {
  long left = static_cast<long>(tets_below(P, tets, floor).size());
  if (left == 0) return 0;
  // first the plain rounds, then, for what they leave, the rounds with optimise_node and the
  // best flips (run first, those left NIST 5's fill with tets below 0.1 that these clear),
  // then for what those leave the wide reconnections (every triangulation of larger edge
  // rings, multi-face removal: the slivers of boundary nodes that no point may take out);
  // what each phase leaves and the CPU it takes go to the volume stage's info line
  constexpr const char* kPhase[] = {"perturbation, flips and refills", "optimisation", "wide reconnections"};
  std::ostringstream report;
  report << "volume: sliver removal: " << left << " tets below " << floor;
  for (const int phase : {0, 1, 2}) {
    if (left == 0) break;
    const double cpu0 = thread_cpu_seconds();
    for (int round = 0; round < rounds && left > 0; ++round) {
      progress.check_cancel("volume meshing (slivers)");
      perturb_sliver_nodes(P, tets, first_new, floor, phase > 0);
      flip_bad_tets(P, tets, floor, phase > 0, phase == 2);
      remove_tets_below(P, tets, floor, 2, progress);
      const long now = static_cast<long>(tets_below(P, tets, floor).size());
      const bool fell = now < left;
      left = now;
      if (!fell) break;
    }
    report << ", " << left << " after the " << kPhase[phase] << " (" << std::fixed << std::setprecision(2)
           << thread_cpu_seconds() - cpu0 << " s CPU)";
  }
  progress.info(report.str());
  return left;
}

long insert_points_at_slivers(std::vector<Vec3>& P, std::vector<Tet>& tets, double bad) {
  long done = 0;
  for (int sweep = 0; sweep < 3; ++sweep) {
    TetSweep s(P, tets);
    // worst first: a replacement locks its nodes for the rest of the sweep
    done += refill_sweep(s, tets, tets_below(P, tets, bad), bad, false);
    if (s.pending.empty()) break;
    s.end();
  }
  return done;
}

void improve_tets(std::vector<Vec3>& P, std::vector<Tet>& tets, int first_new, const TetImproveParams& params,
                  const Progress& progress) {
  for (int round = 0; round < params.quality_rounds; ++round) {
    progress.check_cancel("volume meshing (quality)");
    if (params.flip_below > 0) flip_bad_tets(P, tets, params.flip_below);
    if (params.smoothing_iterations > 0 && static_cast<int>(P.size()) > first_new) {
      const Adjacency stars = node_stars(P.size(), tets);
      smooth_nodes(P, tets, stars, first_new, params.smoothing_iterations);
      search_nodes_of_bad_tets(P, tets, stars, first_new, params.sliver_below);
    }
  }
  // slivers the flips and moves left (e.g. with two faces on the boundary): re-filled from a
  // new point, then one more round of flips and compass search
  for (int again = 0; again < 3 && params.sliver_below > 0; ++again) {
    progress.check_cancel("volume meshing (quality)");
    if (insert_points_at_slivers(P, tets, params.sliver_below) == 0) break;
    if (params.flip_below > 0) {
      flip_bad_tets(P, tets, params.sliver_below);
      search_nodes_of_bad_tets(P, tets, node_stars(P.size(), tets), first_new, params.sliver_below);
    }
  }
  if (params.sliver_floor > 0) {
    remove_tets_below(P, tets, params.sliver_floor, 4, progress);
    remove_slivers(P, tets, first_new, params.sliver_floor, params.sliver_rounds, progress);
  }
  if (params.shape_floor > params.sliver_floor)
    remove_slivers(P, tets, first_new, params.shape_floor, params.sliver_rounds, progress);
}

}  // namespace topopt::mesh
