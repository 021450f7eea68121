// Delaunay bulk for the 3D front (see delaunay_bulk.h).
#include "mesh/volume/delaunay_bulk.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <queue>
#include <unordered_map>

#include "common/face_key.h"
#include "mesh/core/predicates.h"
#include "mesh/core/tet_quality.h"
#include "mesh/volume/background_size.h"

namespace topopt::mesh {
namespace {

using Vec3 = Eigen::Vector3d;
using predicates::insphere;
using predicates::orient3d;

constexpr auto& kFace = kTetFace;

/// Rounds of taking unseen tets out of a point's cavity before its insertion is refused.
/// Most points need one or two; next to NIST 6's B-spline half-cylinders many need more: at 3,
/// the bulk of its surface (DelaunayBulk.Nist6BulkReachesItsCurvedWalls) refused 7 571 points
/// at the cap and kept 2 324 tets of four boundary nodes below radius ratio 0.1 under those
/// faces, which the improvement turns into tets standing on the boundary that it cannot lift
/// (the product's mesh at 0.6x its size: 5 828 tets below 0.1). Measured (BENCHMARKS.md, issue
/// 20, eighth pass): 8 and more leave one tet of 0.095 in VolumeFillQuality.NoSliverOnNist5,
/// and at 12 the front could not close the bulk's holes on NIST 6 at 0.6x (then filled by the
/// front alone: 23 257 tets below 0.1 before the improvement); 6 passes both.
constexpr int kMaxPeels = 6;
/// A repaired insertion is refused when its star has a tet below this radius ratio that is
/// worse than every tet it removes (Tets::poor_star). Measured (BENCHMARKS.md, issue 20 sixth
/// pass): 0.1 cleans NIST 2 but gives back most of NIST 6's gain (43 -> 256 tets below 0.1
/// after the improvement); 0.02 keeps NIST 6's (38) and NIST 5's test clean.
constexpr double kRepairFloor = 0.02;

/// A tet mesh with face adjacency (nb[t][i]: the tet across face i, -1 for none: a wall) and
/// Bowyer–Watson insertion. Slots of removed tets are reused; gen[t] counts the reuses so that
/// queued references to a slot can tell they are stale.
class Tets {
 public:
  explicit Tets(std::vector<Vec3>& P) : P_(P) {}

  std::vector<std::array<int, 4>> v, nb;
  std::vector<char> dead;
  std::vector<unsigned> gen;

  int make(int a, int b, int c, int d) {
    int t;
    if (!free_.empty()) {
      t = free_.back();
      free_.pop_back();
      v[t] = {a, b, c, d};
      nb[t] = {-1, -1, -1, -1};
      dead[t] = 0;
      ++gen[t];
    } else {
      t = static_cast<int>(v.size());
      v.push_back({a, b, c, d});
      nb.push_back({-1, -1, -1, -1});
      dead.push_back(0);
      gen.push_back(0);
      stamp_.push_back(0);
    }
    ++alive_;
    last_ = t;
    return t;
  }
  void kill(int t) {
    dead[t] = 1;
    free_.push_back(t);
    --alive_;
  }
  long alive() const { return alive_; }
  const double* x(int i) const { return P_[i].data(); }

  /// The tet holding q (on its closure), walking from t; -1 when the walk meets a wall.
  int locate(int t, const double* q) {
    for (int steps = 0; steps < 2000; ++steps) {
      seed_ = seed_ * 1664525u + 1013904223u;
      const unsigned r = seed_ >> 16;
      int next = -2;
      for (int j = 0; j < 4; ++j) {
        const int i = static_cast<int>((r + j) & 3);
        const int* f = kFace[i];
        if (orient3d(x(v[t][f[0]]), x(v[t][f[1]]), x(v[t][f[2]]), q) > 0) {
          next = nb[t][i];
          break;
        }
      }
      if (next == -2) return t;
      if (next < 0) return -1;
      t = next;
    }
    return -1;
  }

