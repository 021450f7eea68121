// 2D advancing front for partially meshed faces (see face_front.h).
#include "mesh/surface/face_front.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <sstream>
#include <unordered_map>

#include "common/error.h"
#include "mesh/core/predicates.h"

namespace topopt::mesh {
namespace {

using predicates::incircle;
using predicates::orient2d;

inline uint64_t edge_key(int a, int b) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

/// Shape quality of a triangle: 4√3·area / (sum of squared edge lengths); 1 for equilateral.
double quality(const double* a, const double* b, const double* c) {
  const double area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  const double s = (b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (c[0] - b[0]) * (c[0] - b[0]) +
                   (c[1] - b[1]) * (c[1] - b[1]) + (a[0] - c[0]) * (a[0] - c[0]) + (a[1] - c[1]) * (a[1] - c[1]);
  return s > 0 ? 2 * std::sqrt(3.0) * area2 / s : 0;
}

/// The front: directed edges (unmeshed region on the left), their lookup by (a, b), the
/// nodes that can still take triangles, and uniform grids over both for the searches.
class Front {
 public:
  Front(std::vector<double>& xy, double cell, const double* lo) : xy_(xy), cell_(cell) {
    lo_[0] = lo[0];
    lo_[1] = lo[1];
  }
  const double* p(int n) const { return &xy_[2 * n]; }
  int add_node(const double* q) {
    xy_.push_back(q[0]);
    xy_.push_back(q[1]);
    const int n = static_cast<int>(xy_.size() / 2) - 1;
    degree_.push_back(0);
    pending_.push_back(0);
    node_cells_[cell_of(q)].push_back(n);
    return n;
  }
  void register_existing(int n) {
    if (static_cast<int>(degree_.size()) <= n) degree_.resize(n + 1, 0), pending_.resize(n + 1, 0);
    node_cells_[cell_of(p(n))].push_back(n);
  }
  void set_pending(int n) { pending_[n] = 1; }
  void clear_pending(int n) { pending_[n] = 0; }
  bool active(int n) const { return degree_[n] > 0 || pending_[n]; }
  bool pending(int n) const { return pending_[n]; }

  int find(int a, int b) const {
    auto it = lookup_.find(edge_key(a, b));
    return it == lookup_.end() ? -1 : it->second;
  }
  int add_edge(int a, int b) {
    const int id = static_cast<int>(ea_.size());
    ea_.push_back(a);
    eb_.push_back(b);
    alive_.push_back(1);
    fails_.push_back(0);
    lookup_[edge_key(a, b)] = id;
    ++degree_[a];
    ++degree_[b];
    // in every cell its bounding box overlaps, so searches need not widen by the longest edge
    const long i0 = cell_index(std::min(p(a)[0], p(b)[0]) - lo_[0]),
               i1 = cell_index(std::max(p(a)[0], p(b)[0]) - lo_[0]);
    const long j0 = cell_index(std::min(p(a)[1], p(b)[1]) - lo_[1]),
               j1 = cell_index(std::max(p(a)[1], p(b)[1]) - lo_[1]);
    for (long i = i0; i <= i1; ++i)
      for (long j = j0; j <= j1; ++j) edge_cells_[cell_key(i, j)].push_back(id);
    ++alive_count_;
    return id;
  }
  void remove_edge(int id) {
    alive_[id] = 0;
    lookup_.erase(edge_key(ea_[id], eb_[id]));
    --degree_[ea_[id]];
    --degree_[eb_[id]];
    --alive_count_;
  }
  int a(int id) const { return ea_[id]; }
  int b(int id) const { return eb_[id]; }
  bool alive(int id) const { return alive_[id]; }
  int& fails(int id) { return fails_[id]; }
  long alive_count() const { return alive_count_; }

  /// Calls fn(node) for nodes in grid cells within distance r of q (a superset).
  template <class Fn>
  void nodes_near(const double* q, double r, Fn&& fn) const {
    visit(node_cells_, q, r, fn);
  }
  /// Calls fn(edge) for alive edges that pass through cells within r of q (an edge may come
  /// more than once).
  template <class Fn>
  void edges_near(const double* q, double r, Fn&& fn) const {
    visit(edge_cells_, q, r, [&](int e) {
      if (alive_[e]) fn(e);
    });
  }

 private:
  using Cells = std::unordered_map<uint64_t, std::vector<int>>;
  uint64_t cell_key(long i, long j) const { return edge_key(static_cast<int>(i), static_cast<int>(j)); }
  long cell_index(double x) const { return static_cast<long>(std::floor(x / cell_)); }
  uint64_t cell_of(const double* q) const { return cell_key(cell_index(q[0] - lo_[0]), cell_index(q[1] - lo_[1])); }
  template <class Fn>
  void visit(const Cells& cells, const double* q, double r, Fn&& fn) const {
    const long i0 = static_cast<long>(std::floor((q[0] - r - lo_[0]) / cell_)),
               i1 = static_cast<long>(std::floor((q[0] + r - lo_[0]) / cell_));
    const long j0 = static_cast<long>(std::floor((q[1] - r - lo_[1]) / cell_)),
               j1 = static_cast<long>(std::floor((q[1] + r - lo_[1]) / cell_));
    if ((i1 - i0 + 1) * (j1 - j0 + 1) > static_cast<long>(4 * cells.size() + 16)) {
      for (const auto& kv : cells)
        for (int x : kv.second) fn(x);
      return;
    }
    for (long i = i0; i <= i1; ++i)
      for (long j = j0; j <= j1; ++j) {
        auto it = cells.find(cell_key(i, j));
        if (it != cells.end())
          for (int x : it->second) fn(x);
      }
  }

  std::vector<double>& xy_;
  double cell_, lo_[2];
  std::vector<int> ea_, eb_, fails_;
  std::vector<char> alive_;
  std::vector<int> degree_;
  std::vector<char> pending_;
  std::unordered_map<uint64_t, int> lookup_;
  Cells node_cells_, edge_cells_;
  long alive_count_ = 0;
};

/// True if segments p1p2 and q1q2 share a point other than a common endpoint (proper
/// crossings, a point of one in the other's interior, collinear overlaps).
bool segments_conflict(const Front& f, int p1, int p2, int q1, int q2) {
  const double *P1 = f.p(p1), *P2 = f.p(p2), *Q1 = f.p(q1), *Q2 = f.p(q2);
  const int s1 = orient2d(P1, P2, Q1), s2 = orient2d(P1, P2, Q2);
  const int s3 = orient2d(Q1, Q2, P1), s4 = orient2d(Q1, Q2, P2);
  const bool shared = p1 == q1 || p1 == q2 || p2 == q1 || p2 == q2;
  auto between = [](const double* a, const double* b, const double* x) {  // x on segment ab (collinear)
    return std::min(a[0], b[0]) <= x[0] && x[0] <= std::max(a[0], b[0]) && std::min(a[1], b[1]) <= x[1] &&
           x[1] <= std::max(a[1], b[1]);
  };
  if (!shared) {
    if (s1 * s2 < 0 && s3 * s4 < 0) return true;
    if (s1 == 0 && between(P1, P2, Q1)) return true;
    if (s2 == 0 && between(P1, P2, Q2)) return true;
    if (s3 == 0 && between(Q1, Q2, P1)) return true;
    if (s4 == 0 && between(Q1, Q2, P2)) return true;
    return false;
  }
  if ((p1 == q1 && p2 == q2) || (p1 == q2 && p2 == q1)) return false;  // the same edge
  // one shared endpoint: conflict only if collinear and overlapping beyond it
  const int other_q = (q1 == p1 || q1 == p2) ? q2 : q1;
  const int other_p = (p1 == q1 || p1 == q2) ? p2 : p1;
  if (orient2d(P1, P2, f.p(other_q)) == 0 && between(P1, P2, f.p(other_q))) return true;
  if (orient2d(Q1, Q2, f.p(other_p)) == 0 && between(Q1, Q2, f.p(other_p))) return true;
  return false;
}

}  // namespace

FaceFrontResult fill_face(const FaceFrontInput& in, const FaceFrontParams& params, const Progress& progress) {
  const int np = static_cast<int>(in.P.rows());
  std::vector<double> xy(in.P.data(), in.P.data() + 2 * np);
  for (int n = 0; n < np; ++n) xy[2 * n] = in.P(n, 0), xy[2 * n + 1] = in.P(n, 1);
  auto check_node = [&](int n) {
    if (n < 0 || n >= np) throw Error(ErrorCode::InvalidParameter, "face front: a node index is out of range");
  };
  // Directed edges of the initial front: boundary segments, reversed free edges of the
  // pre-placed triangles, both directions of isolated segments; opposite pairs cancel.
  std::vector<std::pair<int, int>> start;
  std::unordered_map<uint64_t, int> count;
  auto push = [&](int a, int b) {
    check_node(a);
    check_node(b);
    auto it = count.find(edge_key(b, a));
    if (it != count.end() && it->second > 0) {
      --it->second;  // cancels with its opposite
      return;
    }
    ++count[edge_key(a, b)];
  };
  for (long k = 0; k < in.boundary.rows(); ++k) push(in.boundary(k, 0), in.boundary(k, 1));
  for (long k = 0; k < in.triangles.rows(); ++k)
    for (int e = 0; e < 3; ++e) push(in.triangles(k, (e + 1) % 3), in.triangles(k, e));
  double total_len = 0;
  long edges = 0;
  for (const auto& kv : count)
    for (int r = 0; r < kv.second; ++r) {
      start.emplace_back(static_cast<int>(kv.first >> 32), static_cast<int>(kv.first & 0xffffffffu));
    }
  for (long k = 0; k < in.segments.rows(); ++k) {
    check_node(in.segments(k, 0));
    check_node(in.segments(k, 1));
    start.emplace_back(in.segments(k, 0), in.segments(k, 1));
    start.emplace_back(in.segments(k, 1), in.segments(k, 0));
  }
  std::sort(start.begin(), start.end());
  if (std::adjacent_find(start.begin(), start.end()) != start.end())
    throw Error(ErrorCode::InvalidParameter, "face front: an edge is given twice in the same direction");
  // Every node of the front needs as many edges in as out (a closed front).
  std::vector<int> balance(np, 0);
  for (auto [a, b] : start) {
    ++balance[a], --balance[b];
    total_len += std::hypot(xy[2 * a] - xy[2 * b], xy[2 * a + 1] - xy[2 * b + 1]);
    ++edges;
  }
  for (int n = 0; n < np; ++n)
    if (balance[n] != 0) {
      std::ostringstream s;
      s << "face front: the boundary is not closed at node " << n << " (" << xy[2 * n] << ", " << xy[2 * n + 1]
        << "); boundary loops must be closed and oriented with the region on their left";
      throw Error(ErrorCode::InvalidParameter, s.str());
    }
  FaceFrontResult out;
  if (start.empty() && in.isolated.empty()) {
    out.P = in.P;
    return out;
  }
  const double mean_len = edges ? total_len / edges : 1.0;
  auto size_at = [&](const double* q) { return params.size ? params.size(q) : mean_len; };
  double lo[2] = {1e300, 1e300};
  for (int n = 0; n < np; ++n) lo[0] = std::min(lo[0], xy[2 * n]), lo[1] = std::min(lo[1], xy[2 * n + 1]);
  Front front(xy, mean_len, lo);
  for (int n = 0; n < np; ++n) front.register_existing(n);
  for (int n : in.isolated) {
    check_node(n);
    front.set_pending(n);
  }
  using Item = std::pair<double, int>;  // (priority, edge)
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  auto length = [&](int e) {
    const double* A = front.p(front.a(e));
    const double* B = front.p(front.b(e));
    return std::hypot(A[0] - B[0], A[1] - B[1]);
  };
  auto enqueue = [&](int e) { queue.emplace(length(e) + 1e6 * mean_len * front.fails(e), e); };
  for (auto [a, b] : start) enqueue(front.add_edge(a, b));
  // Isolated nodes with no edge at all would never be reached if the whole front closed
  // around them first; the "no node inside" test below forbids that.

  std::vector<std::array<int, 3>> tris;
  std::vector<std::pair<double, int>> cand;  // (distance to ideal point, node; -1 = the ideal point)
  long since_progress = 0;
  while (front.alive_count() > 0) {
    if (queue.empty()) throw Error(ErrorCode::Internal, "face front: the queue ran dry with an open front");
    const int e = queue.top().second;
    queue.pop();
    if (!front.alive(e)) continue;
    if (tris.size() % 4096 == 0) progress.check_cancel("face meshing");
    if (static_cast<long>(tris.size()) >= params.max_triangles)
      throw Error(ErrorCode::TooLarge, "face front: more than the allowed number of triangles; raise the mesh size");
    const int a = front.a(e), b = front.b(e);
    const int pass = front.fails(e);
    // copies: a tentative new node below may move the node array
    const double A[2] = {front.p(a)[0], front.p(a)[1]}, B[2] = {front.p(b)[0], front.p(b)[1]};
    const double L = std::hypot(B[0] - A[0], B[1] - A[1]);
    const double mid[2] = {0.5 * (A[0] + B[0]), 0.5 * (A[1] + B[1])};
    const double nrm[2] = {-(B[1] - A[1]) / L, (B[0] - A[0]) / L};  // left normal
    const double d = std::clamp(size_at(mid), 0.55 * L, 1.6 * L);
    const double height = std::sqrt(std::max(d * d - 0.25 * L * L, 0.0625 * L * L));
    const double ideal[2] = {mid[0] + nrm[0] * height, mid[1] + nrm[1] * height};
    const double R = (1.2 + 0.6 * pass) * std::max(d, L);
    const double qmin[] = {0.35, 0.2, 0.08, 0.02, 0.0};
    const double q_floor = qmin[std::min(pass, 4)];
    cand.clear();
    front.nodes_near(ideal, R, [&](int n) {
      if (n == a || n == b || !front.active(n)) return;
      const double* C = front.p(n);
      const double dist = std::hypot(C[0] - ideal[0], C[1] - ideal[1]);
      if (dist <= R && orient2d(A, B, C) > 0) cand.emplace_back(dist, n);
    });
    // A new node only if no front node already sits close to where it would go.
    bool crowded = false;
    for (const auto& c : cand) crowded |= c.first < 0.45 * d;
    if (!crowded && pass < 3) cand.emplace_back(0.5 * d, -1);
    std::sort(cand.begin(), cand.end());
    const double search = R + d;
    int chosen = -1;
    bool made_new = false;
    for (const auto& c : cand) {
      int n = c.second;
      const double* C = n >= 0 ? front.p(n) : ideal;
      if (orient2d(A, B, C) <= 0) continue;
      if (quality(A, B, C) < q_floor) continue;
      // sides (b, c) and (c, a): closing an existing front edge, or new and crossing nothing
      const int bc = n >= 0 ? front.find(b, n) : -1, ca = n >= 0 ? front.find(n, a) : -1;
      if (n >= 0 && ((bc < 0 && front.find(n, b) >= 0) || (ca < 0 && front.find(a, n) >= 0))) continue;
      bool ok = true;
      // no active node inside or on the triangle (other than its corners)
      front.nodes_near(mid, R + d, [&](int x) {
        if (!ok || x == a || x == b || x == n || !front.active(x)) return;
        const double* X = front.p(x);
        if (orient2d(A, B, X) >= 0 && orient2d(B, C, X) >= 0 && orient2d(C, A, X) >= 0) ok = false;
      });
      if (!ok) continue;
      int cn = n;
      if (n < 0) cn = front.add_node(ideal);  // tentatively, removed from consideration if rejected
      front.edges_near(mid, search, [&](int f) {
        if (!ok || f == e) return;
        const int fa = front.a(f), fb = front.b(f);
        if (bc < 0 && segments_conflict(front, b, cn, fa, fb)) ok = false;
        if (ok && ca < 0 && segments_conflict(front, cn, a, fa, fb)) ok = false;
      });
      if (!ok) continue;  // a rejected new point stays behind as an inactive stray, dropped at the end
      chosen = cn;
      made_new = n < 0;
      break;
    }
    if (chosen < 0) {
      if (++front.fails(e) > params.passes) {
        std::ostringstream s;
        s << "the face's advancing front could not be closed near (" << mid[0] << ", " << mid[1]
          << ") in the face's parameters; try a smaller mesh size there";
        throw Error(ErrorCode::MeshingFailed, s.str());
      }
      enqueue(e);
      if (++since_progress > 4 * front.alive_count() + 100)
        throw Error(ErrorCode::MeshingFailed, "the face's advancing front stopped making progress");
      continue;
    }
    (void)made_new;
    since_progress = 0;
    const int c = chosen;
    tris.push_back({a, b, c});
    front.remove_edge(e);
    front.clear_pending(c);
    const int bc = front.find(b, c);
    if (bc >= 0)
      front.remove_edge(bc);
    else
      enqueue(front.add_edge(c, b));
    const int ca = front.find(c, a);
    if (ca >= 0)
      front.remove_edge(ca);
    else
      enqueue(front.add_edge(a, c));
  }
  for (int n : in.isolated)
    if (front.pending(n)) {
      std::ostringstream s;
      s << "face front: isolated node " << n << " lies outside the region to mesh";
      throw Error(ErrorCode::InvalidParameter, s.str());
    }

  // ---- Delaunay flips among the new triangles (input edges are constraints)
  std::unordered_map<uint64_t, char> fixed_edge;
  for (auto [a, b] : start) fixed_edge[edge_key(std::min(a, b), std::max(a, b))] = 1;
  for (long k = 0; k < in.triangles.rows(); ++k)
    for (int e = 0; e < 3; ++e) {
      int a = in.triangles(k, e), b = in.triangles(k, (e + 1) % 3);
      fixed_edge[edge_key(std::min(a, b), std::max(a, b))] = 1;
    }
  auto ukey = [](int a, int b) { return edge_key(std::min(a, b), std::max(a, b)); };
  for (int sweep = 0; sweep < params.flip_sweeps; ++sweep) {
    std::unordered_map<uint64_t, std::pair<int, int>> adj;  // undirected edge -> (tri, tri)
    adj.reserve(tris.size() * 2);
    for (int t = 0; t < static_cast<int>(tris.size()); ++t)
      for (int k = 0; k < 3; ++k) {
        auto& slot = adj.try_emplace(ukey(tris[t][k], tris[t][(k + 1) % 3]), -1, -1).first->second;
        (slot.first < 0 ? slot.first : slot.second) = t;
      }
    std::vector<char> touched(tris.size(), 0);
    int flips = 0;
    for (const auto& [key, pr] : adj) {
      if (pr.second < 0 || fixed_edge.count(key)) continue;
      const int t0 = pr.first, t1 = pr.second;
      if (touched[t0] || touched[t1]) continue;
      const int u = static_cast<int>(key >> 32), v = static_cast<int>(key & 0xffffffffu);
      auto apex = [&](int t) {
        for (int k = 0; k < 3; ++k)
          if (tris[t][k] != u && tris[t][k] != v) return tris[t][k];
        return -1;
      };
      // orient t0 as (p, q, r) with edge p->q shared, apex r; t1's apex s
      int p = -1, q = -1;
      for (int k = 0; k < 3; ++k)
        if ((tris[t0][k] == u && tris[t0][(k + 1) % 3] == v) || (tris[t0][k] == v && tris[t0][(k + 1) % 3] == u))
          p = tris[t0][k], q = tris[t0][(k + 1) % 3];
      const int r = apex(t0), s = apex(t1);
      if (p < 0 || r < 0 || s < 0) continue;
      if (incircle(front.p(p), front.p(q), front.p(r), front.p(s)) <= 0) continue;
      // the flipped pair (r, p, s) and (s, q, r) must both be counter-clockwise
      if (orient2d(front.p(r), front.p(p), front.p(s)) <= 0 || orient2d(front.p(s), front.p(q), front.p(r)) <= 0)
        continue;
      tris[t0] = {r, p, s};
      tris[t1] = {s, q, r};
      touched[t0] = touched[t1] = 1;
      ++flips;
    }
    if (flips == 0) break;
  }

  // ---- Laplacian smoothing of the new nodes, a move kept only if no triangle inverts and
  // the worst quality around the node does not drop
  const int ntot = static_cast<int>(xy.size() / 2);
  std::vector<int> star_ptr(ntot + 1, 0), star;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) ++star_ptr[t[k] + 1];
  for (int n = 0; n < ntot; ++n) star_ptr[n + 1] += star_ptr[n];
  star.resize(star_ptr[ntot]);
  {
    std::vector<int> fill(star_ptr.begin(), star_ptr.end() - 1);
    for (int t = 0; t < static_cast<int>(tris.size()); ++t)
      for (int k = 0; k < 3; ++k) star[fill[tris[t][k]]++] = t;
  }
  std::vector<char> movable(ntot, 0);
  for (int n = np; n < ntot; ++n) movable[n] = star_ptr[n + 1] > star_ptr[n];
  for (const auto& [a, b] : start) movable[a] = movable[b] = 0;  // (input nodes are < np anyway)
  for (int it = 0; it < params.smoothing_iterations; ++it)
    for (int n = np; n < ntot; ++n) {
      if (!movable[n]) continue;
      double c[2] = {0, 0};
      int k = 0;
      for (int j = star_ptr[n]; j < star_ptr[n + 1]; ++j)
        for (int v : tris[star[j]])
          if (v != n) c[0] += xy[2 * v], c[1] += xy[2 * v + 1], ++k;
      c[0] /= k, c[1] /= k;
      const double old[2] = {xy[2 * n], xy[2 * n + 1]};
      auto worst = [&]() {
        double w = 1e300;
        for (int j = star_ptr[n]; j < star_ptr[n + 1]; ++j) {
          const auto& t = tris[star[j]];
          if (orient2d(&xy[2 * t[0]], &xy[2 * t[1]], &xy[2 * t[2]]) <= 0) return -1.0;
          w = std::min(w, quality(&xy[2 * t[0]], &xy[2 * t[1]], &xy[2 * t[2]]));
        }
        return w;
      };
      const double before = worst();
      xy[2 * n] = c[0], xy[2 * n + 1] = c[1];
      if (worst() < before) xy[2 * n] = old[0], xy[2 * n + 1] = old[1];
    }

  // ---- output: drop stray points that no triangle uses (rejected ideal points) at the end
  std::vector<int> remap(ntot, -1);
  for (int n = 0; n < np; ++n) remap[n] = n;
  int next = np;
  for (const auto& t : tris)
    for (int v : t)
      if (remap[v] < 0) remap[v] = next++;
  out.P.resize(next, 2);
  for (int n = 0; n < ntot; ++n)
    if (remap[n] >= 0) out.P(remap[n], 0) = xy[2 * n], out.P(remap[n], 1) = xy[2 * n + 1];
  out.T.resize(static_cast<long>(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) out.T(t, k) = remap[tris[t][k]];
  return out;
}

}  // namespace topopt::mesh
