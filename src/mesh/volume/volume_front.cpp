// 3D advancing front (see volume_front.h).
#include "mesh/volume/volume_front.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <queue>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "common/error.h"
#include "common/face_key.h"
#include "mesh/core/predicates.h"
#include "mesh/core/tet_quality.h"
#include "mesh/volume/background_size.h"
#include "mesh/volume/delaunay_bulk.h"

namespace topopt::mesh {
namespace {

using Vec3 = Eigen::Vector3d;
using Tri = std::array<int, 3>;

/// Outward faces of a positive tet, opposite vertex 0..3; triangles matched by their sorted key.
constexpr auto& kFace = kTetFace;
using TriKey = FaceKey;
using TriKeyHash = FaceKeyHash;
inline TriKey key_of(int a, int b, int c) { return face_key(a, b, c); }

/// Uniform grid of buckets over ids with a box each; lookups return candidates (the caller
/// filters stale or far ones). Entries are removed lazily by the caller's alive flags.
/// Multi-level hashed grid of boxes. An item goes to the level whose cells are at least as
/// large as its size (level k has cells of base·2^k, so an item sits in at most 8 cells),
/// which keeps the buckets small where the mesh is graded from tiny to large elements. Every
/// level also counts its non-empty cells per block of 16³ cells: a query visits, on each
/// level holding items, either the cells overlapping its box (small boxes) or the occupied
/// blocks overlapping it (a large box over a fine level costs its blocks, not its cells).
class Grid {
 public:
  Grid(const Vec3& origin, double base) : origin_(origin), base_(base) {}
  /// Registers id with box [lo, hi]; `size` (>= the box) chooses the level.
  void insert(int id, const Vec3& lo, const Vec3& hi, double size = 0) {
    const double ext = std::max(size, (hi - lo).maxCoeff());
    int k = 0;
    while (k < 48 && base_ * std::ldexp(1.0, k) < ext) ++k;
    while (static_cast<int>(levels_.size()) <= k)
      levels_.emplace_back(1.0 / (base_ * std::ldexp(1.0, static_cast<int>(levels_.size()))));
    Level& L = levels_[k];
    const auto a = L.cell(lo, origin_), b = L.cell(hi, origin_);
    for (long x = a[0]; x <= b[0]; ++x)
      for (long y = a[1]; y <= b[1]; ++y)
        for (long z = a[2]; z <= b[2]; ++z) {
          std::vector<int>& ids = L.buckets[key(x, y, z)];
          if (ids.empty()) ++L.blocks[key(x >> 4, y >> 4, z >> 4)];
          ids.push_back(id);
        }
    ++L.items;
  }
  /// Appends the live ids (keep(id)) registered in cells overlapping [lo, hi] to out, each
  /// once (`stamp` marks ids already taken in this query: sized to the id range by the caller,
  /// holding values < `ticket`). Dead ids are dropped from the cells visited on the way.
  template <class Keep>
  void query(const Vec3& lo, const Vec3& hi, std::vector<int>& out, Keep&& keep, std::vector<unsigned>& stamp,
             unsigned ticket) {
    for (Level& L : levels_) {
      if (L.blocks.empty()) continue;
      const auto a = L.cell(lo, origin_), b = L.cell(hi, origin_);
      auto visit = [&](long x, long y, long z) {
        auto it = L.buckets.find(key(x, y, z));
        if (it == L.buckets.end()) return;
        std::vector<int>& ids = it->second;
        size_t w = 0;
        for (size_t r = 0; r < ids.size(); ++r) {
          const int id = ids[r];
          if (!keep(id)) continue;
          ids[w++] = id;
          if (stamp[id] != ticket) stamp[id] = ticket, out.push_back(id);
        }
        ids.resize(w);
        if (w == 0) {  // the cell emptied: its block counts one cell less
          L.buckets.erase(it);
          auto bl = L.blocks.find(key(x >> 4, y >> 4, z >> 4));
          if (bl != L.blocks.end() && --bl->second <= 0) L.blocks.erase(bl);
        }
      };
      const long cells = (b[0] - a[0] + 1) * (b[1] - a[1] + 1) * (b[2] - a[2] + 1);
      if (cells <= 64) {
        for (long x = a[0]; x <= b[0]; ++x)
          for (long y = a[1]; y <= b[1]; ++y)
            for (long z = a[2]; z <= b[2]; ++z) visit(x, y, z);
        continue;
      }
      for (long bx = a[0] >> 4; bx <= b[0] >> 4; ++bx)
        for (long by = a[1] >> 4; by <= b[1] >> 4; ++by)
          for (long bz = a[2] >> 4; bz <= b[2] >> 4; ++bz) {
            if (!L.blocks.count(key(bx, by, bz))) continue;
            for (long x = std::max(a[0], bx << 4); x <= std::min(b[0], (bx << 4) + 15); ++x)
              for (long y = std::max(a[1], by << 4); y <= std::min(b[1], (by << 4) + 15); ++y)
                for (long z = std::max(a[2], bz << 4); z <= std::min(b[2], (bz << 4) + 15); ++z) visit(x, y, z);
          }
    }
  }