  /// Inserts node p, lying in tet t: the tets whose circumsphere holds it strictly (connected,
  /// never through a wall) are replaced by the star of p on their boundary. With repair >= 0
  /// (a tet of that cavity), a tet of the cavity with a boundary face p does not see strictly
  /// (a wall nearby turns the cavity away from p) leaves it, until p sees all of its boundary
  /// (at most kMaxPeels rounds: each costs a pass over the cavity) — the star is then valid
  /// but not always Delaunay. Refused, mesh unchanged, when p is an
  /// existing node, does not see every boundary face strictly (without repair, or t or the
  /// tet `repair` would have to leave: the point is there to remove that tet), is repaired
  /// and its star has a tet below kRepairFloor worse than the cavity's worst (poor_star), or comes
  /// nearer than sqrt(min_dist2) to a node of those faces (the only nodes it would be joined
  /// to). The new tets go to `created` when given.
  bool insert(int p, int t, std::vector<int>* created, double min_dist2 = 0, int repair = -1) {
    const double* q = x(p);
    auto in_sphere = [&](int s) {
      const auto& w = v[s];
      return insphere(x(w[0]), x(w[1]), x(w[2]), x(w[3]), q) > 0;
    };
    unseen_ = poor_ = false;
    if (!in_sphere(t)) return false;
    ticket_ += 3;
    const unsigned in = ticket_ - 2, out = ticket_ - 1;
    cavity_.clear();
    stamp_[t] = in;
    cavity_.push_back(t);
    for (size_t k = 0; k < cavity_.size(); ++k)
      for (int i = 0; i < 4; ++i) {
        const int n = nb[cavity_[k]][i];
        if (n < 0 || stamp_[n] == in || stamp_[n] == out) continue;
        stamp_[n] = in_sphere(n) ? in : out;
        if (stamp_[n] == in) cavity_.push_back(n);
      }
    peels_ = 0;
    unseen_ = true;
    for (; !seen_cavity(t, q, in, out); ++peels_)
      if (repair < 0 || peels_ == kMaxPeels || stamp_[t] != in || stamp_[repair] != in) return false;
    unseen_ = false;
    poor_ = peels_ > 0 && poor_star(p);
    if (poor_) return false;
    for (const auto& [s, i] : boundary_) {
      const int* f = kFace[i];
      if (min_dist2 > 0)
        for (int w : {v[s][f[0]], v[s][f[1]], v[s][f[2]]})
          if ((P_[w] - P_[p]).squaredNorm() < min_dist2) return false;
    }
    edges_.clear();
    if (created) created->clear();
    for (const auto& [s, i] : boundary_) {
      const int* f = kFace[i];
      const int a = v[s][f[0]], b = v[s][f[1]], c = v[s][f[2]];
      const int o = nb[s][i];
      const int n = make(a, c, b, p);  // its face opposite p is (a, b, c), outward
      nb[n][3] = o;
      if (o >= 0)
        for (int k = 0; k < 4; ++k)
          if (nb[o][k] == s) {
            nb[o][k] = n;
            break;
          }
      edges_.push_back({std::min(b, c), std::max(b, c), n, 0});
      edges_.push_back({std::min(a, b), std::max(a, b), n, 1});
      edges_.push_back({std::min(a, c), std::max(a, c), n, 2});
      if (created) created->push_back(n);
    }
    std::sort(edges_.begin(), edges_.end(),
              [](const Edge& l, const Edge& r) { return l.u != r.u ? l.u < r.u : l.w < r.w; });
    for (size_t k = 0; k + 1 < edges_.size(); k += 2) {
      nb[edges_[k].t][edges_[k].face] = edges_[k + 1].t;
      nb[edges_[k + 1].t][edges_[k + 1].face] = edges_[k].t;
    }
    for (int s : cavity_) kill(s);
    return true;
  }
  /// The cavity's boundary faces (boundary_) from its tets (stamped `in`, listed in cavity_,
  /// connected to t); true when q sees every one strictly. Otherwise the tets with a face q
  /// does not see are stamped `out`, cavity_ keeps the tets still connected to t through
  /// tets stamped `in`, and false is returned (t itself may have left).
  bool seen_cavity(int t, const double* q, unsigned in, unsigned out) {
    boundary_.clear();
    bool all = true;
    for (int s : cavity_)
      for (int i = 0; i < 4; ++i) {
        const int n = nb[s][i];
        if (n >= 0 && stamp_[n] == in) continue;
        boundary_.push_back({s, i});
        const int* f = kFace[i];
        if (orient3d(x(v[s][f[0]]), x(v[s][f[1]]), x(v[s][f[2]]), q) < 0) continue;  // strictly inside
        all = false;
        stamp_[s] = out;
      }
    if (all || stamp_[t] != in) return all;
    const unsigned reach = in + 2;  // the tets still in, reached from t
    const std::vector<int> was = cavity_;
    cavity_.assign(1, t);
    stamp_[t] = reach;
    for (size_t k = 0; k < cavity_.size(); ++k)
      for (int n : nb[cavity_[k]])
        if (n >= 0 && stamp_[n] == in) stamp_[n] = reach, cavity_.push_back(n);
    for (int s : was)
      if (stamp_[s] == in) stamp_[s] = out;  // cut off from t
    for (int s : cavity_) stamp_[s] = in;
    return false;
  }

  /// Whether the star of p on the cavity's boundary (boundary_, seen by p) has a tet below
  /// kRepairFloor that is also worse than the worst tet of the cavity (cavity_): a repaired
  /// cavity is not Delaunay, and its star can hold a flat tet that no later point removes and
  /// the improvement only lifts part of the way (NIST 5: a star tet of 0.011,
  /// left at 0.091).
  bool poor_star(int p) const {
    double star = INFINITY, cavity = INFINITY;
    for (const auto& [s, i] : boundary_) {
      const int* f = kFace[i];
      star = std::min(star, radius_ratio(P_[v[s][f[0]]], P_[v[s][f[2]]], P_[v[s][f[1]]], P_[p]));
    }
    if (star >= kRepairFloor) return false;
    for (int s : cavity_) cavity = std::min(cavity, radius_ratio(P_[v[s][0]], P_[v[s][1]], P_[v[s][2]], P_[v[s][3]]));
    return star < cavity;
  }

  /// The tet made last (alive after a successful insertion).
  int last() const { return last_; }
  /// Rounds the last insertion took out of its cavity (0: its Delaunay cavity as it was).
  int peels() const { return peels_; }
  /// Whether the last insertion was refused because its point did not see its cavity.
  bool unseen() const { return unseen_; }
  /// Whether the last insertion was refused because its repaired star was poor (poor_star).
  bool poor() const { return poor_; }