 private:
  struct Level {
    explicit Level(double inv_cell) : inv(inv_cell) {}
    double inv;
    long items = 0;
    std::unordered_map<uint64_t, std::vector<int>> buckets;
    std::unordered_map<uint64_t, int> blocks;  ///< non-empty cells per block of 16³
    std::array<long, 3> cell(const Vec3& p, const Vec3& o) const {
      return {static_cast<long>(std::floor((p[0] - o[0]) * inv)), static_cast<long>(std::floor((p[1] - o[1]) * inv)),
              static_cast<long>(std::floor((p[2] - o[2]) * inv))};
    }
  };
  /// Distinct cells give distinct keys while |coordinates| < 2^20 cells; beyond, two cells
  /// may share a bucket, which only costs time (callers test the geometry).
  static uint64_t key(long x, long y, long z) {
    const uint64_t m = (1ull << 21) - 1;
    return ((static_cast<uint64_t>(x) & m) << 42) | ((static_cast<uint64_t>(y) & m) << 21) |
           (static_cast<uint64_t>(z) & m);
  }
  Vec3 origin_;
  double base_;
  std::vector<Level> levels_;
};

using predicates::orient3d;

/// Does segment (u, v) meet triangle (x, y, z) anywhere other than at a shared vertex?
/// Exact; touching counts as meeting (conservative), coplanar configurations too unless the
/// segment shares a vertex with the triangle and leaves it outside.
bool segment_meets_triangle(const std::vector<Vec3>& P, int u, int v, int x, int y, int z) {
  bool u_shared = u == x || u == y || u == z, v_shared = v == x || v == y || v == z;
  if (u_shared && v_shared) return false;  // the segment is an edge of the triangle
  // separated boxes: no predicate needed (exact: comparisons of the input doubles)
  for (int k = 0; k < 3; ++k) {
    double slo = std::min(P[u][k], P[v][k]), shi = std::max(P[u][k], P[v][k]);
    double tlo = std::min({P[x][k], P[y][k], P[z][k]}), thi = std::max({P[x][k], P[y][k], P[z][k]});
    if (shi < tlo || slo > thi) return false;
  }
  const double *pu = P[u].data(), *pv = P[v].data(), *px = P[x].data(), *py = P[y].data(), *pz = P[z].data();
  int su = u_shared ? 0 : orient3d(px, py, pz, pu), sv = v_shared ? 0 : orient3d(px, py, pz, pv);
  if (su == sv && su != 0) return false;
  if (su == 0 && sv == 0) {
    // coplanar: meet unless separated; decide in the plane with the 2D predicate on the
    // projection that keeps the triangle non-degenerate
    Vec3 n = (P[y] - P[x]).cross(P[z] - P[x]);
    int drop = 0;
    n.cwiseAbs().maxCoeff(&drop);
    int i0 = (drop + 1) % 3, i1 = (drop + 2) % 3;
    auto q = [&](int k) { return std::array<double, 2>{P[k][i0], P[k][i1]}; };
    auto U = q(u), Vv = q(v), X = q(x), Y = q(y), Z = q(z);
    int o = predicates::orient2d(X.data(), Y.data(), Z.data());
    auto inside = [&](const std::array<double, 2>& p) {
      int a = predicates::orient2d(X.data(), Y.data(), p.data()) * o,
          b = predicates::orient2d(Y.data(), Z.data(), p.data()) * o,
          c = predicates::orient2d(Z.data(), X.data(), p.data()) * o;
      return a > 0 && b > 0 && c > 0;
    };
    auto crosses = [&](const std::array<double, 2>& a, const std::array<double, 2>& b, const std::array<double, 2>& c,
                       const std::array<double, 2>& d) {  // proper crossing of ab and cd
      int s1 = predicates::orient2d(a.data(), b.data(), c.data()),
          s2 = predicates::orient2d(a.data(), b.data(), d.data());
      int s3 = predicates::orient2d(c.data(), d.data(), a.data()),
          s4 = predicates::orient2d(c.data(), d.data(), b.data());
      return s1 * s2 < 0 && s3 * s4 < 0;
    };
    if ((!u_shared && inside(U)) || (!v_shared && inside(Vv))) return true;
    if (crosses(U, Vv, X, Y) || crosses(U, Vv, Y, Z) || crosses(U, Vv, Z, X)) return true;
    std::array<double, 2> mid{0.5 * (U[0] + Vv[0]), 0.5 * (U[1] + Vv[1])};
    return inside(mid);
  }
  // the segment crosses (or touches) the plane: where does the line pass the triangle?
  int a = orient3d(pu, pv, px, py), b = orient3d(pu, pv, py, pz), c = orient3d(pu, pv, pz, px);
  bool hit = (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
  if (!hit) return false;
  // contact only at a shared vertex: the touching endpoint is that vertex
  if (su == 0 && u_shared) return false;
  if (sv == 0 && v_shared) return false;
  return true;
}

class Front {
 public:
  Front(std::vector<Vec3>& P, double cell, const Vec3& origin)
      : P_(P), faces_grid_(origin, cell), nodes_grid_(origin, cell) {}

  int add_face(int a, int b, int c) {
    TriKey k = key_of(a, b, c);
    auto it = index_.find(k);
    if (it != index_.end()) {  // the opposite face is already on the front: both close
      kill(it->second);
      return -1;
    }
    int id = static_cast<int>(faces_.size());
    faces_.push_back({a, b, c});
    alive_.push_back(1);
    fails_.push_back(0);
    index_.emplace(k, id);
    Vec3 lo = P_[a].cwiseMin(P_[b]).cwiseMin(P_[c]), hi = P_[a].cwiseMax(P_[b]).cwiseMax(P_[c]);
    faces_grid_.insert(id, lo, hi);
    for (int v : {a, b, c}) {
      if (static_cast<int>(active_.size()) <= v) active_.resize(v + 1, 0), in_grid_.resize(v + 1, 0);
      if (active_[v]++ == 0 && !in_grid_[v]) nodes_grid_.insert(v, P_[v], P_[v], (hi - lo).maxCoeff()), in_grid_[v] = 1;
    }
    ++count_;
    return id;
  }
  void kill(int id) {
    if (!alive_[id]) return;
    alive_[id] = 0;
    index_.erase(key_of(faces_[id][0], faces_[id][1], faces_[id][2]));
    for (int v : faces_[id]) --active_[v];
    --count_;
  }
  bool alive(int id) const { return alive_[id]; }
  const Tri& face(int id) const { return faces_[id]; }
  long size() const { return count_; }
  int& fails(int id) { return fails_[id]; }
  bool active(int v) const { return v < static_cast<int>(active_.size()) && active_[v] > 0; }
  void faces_near(const Vec3& lo, const Vec3& hi, std::vector<int>& out) {
    out.clear();
    if (face_stamp_.size() < faces_.size()) face_stamp_.resize(faces_.size() + faces_.size() / 2 + 16, 0);
    faces_grid_.query(
        lo, hi, out, [&](int f) { return alive_[f] != 0; }, face_stamp_, ++face_ticket_);
  }
  /// Active front nodes in the box. A node that left the front may come back (a removed
  /// tet), so nodes stay in the grid and are filtered here, not dropped.
  void nodes_near(const Vec3& lo, const Vec3& hi, std::vector<int>& out) {
    out.clear();
    if (node_stamp_.size() < P_.size()) node_stamp_.resize(P_.size() + P_.size() / 2 + 16, 0);
    nodes_grid_.query(
        lo, hi, out, [&](int v) { return in_grid_keep(v); }, node_stamp_, ++node_ticket_);
    out.erase(std::remove_if(out.begin(), out.end(), [&](int v) { return !active(v); }), out.end());
  }
  int any_alive() const {
    for (size_t i = 0; i < alive_.size(); ++i)
      if (alive_[i]) return static_cast<int>(i);
    return -1;
  }
  size_t capacity() const { return faces_.size(); }

 private:
  std::vector<Vec3>& P_;
  std::vector<Tri> faces_;
  std::vector<char> alive_;
  std::vector<int> fails_;
  std::unordered_map<TriKey, int, TriKeyHash> index_;
  std::vector<int> active_;
  std::vector<char> in_grid_;
  Grid faces_grid_, nodes_grid_;
  long count_ = 0;
  std::vector<unsigned> face_stamp_, node_stamp_;
  unsigned face_ticket_ = 0, node_ticket_ = 0;
  bool in_grid_keep(int v) const { return v < static_cast<int>(in_grid_.size()) && in_grid_[v]; }
};

double tet_rho(const std::vector<Vec3>& P, int a, int b, int c, int d) { return radius_ratio(P[a], P[b], P[c], P[d]); }

/// The tets around each node as one flat array (CSR): tets of node v are
/// items[start[v] .. start[v + 1]). Removed tets (first index < 0) are left out.
struct NodeStars {
  std::vector<int> start, items;
  NodeStars(size_t nodes, const std::vector<std::array<int, 4>>& tets) : start(nodes + 1, 0) {
    for (const auto& t : tets)
      if (t[0] >= 0)
        for (int x : t) ++start[x + 1];
    for (size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    items.resize(start.back());
    std::vector<int> fill(start.begin(), start.end() - 1);
    for (size_t t = 0; t < tets.size(); ++t)
      if (tets[t][0] >= 0)
        for (int x : tets[t]) items[fill[x]++] = static_cast<int>(t);
  }
  const int* begin(int v) const { return items.data() + start[v]; }
  const int* end(int v) const { return items.data() + start[v + 1]; }
  struct Range {
    const int *b, *e;
    const int* begin() const { return b; }
    const int* end() const { return e; }
  };
  Range of(int v) const { return {begin(v), end(v)}; }
};

/// Flips among the new tets (the input's tets and boundary are never touched: a face is only
/// flipped when two new tets share it, an edge only when exactly three new tets close a ring
/// around it). 3-2: an edge surrounded by three tets becomes the triangle of its ring; 2-3:
/// a face shared by two tets becomes the edge joining their apexes. A flip is kept only when
/// it is valid (exact orientation tests) and raises the worst radius ratio of the tets
/// involved. Only tets below `bad` are worked on. Returns the number of flips.
long flip_bad_tets(const std::vector<Vec3>& P, std::vector<std::array<int, 4>>& tets, double bad) {
  long flips = 0;
  auto positive = [&](std::array<int, 4>& t) {  // orients t; false if flat
    const int o = orient3d(P[t[0]].data(), P[t[1]].data(), P[t[2]].data(), P[t[3]].data());
    if (o == 0) return false;
    if (o < 0) std::swap(t[2], t[3]);
    return true;
  };
  auto rho = [&](const std::array<int, 4>& t) { return tet_rho(P, t[0], t[1], t[2], t[3]); };
  for (int sweep = 0; sweep < 4; ++sweep) {
    long here = 0;
    // node stars (CSR): the tets around an edge or a face are found by filtering a star
    const NodeStars stars(P.size(), tets);
    auto has = [&](int t, int x) {
      const auto& v = tets[t];
      return v[0] == x || v[1] == x || v[2] == x || v[3] == x;
    };
    std::vector<int> ring_tets, face_tets;
    auto tets_with = [&](int u, int w, int x, std::vector<int>& out) {  // x < 0: edge (u, w) only
      out.clear();
      for (const int* t = stars.begin(u); t != stars.end(u); ++t)
        if (has(*t, w) && (x < 0 || has(*t, x))) out.push_back(*t);
    };
    std::vector<char> touched(tets.size(), 0);
    // the maps above go stale where a flip happened: nodes of flipped tets are not used
    // again in this sweep
    std::vector<char> locked(P.size(), 0);
    auto lock = [&](std::initializer_list<int> vs) {
      for (int x : vs) locked[x] = 1;
    };
    auto any_locked = [&](std::initializer_list<int> vs) {
      for (int x : vs)
        if (locked[x]) return true;
      return false;
    };
    const size_t n0 = tets.size();
    for (size_t t = 0; t < n0; ++t) {
      if (touched[t] || rho(tets[t]) >= bad) continue;
      const std::array<int, 4> v = tets[t];
      bool done = false;
      // edge removal on each edge of t: the k = 3..7 tets around an inner edge (u, w) are
      // replaced by 2(k - 2) tets over a triangulation of their ring (fans from each ring
      // vertex tried, the best kept); k = 3 is the 3-2 flip
      for (int i = 0; i < 4 && !done; ++i)
        for (int j = i + 1; j < 4 && !done; ++j) {
          tets_with(v[i], v[j], -1, ring_tets);
          const int k = static_cast<int>(ring_tets.size());
          if (k < 3 || k > 7) continue;
          bool free = true;
          for (int r : ring_tets) free &= !touched[r];
          if (!free) continue;
          int u = v[i], w = v[j];
          // the ring in cyclic order: each tet gives the pair of its other two nodes
          std::vector<std::array<int, 2>> pairs;
          for (int r : ring_tets) {
            std::array<int, 2> pr{-1, -1};
            int m = 0;
            for (int x : tets[r])
              if (x != u && x != w) pr[m++] = x;
            pairs.push_back(pr);
          }
          std::vector<int> ring{pairs[0][0], pairs[0][1]};
          std::vector<char> used(k, 0);
          used[0] = 1;
          bool closed = true;
          for (int step = 1; step < k && closed; ++step) {
            closed = false;
            for (int q = 0; q < k; ++q) {
              if (used[q]) continue;
              int nxt = pairs[q][0] == ring.back() ? pairs[q][1] : (pairs[q][1] == ring.back() ? pairs[q][0] : -1);
              if (nxt < 0) continue;
              used[q] = 1, closed = true;
              if (step < k - 1)
                ring.push_back(nxt);
              else
                closed = nxt == ring.front();
              break;
            }
          }
          if (!closed || static_cast<int>(ring.size()) != k) continue;
          bool any = any_locked({u, w});
          for (int x : ring) any |= locked[x] != 0;
          if (any) continue;
          // orient the ring so that (u, w, r_i, r_i+1) are the positive tets
          if (orient3d(P[u].data(), P[w].data(), P[ring[0]].data(), P[ring[1]].data()) < 0)
            std::reverse(ring.begin(), ring.end());
          double before = 1;
          for (int rt : ring_tets) before = std::min(before, rho(tets[rt]));
          std::vector<std::array<int, 4>> best, cand;
          double best_q = before;
          for (int apex = 0; apex < k; ++apex) {
            cand.clear();
            double worst = 1;
            bool ok = true;
            for (int m = 1; m + 1 < k && ok; ++m) {
              const int x = ring[apex], y = ring[(apex + m) % k], z = ring[(apex + m + 1) % k];
              // (x, y, z) runs around the edge like the ring: w above it, u below
              std::array<int, 4> up{x, y, z, w}, down{x, z, y, u};
              ok = orient3d(P[x].data(), P[y].data(), P[z].data(), P[w].data()) > 0 &&
                   orient3d(P[x].data(), P[z].data(), P[y].data(), P[u].data()) > 0;
              if (ok) {
                worst = std::min({worst, rho(up), rho(down)});
                cand.push_back(up), cand.push_back(down);
              }
            }
            if (ok && worst > best_q) best_q = worst, best = cand;
          }
          if (best.empty()) continue;
          for (size_t m = 0; m < best.size(); ++m) {
            if (m < ring_tets.size()) {
              tets[ring_tets[m]] = best[m];
            } else {
              tets.push_back(best[m]);
              touched.push_back(1);
            }
          }
          for (size_t m = best.size(); m < ring_tets.size(); ++m) tets[ring_tets[m]] = {-1, -1, -1, -1};
          for (int rt : ring_tets) touched[rt] = 1;
          lock({u, w});
          for (int x : ring) locked[x] = 1;
          ++here, done = true;
        }
      // 2-3 on each face of t
      for (int fi = 0; fi < 4 && !done; ++fi) {
        const int a = v[kFace[fi][0]], b = v[kFace[fi][1]], c = v[kFace[fi][2]], d = v[fi];
        tets_with(a, b, c, face_tets);
        if (face_tets.size() != 2) continue;
        const int t2 = face_tets[0] == static_cast<int>(t) ? face_tets[1] : face_tets[0];
        if (touched[t2]) continue;
        int e = -1;
        for (int x : tets[t2])
          if (x != a && x != b && x != c) e = x;
        if (e < 0) continue;
        tets_with(d, e, -1, ring_tets);
        if (!ring_tets.empty()) continue;  // the new edge must not exist yet
        if (any_locked({a, b, c, d, e})) continue;
        const int s1 = orient3d(P[d].data(), P[e].data(), P[a].data(), P[b].data());
        const int s2 = orient3d(P[d].data(), P[e].data(), P[b].data(), P[c].data());
        const int s3 = orient3d(P[d].data(), P[e].data(), P[c].data(), P[a].data());
        if (s1 == 0 || s1 != s2 || s2 != s3) continue;
        if (orient3d(P[a].data(), P[b].data(), P[c].data(), P[d].data()) *
                orient3d(P[a].data(), P[b].data(), P[c].data(), P[e].data()) >=
            0)
          continue;
        std::array<int, 4> n1{a, b, d, e}, n2{b, c, d, e}, n3{c, a, d, e};
        if (!positive(n1) || !positive(n2) || !positive(n3)) continue;
        const double before = std::min(rho(tets[t]), rho(tets[t2]));
        if (std::min({rho(n1), rho(n2), rho(n3)}) <= before) continue;
        tets[t] = n1, tets[t2] = n2, tets.push_back(n3);
        touched[t] = touched[t2] = 1;
        touched.push_back(1);
        lock({a, b, c, d, e});
        ++here, done = true;
      }
    }
    tets.erase(std::remove_if(tets.begin(), tets.end(), [](const std::array<int, 4>& x) { return x[0] < 0; }),
               tets.end());
    flips += here;
    if (!here) break;
  }
  return flips;
}

/// Compass search: moves x along ±x, ±y, ±z by `step` while f (which reads x) rises, halving
/// the step when no direction helps, for at most `iterations` tries or until the step is a
/// hundredth of the first. Returns the best f; x ends at its best position.
template <class F>
double compass_maximise(Vec3& x, double step, int iterations, F&& f) {
  double best = f();
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

/// The new nodes (from first_new on) of the tets below `bad`: a compass search for the
/// position that maximises the worst radius ratio around each (steps of a tenth of the local
/// edge length, halved when no direction helps); every tet stays positive.
void compass_search_at_bad_tets(std::vector<Vec3>& P, const std::vector<std::array<int, 4>>& tets,
                                const NodeStars& stars, int first_new, double bad) {
  std::vector<char> seen(P.size(), 0);
  for (size_t t = 0; t < tets.size(); ++t) {
    if (tet_rho(P, tets[t][0], tets[t][1], tets[t][2], tets[t][3]) >= bad) continue;
    for (int v : tets[t]) {
      if (v < first_new || seen[v]) continue;
      seen[v] = 1;
      const NodeStars::Range ts = stars.of(v);
      auto worst_around = [&]() {
        double w = 1;
        for (int q : ts) {
          const auto& x = tets[q];
          if (orient3d(P[x[0]].data(), P[x[1]].data(), P[x[2]].data(), P[x[3]].data()) <= 0) return -1.0;
          w = std::min(w, tet_rho(P, x[0], x[1], x[2], x[3]));
        }
        return w;
      };
      double len = 0;
      int cnt = 0;
      for (int q : ts)
        for (int x : tets[q])
          if (x != v) len += (P[x] - P[v]).norm(), ++cnt;
      if (!cnt) continue;
      compass_maximise(P[v], 0.1 * len / cnt, 40, worst_around);
    }
  }
}

/// A replacement may not leave more tets below this share of the threshold than it removes.
constexpr double kSliverShare = 0.25;

/// Sliver removal by point insertion: each new tet below `bad` is taken out with its new
/// neighbours across its faces (and, when that is not enough, one more layer of them), and
/// the cavity is filled again as a star from one new point: the point that maximises the
/// worst radius ratio of the star (a compass search from the cavity's centroid), kept only
/// where it sees every cavity face (so the star tiles the cavity exactly), the star's worst
/// tet is better than the cavity's and it has no more slivers (kSliverShare) than the cavity
/// had. Removes what flips cannot: a tet with two faces on the
/// boundary. Input tets and boundary faces stay (they are faces of the star). Returns the
/// number of cavities re-filled.
long insert_points_at_slivers(std::vector<Vec3>& P, std::vector<std::array<int, 4>>& tets, double bad) {
  long done = 0;
  auto rho = [&](const std::array<int, 4>& t) { return tet_rho(P, t[0], t[1], t[2], t[3]); };
  for (int sweep = 0; sweep < 3; ++sweep) {
    const NodeStars stars(P.size(), tets);
    std::vector<char> locked(P.size(), 0), gone(tets.size(), 0);
    std::vector<std::array<int, 4>> added;
    const size_t n0 = tets.size();
    auto neighbours_of = [&](int t, std::vector<int>& out) {
      const auto& v = tets[t];
      for (const auto& o : kFace) {
        const int a = v[o[0]], b = v[o[1]], c = v[o[2]];
        for (const int* q = stars.begin(a); q != stars.end(a); ++q) {
          if (*q == t) continue;
          const auto& w = tets[*q];
          const bool hb = w[0] == b || w[1] == b || w[2] == b || w[3] == b;
          const bool hc = w[0] == c || w[1] == c || w[2] == c || w[3] == c;
          if (hb && hc) out.push_back(*q);
        }
      }
    };
    // worst first: a replacement locks its nodes for the rest of the sweep
    std::vector<std::pair<double, size_t>> order;
    for (size_t t = 0; t < n0; ++t)
      if (tets[t][0] >= 0) {
        const double r = rho(tets[t]);
        if (r < bad) order.push_back({r, t});
      }
    std::sort(order.begin(), order.end());
    for (const auto& [r0, t] : order) {
      if (gone[t]) continue;
      bool skip = false;
      for (int x : tets[t]) skip |= locked[x] != 0;
      if (skip) continue;
      // candidate cavities: the tets around each of its edges, then the tet with its face
      // neighbours, then one more layer; the best star over all of them is kept
      std::vector<std::vector<int>> options;
      const auto v = tets[t];
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          std::vector<int> ring;
          for (const int* q = stars.begin(v[i]); q != stars.end(v[i]); ++q) {
            const auto& w = tets[*q];
            if (w[0] == v[j] || w[1] == v[j] || w[2] == v[j] || w[3] == v[j]) ring.push_back(*q);
          }
          options.push_back(ring);
        }
      {
        std::vector<int> layer{static_cast<int>(t)};
        for (int l = 0; l < 2; ++l) {
          std::vector<int> more;
          for (int c : layer) neighbours_of(c, more);
          layer.insert(layer.end(), more.begin(), more.end());
          std::sort(layer.begin(), layer.end());
          layer.erase(std::unique(layer.begin(), layer.end()), layer.end());
          options.push_back(layer);
        }
      }
      double best_gain = 0, best_score = -1;
      std::vector<int> best_cavity;
      std::vector<Tri> best_faces;
      Vec3 best_x;
      for (std::vector<int>& cavity : options) {
        std::sort(cavity.begin(), cavity.end());
        bool usable = !cavity.empty();
        double old_worst = 1;
        int old_bad = 0;
        for (int c : cavity) {
          usable &= !gone[c];
          for (int x : tets[c]) usable &= !locked[x];
          const double r = rho(tets[c]);
          old_worst = std::min(old_worst, r);
          old_bad += r < kSliverShare * bad;
        }
        if (!usable) continue;
        // the cavity's faces (outward), those used by one of its tets
        std::unordered_map<TriKey, std::pair<int, Tri>, TriKeyHash> count;
        for (int c : cavity)
          for (const auto& o : kFace) {
            const Tri f{tets[c][o[0]], tets[c][o[1]], tets[c][o[2]]};
            auto [it, fresh] = count.emplace(key_of(f[0], f[1], f[2]), std::make_pair(1, f));
            if (!fresh) ++it->second.first;
          }
        std::vector<Tri> faces;
        Vec3 centre = Vec3::Zero();
        double len = 0;
        for (const auto& [k, cf] : count)
          if (cf.first == 1) {
            faces.push_back(cf.second);
            for (int x : cf.second) centre += P[x];
            len += (P[cf.second[0]] - P[cf.second[1]]).norm();
          }
        if (faces.empty()) continue;
        centre /= 3.0 * static_cast<double>(faces.size());
        len /= static_cast<double>(faces.size());
        // score of the star from x: its worst radius ratio where x sees every face (kFace gives
        // each face outward from its tet, so a star tet (f, x) is positive when x is inside);
        // elsewhere -1 plus the most negative height of x over a face (in units of the mean
        // edge), which leads the search into the cavity's kernel
        P.push_back(centre);
        const int id = static_cast<int>(P.size()) - 1;
        auto star_score = [&]() {
          double w = 1, hmin = 0;
          bool sees = true;
          for (const Tri& f : faces) {
            if (orient3d(P[f[0]].data(), P[f[2]].data(), P[f[1]].data(), P[id].data()) <= 0) {
              const Vec3 n = (P[f[2]] - P[f[0]]).cross(P[f[1]] - P[f[0]]);
              const double nn = n.norm();
              hmin = std::min(hmin, nn > 0 ? n.dot(P[id] - P[f[0]]) / nn : -len);
              sees = false;
            } else if (sees) {
              w = std::min(w, tet_rho(P, f[0], f[2], f[1], id));
            }
          }
          return sees ? w : -1 + std::min(hmin, 0.0) / len - 1e-9;
        };
        const double best = compass_maximise(P[id], 0.15 * len, 100, star_score);
        // and no more slivers (below kSliverShare × bad) than the cavity had: lifting the worst
        // alone could leave more than it removed, for the next sweep to find (on NIST 6 the
        // sweeps grew the tets below 0.1 from 5 500 to 9 000)
        int new_bad = 0;
        if (best > old_worst)
          for (const Tri& f : faces) new_bad += tet_rho(P, f[0], f[2], f[1], id) < kSliverShare * bad;
        if (best > old_worst && new_bad <= old_bad && best - old_worst > best_gain) {
          best_gain = best - old_worst, best_score = best;
          best_cavity = cavity, best_faces = faces, best_x = P[id];
        }
        P.pop_back();
      }
      if (best_cavity.empty()) continue;
      P.push_back(best_x);
      const int id = static_cast<int>(P.size()) - 1;
      for (int c : best_cavity) {
        gone[c] = 1;
        for (int x : tets[c]) locked[x] = 1;
      }
      for (const Tri& f : best_faces) added.push_back({f[0], f[2], f[1], id});
      (void)best_score;
      ++done;
    }
    if (added.empty()) break;
    std::vector<std::array<int, 4>> kept;
    kept.reserve(tets.size() + added.size());
    for (size_t t = 0; t < tets.size(); ++t)
      if (!gone[t] && tets[t][0] >= 0) kept.push_back(tets[t]);
    kept.insert(kept.end(), added.begin(), added.end());
    tets.swap(kept);
  }
  return done;
}

/// Without a size, the size grows from the boundary's edge lengths by this per unit distance
/// (the surface mesher's default gradation, 1.3).
constexpr double kDefaultGrowth = 0.3;
/// The front gives up past this many times the tets its size asks for (expected_tets).
constexpr double kBudgetFactor = 10.0;

/// The bulk is dropped when its tetrahedralisation lacks more than this share of the boundary.
constexpr double kMaxMissingShare = 0.02;

/// The fill itself (fill_volume below retries without the bulk when this fails with it).
/// `budget`: the front stops with a named error past this many tets (a front whose faces keep
/// shrinking instead of closing), 0 for none.
VolumeFillResult fill(const MatX3d& V, const MatX3i& F, const MatX4i& T0, const VolumeFillParams& params, long budget,
                      const Progress& progress) {
  std::vector<Vec3> P(V.rows());
  for (long i = 0; i < V.rows(); ++i) P[i] = V.row(i).transpose();
  if (F.rows() == 0) throw Error(ErrorCode::MeshingFailed, "nothing to fill: the boundary has no triangles");
  // Cell size: the mean boundary edge.
  double mean_edge = 0, min_edge = 1e300;
  Vec3 lo = P[F(0, 0)], hi = lo;
  for (long t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const double l = (P[F(t, k)] - P[F(t, (k + 1) % 3)]).norm();
      mean_edge += l;
      if (l > 0) min_edge = std::min(min_edge, l);
      lo = lo.cwiseMin(P[F(t, k)]), hi = hi.cwiseMax(P[F(t, k)]);
    }
  mean_edge /= 3.0 * F.rows();
  // the finest grid level: the shortest boundary edge (coarser levels double from there)
  Front front(P, std::max(std::min(min_edge, mean_edge), 1e-9 * (hi - lo).norm()), lo);
  std::vector<std::array<int, 4>> tets;

  // ---- the bulk by Delaunay refinement, where the tetrahedralisation of the boundary's
  // nodes holds the boundary; the front fills the rest. The region's boundary: the boundary
  // triangles no existing tet covers, and the existing tets' free faces turned outwards.
  std::unordered_map<TriKey, int, TriKeyHash> covered;  // faces of existing tets, free faces of bulk tets
  std::vector<std::array<int, 3>> bulk_free;
  for (long t = 0; t < T0.rows(); ++t)
    for (const auto& f : kFace) covered[key_of(T0(t, f[0]), T0(t, f[1]), T0(t, f[2]))]++;
  std::unordered_map<TriKey, char, TriKeyHash> boundary;
  for (long t = 0; t < F.rows(); ++t) boundary[key_of(F(t, 0), F(t, 1), F(t, 2))] = 1;
  if (params.delaunay_bulk) {
    std::vector<std::array<int, 3>> region;
    for (long t = 0; t < F.rows(); ++t)
      if (!covered.count(key_of(F(t, 0), F(t, 1), F(t, 2)))) region.push_back({F(t, 0), F(t, 1), F(t, 2)});
    for (long t = 0; t < T0.rows(); ++t)
      for (const auto& f : kFace) {
        const TriKey k = key_of(T0(t, f[0]), T0(t, f[1]), T0(t, f[2]));
        if (covered[k] == 1 && !boundary.count(k)) region.push_back({T0(t, f[0]), T0(t, f[2]), T0(t, f[1])});
      }
    DelaunayBulkParams dp;
    dp.size = params.size;
    dp.max_tets = params.max_tets;
    dp.max_missing_share = kMaxMissingShare;
    DelaunayBulkResult bulk = delaunay_bulk(P, region, dp, progress);
    if (static_cast<long>(bulk.tets.size()) >= params.max_tets)
      throw Error(ErrorCode::TooLarge, "the volume mesh exceeds " + std::to_string(params.max_tets) + " tets");
    if (bulk.gave_up) {
      // a boundary far from Delaunay (e.g. the cocircular squares of a structured face): the
      // holes would be most of the volume, bounded by long flat tets: the front alone does better
      progress.info("volume: the Delaunay tetrahedralisation lacks " + std::to_string(bulk.missing_triangles) + " of " +
                    std::to_string(region.size()) + " boundary triangles; the front fills it alone");
    } else {
      tets = std::move(bulk.tets);
      bulk_free = std::move(bulk.free_faces);  // only these can meet the boundary or T0's faces
      for (const auto& f : bulk_free) covered[key_of(f[0], f[1], f[2])]++;
      progress.info("volume: Delaunay bulk of " + std::to_string(tets.size()) + " tets (" +
                    std::to_string(bulk.points) + " points); the front fills around " +
                    std::to_string(bulk.missing_triangles) + " boundary triangles it did not hold");
    }
  }
  // ---- the initial front: boundary triangles reversed (normals into the region), then the
  // free faces of the existing and bulk tets (outward from them, i.e. into the unfilled region)
  for (long t = 0; t < F.rows(); ++t) {
    if (covered.count(key_of(F(t, 0), F(t, 1), F(t, 2)))) continue;  // covered by a tet
    front.add_face(F(t, 0), F(t, 2), F(t, 1));
  }
  auto add_free_face = [&](int a, int b, int c) {
    const TriKey k = key_of(a, b, c);
    if (covered[k] == 1 && !boundary.count(k)) front.add_face(a, b, c);
  };
  for (long t = 0; t < T0.rows(); ++t)
    for (const auto& f : kFace) add_free_face(T0(t, f[0]), T0(t, f[1]), T0(t, f[2]));
  for (const auto& f : bulk_free) add_free_face(f[0], f[1], f[2]);
  const long bulk_tets = static_cast<long>(tets.size());

  // ---- the driver loop: smallest face first
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  auto face_size = [&](int id) {
    const Tri& f = front.face(id);
    return (P[f[0]] - P[f[1]]).norm() + (P[f[1]] - P[f[2]]).norm() + (P[f[2]] - P[f[0]]).norm();
  };
  for (size_t id = 0; id < front.capacity(); ++id)
    if (front.alive(static_cast<int>(id))) queue.push({face_size(static_cast<int>(id)), static_cast<int>(id)});
  std::vector<int> near_faces, near_nodes;
  std::vector<std::pair<double, int>> candidates;  // (score, node; -1 - k = new_points[k])
  std::vector<std::pair<double, int>> near_by_distance;
  std::vector<unsigned> seen_node;  // stamps for the node test of valid()
  unsigned seen_ticket = 0;
  // (distance to the ideal point, node)
  std::vector<Vec3> new_points;
  const double sqrt23 = std::sqrt(2.0 / 3.0);

  auto valid = [&](int a, int b, int c, int p, double qmin, int self) {
    if (orient3d(P[a].data(), P[b].data(), P[c].data(), P[p].data()) <= 0) return false;
    if (tet_rho(P, a, b, c, p) < qmin) return false;
    Vec3 tlo = P[a].cwiseMin(P[b]).cwiseMin(P[c]).cwiseMin(P[p]),
         thi = P[a].cwiseMax(P[b]).cwiseMax(P[c]).cwiseMax(P[p]);
    Vec3 pad = Vec3::Constant(1e-9 * (thi - tlo).norm());
    front.faces_near(tlo - pad, thi + pad, near_faces);
    // The edges ab, bc, ca are already part of the front and cross nothing: only the new
    // edges against front faces, and front edges against the new faces, need checking.
    const Tri new_faces[3] = {{a, b, p}, {b, c, p}, {c, a, p}};
    const TriKey new_keys[3] = {key_of(a, b, p), key_of(b, c, p), key_of(c, a, p)};
    for (int g : near_faces) {
      if (g == self) continue;
      const Tri& t = front.face(g);
      // boxes apart: nothing to test (exact, on the input doubles)
      {
        bool apart = false;
        for (int k = 0; k < 3 && !apart; ++k) {
          const double flo = std::min({P[t[0]][k], P[t[1]][k], P[t[2]][k]}),
                       fhi = std::max({P[t[0]][k], P[t[1]][k], P[t[2]][k]});
          apart = fhi < tlo[k] || flo > thi[k];
        }
        if (apart) continue;
      }
      TriKey kt = key_of(t[0], t[1], t[2]);
      for (int v : {a, b, c})
        if (segment_meets_triangle(P, v, p, t[0], t[1], t[2])) {
          // an edge of the closing face itself lies on that face: allowed
          bool closing = false;
          for (const TriKey& k : new_keys) closing |= k == kt;
          if (!closing) return false;
        }
      for (int i = 0; i < 3; ++i) {
        if (new_keys[i] == kt) continue;  // closing against that face
        for (int k = 0; k < 3; ++k)
          if (segment_meets_triangle(P, t[k], t[(k + 1) % 3], new_faces[i][0], new_faces[i][1], new_faces[i][2]))
            return false;
      }
    }
    // front nodes inside the new tet: every front node is a corner of a front face, and a
    // node inside the tet's box has its faces' boxes meeting it, so the faces found above
    // hold them all
    if (seen_node.size() < P.size()) seen_node.resize(P.size() + P.size() / 2 + 16, 0);
    ++seen_ticket;
    for (int g : near_faces) {
      for (int q : front.face(g)) {
        if (seen_node[q] == seen_ticket || q == a || q == b || q == c || q == p) continue;
        seen_node[q] = seen_ticket;
        const double* x = P[q].data();
        if (x[0] < tlo[0] - pad[0] || x[0] > thi[0] + pad[0] || x[1] < tlo[1] - pad[1] || x[1] > thi[1] + pad[1] ||
            x[2] < tlo[2] - pad[2] || x[2] > thi[2] + pad[2])
          continue;
        if (orient3d(P[a].data(), P[b].data(), P[c].data(), x) >= 0 &&
            orient3d(P[a].data(), P[b].data(), x, P[p].data()) >= 0 &&
            orient3d(P[b].data(), P[c].data(), x, P[p].data()) >= 0 &&
            orient3d(P[c].data(), P[a].data(), x, P[p].data()) >= 0)
          return false;  // a front node inside (or on) the new tet
      }
    }
    return true;
  };

  const double qmins[] = {params.min_quality, 0.1, 0.02, 1e-4, 0};
  const double reach[] = {1.0, 1.6, 2.5, 4.0, 6.0};
  // Rounds: advance (with widening passes), fill what is left from single points, and if a
  // stuck region remains, remove the new tets around it and advance again.
  for (int round = 0; round < 10 && front.size() > 0; ++round) {
    if (round > 0 && bulk_tets > 0)  // the bulk's holes did not close: fill_volume goes without it
      throw Error(ErrorCode::MeshingFailed, "the front could not close the holes of the Delaunay bulk (" +
                                                std::to_string(front.size()) + " front faces left)");
    if (round > 0) {
      // the new tets around the stuck front's nodes, widened by one ring of nodes every third
      // round, go back to the front
      const NodeStars stars(P.size(), tets);
      std::vector<char> in_region(P.size(), 0);
      std::vector<int> region;
      for (size_t id = 0; id < front.capacity(); ++id)
        if (front.alive(static_cast<int>(id)))
          for (int v : front.face(static_cast<int>(id)))
            if (!in_region[v]) in_region[v] = 1, region.push_back(v);
      for (int ring = 0; ring < (round - 1) / 3; ++ring) {
        const size_t n = region.size();
        for (size_t i = 0; i < n; ++i)
          for (const int* t = stars.begin(region[i]); t != stars.end(region[i]); ++t)
            for (int x : tets[*t])
              if (!in_region[x]) in_region[x] = 1, region.push_back(x);
      }
      std::vector<int> doomed;
      for (int v : region) doomed.insert(doomed.end(), stars.begin(v), stars.end(v));
      std::sort(doomed.begin(), doomed.end());
      doomed.erase(std::unique(doomed.begin(), doomed.end()), doomed.end());
      for (int t : doomed) {
        const auto tv = tets[t];
        for (const auto& o : kFace) front.add_face(tv[o[0]], tv[o[2]], tv[o[1]]);
        tets[t][0] = -1;
      }
      progress.info("advancing front: re-meshing around a stuck region (" + std::to_string(doomed.size()) +
                    " tets removed)");
      for (size_t id = 0; id < front.capacity(); ++id)
        if (front.alive(static_cast<int>(id))) queue.push({face_size(static_cast<int>(id)), static_cast<int>(id)});
    }
    for (int pass = 0; pass < std::max(1, params.passes) + 1 && front.size() > 0; ++pass) {
      const int ip = std::min(pass + round, 4);
      if (pass > 0 || round > 0) {
        progress.info("advancing front: pass " + std::to_string(pass + 1) + " over " + std::to_string(front.size()) +
                      " faces that failed");
        for (size_t id = 0; id < front.capacity(); ++id)
          if (front.alive(static_cast<int>(id))) queue.push({face_size(static_cast<int>(id)), static_cast<int>(id)});
      }
      std::vector<int> deferred;
      while (!queue.empty()) {
        int f = queue.top().second;
        queue.pop();
        if (!front.alive(f)) continue;
        if (static_cast<long>(tets.size()) > params.max_tets)
          throw Error(ErrorCode::TooLarge, "the volume mesh exceeds " + std::to_string(params.max_tets) + " tets");
        if (budget > 0 && static_cast<long>(tets.size()) > budget) {
          const Tri& t = front.face(f);
          const Vec3 c = (P[t[0]] + P[t[1]] + P[t[2]]) / 3.0;
          std::ostringstream s;
          s << "the volume front made " << tets.size() << " tets without closing, far more than the size asks for ("
            << budget << " at most): its faces keep shrinking, e.g. near (" << c.x() << ", " << c.y() << ", " << c.z()
            << "); a coarser or smoother surface mesh there may help";
          throw Error(ErrorCode::MeshingFailed, s.str());
        }
        if (tets.size() % 20000 == 0) progress.check_cancel("volume meshing");
        const Tri face = front.face(f);
        int a = face[0], b = face[1], c = face[2];
        Vec3 n = (P[b] - P[a]).cross(P[c] - P[a]);
        double L = face_size(f) / 3.0;
        Vec3 centre = (P[a] + P[b] + P[c]) / 3.0;
        double h = params.size ? std::clamp(params.size(centre.data()), 0.55 * L, 1.8 * L) : L;
        Vec3 ideal = centre + n.normalized() * h * sqrt23;
        // candidates: front nodes near the ideal point, on the right side. Connecting to an
        // existing node closes the front, so those come first (best quality first); the ideal
        // point is tried last, and only where no front node is already close to it.
        candidates.clear();
        double r = reach[ip] * h;
        front.nodes_near(ideal - Vec3::Constant(r), ideal + Vec3::Constant(r), near_nodes);
        bool crowded = false;
        // the nearest front nodes only (a large face facing a finely meshed region would
        // otherwise weigh thousands of them)
        near_by_distance.clear();
        for (int q : near_nodes) {
          if (q == a || q == b || q == c) continue;
          const double d = (P[q] - ideal).norm();
          if (d <= r) near_by_distance.push_back({d, q});
        }
        constexpr size_t kMaxNodeCandidates = 40;
        if (near_by_distance.size() > kMaxNodeCandidates) {
          std::nth_element(near_by_distance.begin(), near_by_distance.begin() + kMaxNodeCandidates,
                           near_by_distance.end());
          near_by_distance.resize(kMaxNodeCandidates);
        }
        for (const auto& [d, q] : near_by_distance) {
          if (d < 0.7 * h) crowded = true;
          if (orient3d(P[a].data(), P[b].data(), P[c].data(), P[q].data()) <= 0) continue;
          double rho = tet_rho(P, a, b, c, q);
          if (rho < qmins[ip]) continue;
          candidates.push_back({-rho + 0.25 * d / h - 10.0, q});
        }
        // new points: the ideal one; for faces that failed before, also lower ones (a thin
        // cavity, e.g. a twisted prism between the two sides of a thin wall, has room only
        // close to the face)
        new_points.clear();
        if (!crowded || pass > 0) new_points.push_back(ideal);
        if (ip >= 2) new_points.push_back(centre + n.normalized() * h * sqrt23 * 0.5);
        for (size_t k = 0; k < new_points.size(); ++k) {
          P.push_back(new_points[k]);
          double rho = tet_rho(P, a, b, c, static_cast<int>(P.size()) - 1);
          P.pop_back();
          candidates.push_back({-rho + 0.01 * static_cast<double>(k), -1 - static_cast<int>(k)});
        }
        std::sort(candidates.begin(), candidates.end());
        int chosen = -2;
        for (const auto& [score, q] : candidates) {
          int p = q;
          if (q < 0) {
            P.push_back(new_points[-1 - q]);
            p = static_cast<int>(P.size()) - 1;
          }
          if (valid(a, b, c, p, qmins[ip], f)) {
            chosen = p;
            break;
          }
          if (q < 0) P.pop_back();
        }
        if (chosen == -2) {
          deferred.push_back(f);
          continue;
        }
        int p = chosen;
        tets.push_back({a, b, c, p});
        front.kill(f);
        const int tv[4] = {a, b, c, p};
        for (int k = 0; k < 3; ++k) {  // outward faces of (a, b, c, p) other than (a, c, b)
          const int* o = kFace[k];
          int id = front.add_face(tv[o[0]], tv[o[1]], tv[o[2]]);
          if (id >= 0) queue.push({face_size(id), id});
        }
      }
      if (front.size() == 0) break;
    }
    // ---- last resort for small cavities left over: fill each closed component of the front
    // from one point that sees all its faces (the centroid of its nodes, or one of its nodes)
    if (front.size() > 0 && front.size() < 400) {
      std::vector<int> faces;
      for (size_t id = 0; id < front.capacity(); ++id)
        if (front.alive(static_cast<int>(id))) faces.push_back(static_cast<int>(id));
      // components through shared nodes
      std::unordered_map<int, std::vector<int>> by_node;
      for (int f : faces)
        for (int v : front.face(f)) by_node[v].push_back(f);
      std::unordered_map<int, int> comp;
      int ncomp = 0;
      for (int f : faces) {
        if (comp.count(f)) continue;
        std::vector<int> stack{f};
        comp[f] = ncomp;
        while (!stack.empty()) {
          int g = stack.back();
          stack.pop_back();
          for (int v : front.face(g))
            for (int h2 : by_node[v])
              if (!comp.count(h2)) comp[h2] = ncomp, stack.push_back(h2);
        }
        ++ncomp;
      }
      for (int k = 0; k < ncomp; ++k) {
        std::vector<int> cf;
        std::vector<int> cn;
        for (int f : faces)
          if (comp[f] == k) {
            cf.push_back(f);
            for (int v : front.face(f)) cn.push_back(v);
          }
        const size_t first_piece_face = front.capacity();
        for (int grow = 0; grow < 4; ++grow) {
          if (grow > 0) {
            // no point saw the whole cavity: it takes in the new tets behind its faces (a
            // twisted prism between the two sides of a thin wall has no such point; the larger
            // cavity usually has), then the front faces around its nodes are its faces again
            std::unordered_map<TriKey, int, TriKeyHash> owner;
            for (size_t t = 0; t < tets.size(); ++t)
              if (tets[t][0] >= 0)
                for (const auto& o : kFace)
                  owner[key_of(tets[t][o[0]], tets[t][o[1]], tets[t][o[2]])] = static_cast<int>(t);
            int absorbed = 0;
            for (int f : cf) {
              if (!front.alive(f)) continue;
              const Tri& t = front.face(f);
              auto it = owner.find(key_of(t[0], t[1], t[2]));
              if (it == owner.end() || tets[it->second][0] < 0) continue;
              const auto tv = tets[it->second];
              for (const auto& o : kFace) front.add_face(tv[o[0]], tv[o[2]], tv[o[1]]);
              tets[it->second][0] = -1;
              ++absorbed;
            }
            if (!absorbed) break;
            std::vector<char> near(P.size(), 0);
            for (int v : cn) near[v] = 1;
            for (bool more = true; more;) {  // close under shared nodes
              more = false;
              for (size_t id = 0; id < front.capacity(); ++id) {
                if (!front.alive(static_cast<int>(id))) continue;
                const Tri& t = front.face(static_cast<int>(id));
                if (!(near[t[0]] || near[t[1]] || near[t[2]])) continue;
                for (int v : t)
                  if (!near[v]) near[v] = 1, more = true;
              }
            }
            cf.clear(), cn.clear();
            for (size_t id = 0; id < front.capacity(); ++id) {
              if (!front.alive(static_cast<int>(id))) continue;
              const Tri& t = front.face(static_cast<int>(id));
              if (near[t[0]] || near[t[1]] || near[t[2]]) {
                cf.push_back(static_cast<int>(id));
                for (int v : t) cn.push_back(v);
              }
            }
            if (cf.empty()) break;
          }
          std::sort(cn.begin(), cn.end());
          cn.erase(std::unique(cn.begin(), cn.end()), cn.end());
          auto sees_all = [&](int apex) {
            for (int f : cf) {
              const Tri& t = front.face(f);
              if (t[0] == apex || t[1] == apex || t[2] == apex) continue;
              if (orient3d(P[t[0]].data(), P[t[1]].data(), P[t[2]].data(), P[apex].data()) <= 0) return false;
            }
            return true;
          };
          // the apex: among the cavity's nodes, its centroid and points spread over its box, the
          // one that sees every face with the best worst tet
          auto worst_quality = [&](int apex) {
            double w = 1;
            for (int f : cf) {
              const Tri& t = front.face(f);
              if (t[0] != apex && t[1] != apex && t[2] != apex) w = std::min(w, tet_rho(P, t[0], t[1], t[2], apex));
            }
            return w;
          };
          int apex = -1;
          double best = -1;
          for (int v : cn)
            if (sees_all(v) && worst_quality(v) > best) best = worst_quality(v), apex = v;
          Vec3 clo = P[cn[0]], chi = P[cn[0]], centre = Vec3::Zero();
          for (int v : cn) clo = clo.cwiseMin(P[v]), chi = chi.cwiseMax(P[v]), centre += P[v];
          centre /= cn.size();
          Vec3 best_point;
          unsigned seed = 12345;
          for (int trial = 0; trial < 400; ++trial) {
            Vec3 x = centre;
            if (trial > 0)
              for (int d = 0; d < 3; ++d) {
                seed = seed * 1664525u + 1013904223u;
                x[d] = clo[d] + (chi[d] - clo[d]) * ((seed >> 8) & 0xFFFF) / 65535.0;
              }
            P.push_back(x);
            int id = static_cast<int>(P.size()) - 1;
            if (sees_all(id)) {
              double w = worst_quality(id);
              if (w > best) best = w, apex = -2, best_point = x;
            }
            P.pop_back();
          }
          if (apex == -2) {
            P.push_back(best_point);
            apex = static_cast<int>(P.size()) - 1;
          }
          if (apex < 0) {
            progress.info("advancing front: no point sees all " + std::to_string(cf.size()) + " faces of a cavity");
            if (grow < 3) continue;
            // last: fill the cavity in pieces, each from the point (a cavity node, its centroid
            // or a sample of its box) with which the most faces make valid tets, every tet
            // checked against the whole front as in the advancing loop
            for (int piece = 0; piece < 10; ++piece) {
              std::vector<int> live;
              for (int f : cf)
                if (front.alive(f)) live.push_back(f);
              // faces born in this cavity join it
              for (size_t id = first_piece_face; id < front.capacity(); ++id)
                if (front.alive(static_cast<int>(id))) live.push_back(static_cast<int>(id));
              std::sort(live.begin(), live.end());
              live.erase(std::unique(live.begin(), live.end()), live.end());
              if (live.empty()) break;
              std::vector<int> nodes;
              Vec3 lo3 = P[front.face(live[0])[0]], hi3 = lo3, mid3 = Vec3::Zero();
              for (int f : live)
                for (int v : front.face(f))
                  nodes.push_back(v), lo3 = lo3.cwiseMin(P[v]), hi3 = hi3.cwiseMax(P[v]), mid3 += P[v];
              mid3 /= static_cast<double>(3 * live.size());
              std::sort(nodes.begin(), nodes.end());
              nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
              std::vector<Vec3> trial{mid3};
              unsigned sd = 777u + static_cast<unsigned>(piece);
              for (int q = 0; q < 30; ++q) {
                Vec3 x;
                for (int d = 0; d < 3; ++d) {
                  sd = sd * 1664525u + 1013904223u;
                  x[d] = lo3[d] + (hi3[d] - lo3[d]) * ((sd >> 8) & 0xFFFF) / 65535.0;
                }
                trial.push_back(x);
              }
              int best_count = 0, best_node = -1;
              Vec3 best_x;
              auto count_valid = [&](int p) {
                int c = 0;
                for (int f : live) {
                  const Tri& t = front.face(f);
                  if (t[0] != p && t[1] != p && t[2] != p && valid(t[0], t[1], t[2], p, 0.0, f)) ++c;
                }
                return c;
              };
              for (int v : nodes) {
                const int c = count_valid(v);
                if (c > best_count) best_count = c, best_node = v;
              }
              for (const Vec3& x : trial) {
                P.push_back(x);
                const int c = count_valid(static_cast<int>(P.size()) - 1);
                P.pop_back();
                if (c > best_count) best_count = c, best_node = -2, best_x = x;
              }
              if (best_count == 0) break;
              int p = best_node;
              if (p == -2) P.push_back(best_x), p = static_cast<int>(P.size()) - 1;
              for (int f : live) {
                if (!front.alive(f)) continue;
                const Tri t = front.face(f);
                if (t[0] == p || t[1] == p || t[2] == p || !valid(t[0], t[1], t[2], p, 0.0, f)) continue;
                tets.push_back({t[0], t[1], t[2], p});
                front.kill(f);
                const int tv[4] = {t[0], t[1], t[2], p};
                for (int kf = 0; kf < 3; ++kf) front.add_face(tv[kFace[kf][0]], tv[kFace[kf][1]], tv[kFace[kf][2]]);
              }
            }
            break;
          }
          // every tet checked against the whole front as it is made (the faces gathered for a
          // grown cavity are not always one closed cavity); what is left goes to the next round
          long made = 0;
          for (bool more = true; more;) {
            more = false;
            for (int f : cf) {
              if (!front.alive(f)) continue;
              const Tri t = front.face(f);
              if (t[0] == apex || t[1] == apex || t[2] == apex) continue;
              if (!valid(t[0], t[1], t[2], apex, 0.0, f)) continue;
              tets.push_back({t[0], t[1], t[2], apex});
              front.kill(f);
              const int tv[4] = {t[0], t[1], t[2], apex};
              for (int kf = 0; kf < 3; ++kf) front.add_face(tv[kFace[kf][0]], tv[kFace[kf][1]], tv[kFace[kf][2]]);
              ++made, more = true;
            }
          }
          progress.info("advancing front: filled " + std::to_string(made) + " of a cavity's " +
                        std::to_string(cf.size()) + " faces from one point");
          break;
        }
      }
    }
  }
  if (front.size() > 0) {
    int f = front.any_alive();
    const Tri& t = front.face(f);
    Vec3 c = (P[t[0]] + P[t[1]] + P[t[2]]) / 3.0;
    std::ostringstream s;
    s << "the volume mesh could not be closed: " << front.size() << " front faces remain, e.g. near (" << c.x() << ", "
      << c.y() << ", " << c.z() << "); a finer or smoother surface mesh there may help";
    throw Error(ErrorCode::MeshingFailed, s.str());
  }

  tets.erase(std::remove_if(tets.begin(), tets.end(), [](const std::array<int, 4>& t) { return t[0] < 0; }),
             tets.end());
  // ---- quality: flips of the bad tets, then node smoothing, twice
  const int first_new = static_cast<int>(V.rows());
  for (int round = 0; round < params.quality_rounds; ++round) {
    if (params.flip_below > 0) flip_bad_tets(P, tets, params.flip_below);
    // node smoothing of the new nodes: move to the neighbours' centroid when that improves the
    // worst radius ratio around the node and keeps every tet positive
    if (params.smoothing_iterations > 0 && static_cast<int>(P.size()) > first_new) {
      const NodeStars stars(P.size(), tets);
      for (int it = 0; it < params.smoothing_iterations; ++it)
        for (int v = first_new; v < static_cast<int>(P.size()); ++v) {
          const NodeStars::Range ts = stars.of(v);
          Vec3 sum = Vec3::Zero();
          int n = 0;
          double worst = 1;
          for (int t : ts) {
            worst = std::min(worst, tet_rho(P, tets[t][0], tets[t][1], tets[t][2], tets[t][3]));
            for (int w : tets[t])
              if (w != v) sum += P[w], ++n;
          }
          if (!n) continue;
          Vec3 old = P[v];
          P[v] = sum / n;
          bool ok = true;
          double now = 1;
          for (int t : ts) {
            const auto& q = tets[t];
            if (orient3d(P[q[0]].data(), P[q[1]].data(), P[q[2]].data(), P[q[3]].data()) <= 0) {
              ok = false;
              break;
            }
            now = std::min(now, tet_rho(P, q[0], q[1], q[2], q[3]));
          }
          if (!ok || now < worst) P[v] = old;
        }
      compass_search_at_bad_tets(P, tets, stars, first_new, params.sliver_below);
    }
  }
  // ---- slivers the flips and moves left (e.g. with two faces on the boundary): re-filled
  // from a new point, then one more round of flips
  for (int again = 0; again < 3 && params.sliver_below > 0; ++again) {
    if (insert_points_at_slivers(P, tets, params.sliver_below) == 0) break;
    if (params.flip_below > 0) {
      flip_bad_tets(P, tets, params.sliver_below);
      compass_search_at_bad_tets(P, tets, NodeStars(P.size(), tets), first_new, params.sliver_below);
    }
  }
  // Output: the input nodes as they were, then only the new nodes some tet uses (tets removed
  // by the re-meshing rounds leave theirs behind, and a later point may land on one)
  std::vector<int> renum(P.size(), -1);
  int kept = static_cast<int>(V.rows());
  for (int i = 0; i < kept; ++i) renum[i] = i;
  for (const auto& t : tets)
    for (int x : t)
      if (renum[x] < 0) renum[x] = kept++;
  VolumeFillResult out;
  out.V.resize(kept, 3);
  for (size_t i = 0; i < P.size(); ++i)
    if (renum[i] >= 0) out.V.row(renum[i]) = P[i].transpose();
  out.T.resize(tets.size(), 4);
  for (size_t t = 0; t < tets.size(); ++t)
    out.T.row(t) << renum[tets[t][0]], renum[tets[t][1]], renum[tets[t][2]], renum[tets[t][3]];
  return out;
}

}  // namespace

VolumeFillResult fill_volume(const MatX3d& V, const MatX3i& F, const MatX4i& T0, const VolumeFillParams& given,
                             const Progress& progress) {
  VolumeFillParams params = given;
  if (!params.size && F.rows() > 0) {
    // no size given: graded from the boundary's (and the existing tets') edge lengths up to the
    // longest of them, so that the front does not fill the whole region at its finest edge
    MatX3i faces(F.rows() + 4 * T0.rows(), 3);
    faces.topRows(F.rows()) = F;
    for (long t = 0; t < T0.rows(); ++t)
      for (int k = 0; k < 4; ++k)
        faces.row(F.rows() + 4 * t + k) << T0(t, kFace[k][0]), T0(t, kFace[k][1]), T0(t, kFace[k][2]);
    const std::vector<double> spacing = node_spacing(V, faces);
    const double h = *std::max_element(spacing.begin(), spacing.end());
    auto background = std::make_shared<BackgroundSize>(V, faces, h, kDefaultGrowth);
    params.size = [background](const double* x) { return background->at(x); };
  }
  // the front's budget: many times the tets its size asks for, and room for a fine boundary
  // (the grid resolves the region about as finely as its boundary: 8 cells per triangle, at
  // least 100 k, at most 1 M)
  const long cells = std::clamp(8 * static_cast<long>(F.rows()), 100'000L, 1'000'000L);
  const double expected = params.size ? expected_tets(V, F, params.size, cells) : 0.0;
  const long budget = expected > 0 ? static_cast<long>(kBudgetFactor * expected) + 30 * F.rows() + 100'000 : 0;
  progress.info("volume: the size asks for about " + std::to_string(static_cast<long>(expected)) + " tets");
  if (!params.delaunay_bulk) return fill(V, F, T0, params, budget, progress);
  try {
    return fill(V, F, T0, params, budget, progress);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::MeshingFailed) throw;
    // the bulk's holes left the front a region it could not close: the front alone, from
    // the boundary, is the method this engine was built on
    progress.info(std::string("volume: the front could not close the Delaunay bulk's holes (") + e.what() +
                  "); filling by the front alone");
    VolumeFillParams alone = params;
    alone.delaunay_bulk = false;
    return fill(V, F, T0, alone, budget, progress);
  }
}

}  // namespace topopt::mesh