 private:
  struct Edge {
    int u, w, t, face;
  };
  std::vector<Vec3>& P_;
  std::vector<int> free_, cavity_;
  std::vector<std::pair<int, int>> boundary_;
  std::vector<Edge> edges_;
  std::vector<unsigned> stamp_;
  unsigned ticket_ = 0, seed_ = 12345;
  long alive_ = 0;
  int last_ = -1, peels_ = 0;
  bool unseen_ = false, poor_ = false;
};

/// A new point keeps this × the size from every node it is joined to. A Delaunay cavity's
/// nodes are at least the circumradius (> 0.95 × the size) away; next to walls they need not
/// be, and without this bound refinement cascades at small angles between boundary faces.
constexpr double kClearance = 0.5;

/// How fast the size may grow away from a node (per unit of distance).
constexpr double kGrading = 0.4;

/// Circumcentre of tet t and its circumradius (infinite for a flat tet).
double circumcentre(const Tets& m, const std::vector<Vec3>& P, int t, Vec3& c) {
  const Vec3& a = P[m.v[t][0]];
  const Vec3 u = P[m.v[t][1]] - a, v = P[m.v[t][2]] - a, w = P[m.v[t][3]] - a;
  const double den = 2.0 * u.dot(v.cross(w));
  if (!(std::abs(den) > 0)) return INFINITY;
  const Vec3 r = (u.squaredNorm() * v.cross(w) + v.squaredNorm() * w.cross(u) + w.squaredNorm() * u.cross(v)) / den;
  c = a + r;
  return r.norm();
}

/// Could tet t meet triangle T = (T[0], T[1], T[2]) anywhere but at the nodes they share (and
/// the edge of two shared nodes)? False only when a plane of the tet or of the triangle has
/// the other's unshared nodes strictly on its far side and the shared ones on it, so a true
/// answer may be a false alarm — never the other way round.
bool may_meet(const Tets& m, const std::vector<Vec3>& P, int t, const std::array<int, 3>& T) {
  const auto& w = m.v[t];
  auto shared = [&](int x) { return x == w[0] || x == w[1] || x == w[2] || x == w[3]; };
  for (int k = 0; k < 3; ++k) {
    const double tlo = std::min({P[w[0]][k], P[w[1]][k], P[w[2]][k], P[w[3]][k]});
    const double thi = std::max({P[w[0]][k], P[w[1]][k], P[w[2]][k], P[w[3]][k]});
    if (std::max({P[T[0]][k], P[T[1]][k], P[T[2]][k]}) < tlo || std::min({P[T[0]][k], P[T[1]][k], P[T[2]][k]}) > thi)
      return false;
  }
  for (int i = 0; i < 4; ++i) {
    if (w[i] == T[0] || w[i] == T[1] || w[i] == T[2]) continue;  // a shared node off this face's plane
    const int* f = kFace[i];
    const double *x = P[w[f[0]]].data(), *y = P[w[f[1]]].data(), *z = P[w[f[2]]].data();
    bool apart = true;
    for (int v : T) apart &= shared(v) || orient3d(x, y, z, P[v].data()) > 0;
    if (apart) return false;
  }
  int pos = 0, neg = 0, off = 0;
  for (int x : w) {
    if (x == T[0] || x == T[1] || x == T[2]) continue;
    const int s = orient3d(P[T[0]].data(), P[T[1]].data(), P[T[2]].data(), P[x].data());
    pos += s > 0, neg += s < 0, ++off;
  }
  return !(pos == off || neg == off);
}

/// The boundary's nodes (ascending) and the corners of their box.
std::vector<int> boundary_nodes(const std::vector<Vec3>& P, const std::vector<std::array<int, 3>>& B, Vec3& lo,
                                Vec3& hi) {
  std::vector<char> on(P.size(), 0);
  for (const auto& t : B)
    for (int x : t) on[x] = 1;
  std::vector<int> nodes;
  lo = P[B[0][0]], hi = lo;
  for (size_t i = 0; i < P.size(); ++i)
    if (on[i]) {
      nodes.push_back(static_cast<int>(i));
      lo = lo.cwiseMin(P[i]), hi = hi.cwiseMax(P[i]);
    }
  return nodes;
}

/// The Delaunay tetrahedralisation of the nodes inside a far tet (its four nodes appended to
/// P at far0 = #P on entry, with size 20 × the box in hs), inserted in Morton order.
void tetrahedralise(Tets& m, std::vector<Vec3>& P, std::vector<double>& hs, const std::vector<int>& nodes,
                    const Vec3& lo, const Vec3& hi) {
  const Vec3 mid = (lo + hi) / 2;
  const double D = std::max((hi - lo).maxCoeff(), 1e-12);
  const int far0 = static_cast<int>(P.size());
  for (const Vec3& s : {Vec3(1, 1, 1), Vec3(1, -1, -1), Vec3(-1, 1, -1), Vec3(-1, -1, 1)})
    P.push_back(mid + 20 * D * s);
  hs.resize(P.size(), 20 * D);
  if (orient3d(P[far0].data(), P[far0 + 1].data(), P[far0 + 2].data(), P[far0 + 3].data()) > 0)
    m.make(far0, far0 + 1, far0 + 2, far0 + 3);
  else
    m.make(far0, far0 + 2, far0 + 1, far0 + 3);
  auto morton = [&](int i) {
    uint64_t code = 0;
    uint64_t q[3];
    for (int k = 0; k < 3; ++k) q[k] = static_cast<uint64_t>(std::clamp((P[i][k] - lo[k]) / D, 0.0, 1.0) * 1048575.0);
    for (int b = 19; b >= 0; --b)
      for (int k = 0; k < 3; ++k) code = (code << 1) | ((q[k] >> b) & 1);
    return code;
  };
  std::vector<std::pair<uint64_t, int>> order;
  order.reserve(nodes.size());
  for (int i : nodes) order.push_back({morton(i), i});
  std::sort(order.begin(), order.end());
  int at = 0;
  for (const auto& [code, i] : order) {
    const int t = m.locate(at, P[i].data());
    if (t >= 0 && m.insert(i, t, nullptr)) at = m.last();
  }
}

/// Which boundary triangles the tetrahedralisation holds, and what each tet knows of the
/// region: its faces on boundary triangles (wall bits) and on which side of them it lies.
struct HeldBoundary {
  std::vector<char> found;     ///< #B: the triangle is a face of some tet
  std::vector<char> wall;      ///< per tet: bit i when face i is a boundary triangle
  std::vector<char> evidence;  ///< per tet: 1 inside (by one of its walls), 2 outside, 3 both
};

HeldBoundary held_boundary(const Tets& m, const std::vector<std::array<int, 3>>& B) {
  std::unordered_map<FaceKey, int, FaceKeyHash> bindex;
  bindex.reserve(B.size() * 2);
  for (size_t b = 0; b < B.size(); ++b) bindex.emplace(face_key(B[b][0], B[b][1], B[b][2]), static_cast<int>(b));
  const size_t nt = m.v.size();
  HeldBoundary h{std::vector<char>(B.size(), 0), std::vector<char>(nt, 0), std::vector<char>(nt, 0)};
  for (size_t t = 0; t < nt; ++t) {
    if (m.dead[t]) continue;
    for (int i = 0; i < 4; ++i) {
      const int* f = kFace[i];
      const int a = m.v[t][f[0]], b = m.v[t][f[1]], c = m.v[t][f[2]];
      auto it = bindex.find(face_key(a, b, c));
      if (it == bindex.end()) continue;
      h.found[it->second] = 1;
      h.wall[t] |= static_cast<char>(1 << i);
      const auto& tri = B[it->second];
      // the tet's outward face turns the same way as the region's outward triangle: inside
      const bool same = (tri[0] == a && tri[1] == b) || (tri[1] == a && tri[2] == b) || (tri[2] == a && tri[0] == b);
      h.evidence[t] |= same ? 1 : 2;
    }
  }
  return h;
}

/// Around every missing boundary triangle, every tet that may meet it (other than at a shared
/// node or edge): found from the stars of its three nodes, then across faces while they may.
/// Returns the marks (per tet).
std::vector<char> tets_near_missing(const Tets& m, const std::vector<Vec3>& P, const std::vector<std::array<int, 3>>& B,
                                    const std::vector<char>& found) {
  const size_t nt = m.v.size();
  std::vector<int> vtet(P.size(), -1);
  for (size_t t = 0; t < nt; ++t)
    if (!m.dead[t])
      for (int x : m.v[t]) vtet[x] = static_cast<int>(t);
  std::vector<char> removed(nt, 0);
  std::vector<unsigned> seen(nt, 0);
  unsigned ticket = 0;
  std::vector<int> queue;
  for (size_t b = 0; b < B.size(); ++b) {
    if (found[b]) continue;
    queue.clear();
    for (int x : B[b]) {  // the star of x: the tets reached across faces through x
      if (vtet[x] < 0) continue;
      ++ticket;
      const size_t first = queue.size();
      seen[vtet[x]] = ticket;
      queue.push_back(vtet[x]);
      for (size_t k = first; k < queue.size(); ++k)
        for (int i = 0; i < 4; ++i) {
          const int n = m.nb[queue[k]][i];
          if (m.v[queue[k]][i] == x || n < 0 || seen[n] == ticket) continue;  // across faces through x
          seen[n] = ticket;
          queue.push_back(n);
        }
    }
    ++ticket;
    for (int s : queue) {
      seen[s] = ticket;
      if (may_meet(m, P, s, B[b])) removed[s] = 1;
    }
    for (size_t k = 0; k < queue.size(); ++k)
      for (int n : m.nb[queue[k]]) {
        if (n < 0 || seen[n] == ticket) continue;
        seen[n] = ticket;
        if (may_meet(m, P, n, B[b])) removed[n] = 1, queue.push_back(n);
      }
  }
  return removed;
}

/// Components of the tets not removed, not crossing boundary triangles: kept when inside (all
/// their evidence says so and none touches a far node); the others die, and the survivors'
/// neighbours across dead tets become walls.
void keep_inside(Tets& m, const HeldBoundary& held, const std::vector<char>& removed, int far0) {
  const size_t nt = m.v.size();
  std::vector<int> comp(nt, -1), queue;
  std::vector<char> keep_comp;
  for (size_t t0 = 0; t0 < nt; ++t0) {
    if (m.dead[t0] || removed[t0] || comp[t0] >= 0) continue;
    const int c = static_cast<int>(keep_comp.size());
    bool far = false;
    char ev = 0;
    queue.assign(1, static_cast<int>(t0));
    comp[t0] = c;
    for (size_t k = 0; k < queue.size(); ++k) {
      const int s = queue[k];
      ev |= held.evidence[s];
      for (int x : m.v[s]) far |= x >= far0;
      for (int i = 0; i < 4; ++i) {
        const int n = m.nb[s][i];
        if ((held.wall[s] >> i) & 1 || n < 0 || removed[n] || comp[n] >= 0) continue;
        comp[n] = c;
        queue.push_back(n);
      }
    }
    keep_comp.push_back(!far && ev == 1);
  }
  for (size_t t = 0; t < nt; ++t)
    if (!m.dead[t] && (removed[t] || !keep_comp[comp[t]])) m.kill(static_cast<int>(t));
  for (size_t t = 0; t < nt; ++t)
    if (!m.dead[t])
      for (int& n : m.nb[t])
        if (n >= 0 && m.dead[n]) n = -1;
}

/// Refinement: circumcentres of the tets too large for the size, largest ratio first (a tet
/// whose circumcentre lies outside the region or behind a hole is left as it is). Each point
/// is inserted with the cavity repaired (Tets::insert): next to walls the Delaunay cavity of a
/// point is often not star-shaped from it, and refusing those points left the tets along the
/// boundary as coarse as the tetrahedralisation of the boundary nodes made them — NIST 6's
/// slivers (BENCHMARKS.md, issue 20). The size at a point: each node of its tet allows its
/// own size (hs) plus kGrading × the distance to it (a small boundary feature sets the size
/// around it, growing away from it); the size function, where given, caps that. Counts the
/// points inserted, repaired and refused for their cavity in `out`.
void refine(Tets& m, std::vector<Vec3>& P, std::vector<double>& hs, const DelaunayBulkParams& params,
            const Progress& progress, DelaunayBulkResult& out) {
  auto size_at = [&](int t, const Vec3& c) {
    double h = params.size ? params.size(c.data()) : INFINITY;
    for (int x : m.v[t]) h = std::min(h, hs[x] + kGrading * (P[x] - c).norm());
    return h;
  };
  struct Item {
    double ratio;
    int t;
    unsigned gen;
    bool operator<(const Item& o) const { return ratio < o.ratio; }
  };
  std::priority_queue<Item> work;
  auto consider = [&](int t) {
    Vec3 c;
    const double R = circumcentre(m, P, t, c);
    if (!std::isfinite(R)) return;
    const auto& w = m.v[t];
    const double h = size_at(t, (P[w[0]] + P[w[1]] + P[w[2]] + P[w[3]]) / 4);
    if (R > params.refine_above * h) work.push({R / h, t, m.gen[t]});
  };
  for (size_t t = 0; t < m.v.size(); ++t)
    if (!m.dead[t]) consider(static_cast<int>(t));
  std::vector<int> created;
  long popped = 0;
  while (!work.empty() && m.alive() < params.max_tets) {
    const Item it = work.top();
    work.pop();
    if (m.dead[it.t] || m.gen[it.t] != it.gen) continue;
    if (++popped % 20000 == 0) progress.check_cancel("volume meshing");
    Vec3 c;
    const double R = circumcentre(m, P, it.t, c);
    const int t = m.locate(it.t, c.data());
    if (t < 0) continue;  // outside, or behind a hole
    const double h = size_at(t, c);
    if (R <= params.refine_above * h) continue;
    P.push_back(c);
    hs.push_back(h);
    const int p = static_cast<int>(P.size()) - 1;
    if (!m.insert(p, t, &created, kClearance * kClearance * h * h, params.repair_cavities ? it.t : -1)) {
      P.pop_back(), hs.pop_back();
      out.refused_unseen += m.unseen();
      out.refused_poor += m.poor();
      continue;
    }
    ++out.points;
    out.repaired += m.peels() > 0;
    for (int n : created) consider(n);
  }
}

}  // namespace

DelaunayBulkResult delaunay_bulk(std::vector<Vec3>& P, const std::vector<std::array<int, 3>>& B,
                                 const DelaunayBulkParams& params, const Progress& progress) {
  DelaunayBulkResult out;
  if (B.empty()) return out;
  std::vector<double> hs = node_spacing(P, B);  // the boundary nodes' sizes: their mean edge
  Vec3 lo, hi;
  const std::vector<int> nodes = boundary_nodes(P, B, lo, hi);
  const int far0 = static_cast<int>(P.size());
  Tets m(P);
  tetrahedralise(m, P, hs, nodes, lo, hi);
  const HeldBoundary held = held_boundary(m, B);
  out.missing_triangles = std::count(held.found.begin(), held.found.end(), 0);
  if (out.missing_triangles > params.max_missing_share * static_cast<double>(B.size())) {
    P.resize(far0);
    out.gave_up = true;
    return out;
  }
  keep_inside(m, held, tets_near_missing(m, P, B, held.found), far0);
  refine(m, P, hs, params, progress, out);
  for (size_t t = 0; t < m.v.size(); ++t) {
    if (m.dead[t]) continue;
    out.tets.push_back(m.v[t]);
    for (int i = 0; i < 4; ++i)
      if (m.nb[t][i] < 0) out.free_faces.push_back({m.v[t][kFace[i][0]], m.v[t][kFace[i][1]], m.v[t][kFace[i][2]]});
  }
  return out;
}

}  // namespace topopt::mesh
