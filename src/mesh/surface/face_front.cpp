// 2D advancing front for partially meshed faces (see face_front.h).
#include "mesh/surface/face_front.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "common/error.h"
#include "mesh/core/predicates.h"
#include "mesh/core/spatial_grid.h"
#include "mesh/surface/triangle_stars.h"

namespace topopt::mesh {
namespace {

using predicates::incircle;
using predicates::orient2d;
using Edge = std::pair<int, int>;

inline uint64_t edge_key(int a, int b) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}
inline uint64_t undirected_key(int a, int b) { return edge_key(std::min(a, b), std::max(a, b)); }

/// Shape quality of a triangle: 4√3·area / (sum of squared edge lengths); 1 for equilateral.
double quality(const double* a, const double* b, const double* c) {
  const double area2 = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
  const double s = (b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (c[0] - b[0]) * (c[0] - b[0]) +
                   (c[1] - b[1]) * (c[1] - b[1]) + (a[0] - c[0]) * (a[0] - c[0]) + (a[1] - c[1]) * (a[1] - c[1]);
  return s > 0 ? 2 * std::sqrt(3.0) * area2 / s : 0;
}

// ============================================================================ the container

/// The face front: directed edges (unmeshed region on the left), their lookup by (a, b), the
/// nodes that can still take triangles, and a spatial grid over each (mesh/core/spatial_grid.h)
/// for the searches.
class FaceFront {
 public:
  /// xy: the nodes' (u, v), which add_node extends; cell: the grids' finest cells; lo: their
  /// origin.
  FaceFront(std::vector<double>& xy, double cell, const double* lo) : xy_(xy), nodes_(lo, cell), edges_(lo, cell) {}
  const double* p(int n) const { return &xy_[2 * n]; }
  int add_node(const double* q) {
    xy_.push_back(q[0]);
    xy_.push_back(q[1]);
    const int n = static_cast<int>(xy_.size() / 2) - 1;
    degree_.push_back(0);
    pending_.push_back(0);
    nodes_.insert(n, q, q);
    return n;
  }
  void register_existing(int n) {
    if (static_cast<int>(degree_.size()) <= n) degree_.resize(n + 1, 0), pending_.resize(n + 1, 0);
    nodes_.insert(n, p(n), p(n));
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
    // by its bounding box, so searches need not widen by the longest edge
    const double lo[2] = {std::min(p(a)[0], p(b)[0]), std::min(p(a)[1], p(b)[1])};
    const double hi[2] = {std::max(p(a)[0], p(b)[0]), std::max(p(a)[1], p(b)[1])};
    edges_.insert(id, lo, hi);
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
  int fails(int id) const { return fails_[id]; }
  long alive_count() const { return alive_count_; }

  /// Calls fn(node) for the nodes (active or not) in the box of half-side r around q and
  /// maybe a few more (a superset).
  template <class Fn>
  void nodes_near(const double* q, double r, Fn&& fn) const {
    const double lo[2] = {q[0] - r, q[1] - r}, hi[2] = {q[0] + r, q[1] + r};
    nodes_.for_each(lo, hi, fn);
  }
  /// Calls fn(edge) once for each alive edge whose box meets the box of half-side r around q,
  /// and maybe a few more (a superset); dead edges met leave the grid.
  template <class Fn>
  void edges_near(const double* q, double r, Fn&& fn) {
    const double lo[2] = {q[0] - r, q[1] - r}, hi[2] = {q[0] + r, q[1] + r};
    found_.clear();
    edges_.query(lo, hi, found_, [&](int e) { return alive_[e] != 0; });
    for (int e : found_) fn(e);
  }

 private:
  std::vector<double>& xy_;
  SpatialGrid<2> nodes_, edges_;
  std::vector<int> found_;  ///< edges_near's answer
  std::vector<int> ea_, eb_, fails_;
  std::vector<char> alive_;
  std::vector<int> degree_;
  std::vector<char> pending_;
  std::unordered_map<uint64_t, int> lookup_;
  long alive_count_ = 0;
};

/// True if segments p1p2 and q1q2 share a point other than a common endpoint (proper
/// crossings, a point of one in the other's interior, collinear overlaps).
bool segments_conflict(const FaceFront& f, int p1, int p2, int q1, int q2) {
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

// ============================================================================ the initial front

void check_node(const FaceFrontInput& in, int n) {
  if (n < 0 || n >= in.P.rows()) throw Error(ErrorCode::InvalidParameter, "face front: a node index is out of range");
}

/// The directed edges of the initial front, sorted: boundary segments, reversed free edges of
/// the pre-placed triangles (opposite pairs cancel), both directions of isolated segments.
/// Throws Error(InvalidParameter) for a node out of range, an edge given twice in one
/// direction, and a boundary that is not closed (a node with more edges in than out).
std::vector<Edge> initial_edges(const FaceFrontInput& in) {
  std::unordered_map<uint64_t, int> count;
  auto push = [&](int a, int b) {
    check_node(in, a);
    check_node(in, b);
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
  std::vector<Edge> start;
  for (const auto& kv : count)
    for (int r = 0; r < kv.second; ++r)
      start.emplace_back(static_cast<int>(kv.first >> 32), static_cast<int>(kv.first & 0xffffffffu));
  for (long k = 0; k < in.segments.rows(); ++k) {
    check_node(in, in.segments(k, 0));
    check_node(in, in.segments(k, 1));
    start.emplace_back(in.segments(k, 0), in.segments(k, 1));
    start.emplace_back(in.segments(k, 1), in.segments(k, 0));
  }
  std::sort(start.begin(), start.end());
  if (std::adjacent_find(start.begin(), start.end()) != start.end())
    throw Error(ErrorCode::InvalidParameter, "face front: an edge is given twice in the same direction");
  // every node of the front needs as many edges in as out (a closed front)
  std::vector<int> balance(in.P.rows(), 0);
  for (auto [a, b] : start) ++balance[a], --balance[b];
  for (long n = 0; n < in.P.rows(); ++n)
    if (balance[n] != 0) {
      std::ostringstream s;
      s << "face front: the boundary is not closed at node " << n << " (" << in.P(n, 0) << ", " << in.P(n, 1)
        << "); boundary loops must be closed and oriented with the region on their left";
      throw Error(ErrorCode::InvalidParameter, s.str());
    }
  return start;
}

/// Mean length of the edges (1 for none): the grid's cell and the size where none is given.
double mean_length(const FaceFrontInput& in, const std::vector<Edge>& edges) {
  double total = 0;
  for (auto [a, b] : edges) total += std::hypot(in.P(a, 0) - in.P(b, 0), in.P(a, 1) - in.P(b, 1));
  return edges.empty() ? 1.0 : total / static_cast<double>(edges.size());
}

// ============================================================================ the advance

/// Where a front edge would put its triangle's apex, and how far and how strictly to look.
struct Reach {
  double A[2], B[2];  ///< the edge's ends (copies: a tentative new node may move the node array)
  double mid[2];      ///< its middle
  double ideal[2];    ///< the apex of the triangle of the size there
  double d;           ///< that size, within [0.55, 1.6] of the edge's length
  double R;           ///< the search radius around the ideal point, wider each failed pass
  double q_floor;     ///< the lowest shape quality accepted in this pass
};

/// The advancing front's driver: takes the shortest front edge, gathers candidate apexes
/// (front nodes near the ideal point, or the ideal point itself), accepts the first valid
/// triangle and updates the front; an edge that fails is retried later (after every shorter
/// edge) with a wider search and a lower quality bound.
class FaceFill {
 public:
  FaceFill(const FaceFrontInput& in, const FaceFrontParams& params, const std::vector<Edge>& start)
      : params_(params),
        xy_(in.P.data(), in.P.data() + 2 * in.P.rows()),
        mean_len_(mean_length(in, start)),
        front_(xy_, mean_len_, lowest_corner(in).data()) {
    const int np = static_cast<int>(in.P.rows());
    for (int n = 0; n < np; ++n) xy_[2 * n] = in.P(n, 0), xy_[2 * n + 1] = in.P(n, 1);
    for (int n = 0; n < np; ++n) front_.register_existing(n);
    for (int n : in.isolated) {
      check_node(in, n);
      front_.set_pending(n);
    }
    // isolated nodes with no edge at all would never be reached if the whole front closed
    // around them first; the "no node inside" test of free_of_nodes forbids that
    for (auto [a, b] : start) enqueue(front_.add_edge(a, b));
  }

  /// Advances until the front is closed. Throws Error(MeshingFailed) where it cannot close,
  /// Error(TooLarge) past params.max_triangles.
  void run(const Progress& progress) {
    long since_progress = 0, steps = 0;
    while (front_.alive_count() > 0) {
      if (queue_.empty()) throw Error(ErrorCode::Internal, "face front: the queue ran dry with an open front");
      const int e = queue_.top().second;
      queue_.pop();
      if (!front_.alive(e)) continue;
      // by steps, not triangles: a front retrying its edges without adding any is checked too
      if (++steps % 1024 == 0) progress.check_cancel("face meshing");
      if (static_cast<long>(tris_.size()) >= params_.max_triangles)
        throw Error(ErrorCode::TooLarge, "face front: more than the allowed number of triangles; raise the mesh size");
      const Reach g = reach(e);
      gather_candidates(e, g);
      const int c = choose_apex(e, g);
      if (c >= 0) {
        add_triangle(e, c);
        since_progress = 0;
      } else {
        retry_later(e, g);
        if (++since_progress > 4 * front_.alive_count() + 100)
          throw Error(ErrorCode::MeshingFailed, "the face's advancing front stopped making progress");
      }
    }
  }

  /// Throws Error(InvalidParameter) for an isolated node no triangle reached.
  void check_isolated_reached(const std::vector<int>& isolated) const {
    for (int n : isolated)
      if (front_.pending(n)) {
        std::ostringstream s;
        s << "face front: isolated node " << n << " lies outside the region to mesh";
        throw Error(ErrorCode::InvalidParameter, s.str());
      }
  }
  std::vector<double>& points() { return xy_; }
  const std::vector<std::array<int, 3>>& triangles() const { return tris_; }

 private:
  static std::array<double, 2> lowest_corner(const FaceFrontInput& in) {
    std::array<double, 2> lo{1e300, 1e300};
    for (long n = 0; n < in.P.rows(); ++n) lo[0] = std::min(lo[0], in.P(n, 0)), lo[1] = std::min(lo[1], in.P(n, 1));
    return lo;
  }
  double size_at(const double* q) const { return params_.size ? params_.size(q) : mean_len_; }
  double length(int e) const {
    const double* A = front_.p(front_.a(e));
    const double* B = front_.p(front_.b(e));
    return std::hypot(A[0] - B[0], A[1] - B[1]);
  }
  void enqueue(int e) { queue_.emplace(length(e) + 1e6 * mean_len_ * front_.fails(e), e); }

  Reach reach(int e) const {
    Reach g;
    const double *pa = front_.p(front_.a(e)), *pb = front_.p(front_.b(e));
    g.A[0] = pa[0], g.A[1] = pa[1], g.B[0] = pb[0], g.B[1] = pb[1];
    const int pass = front_.fails(e);
    const double L = std::hypot(g.B[0] - g.A[0], g.B[1] - g.A[1]);
    g.mid[0] = 0.5 * (g.A[0] + g.B[0]), g.mid[1] = 0.5 * (g.A[1] + g.B[1]);
    const double nrm[2] = {-(g.B[1] - g.A[1]) / L, (g.B[0] - g.A[0]) / L};  // left normal
    g.d = std::clamp(size_at(g.mid), 0.55 * L, 1.6 * L);
    const double height = std::sqrt(std::max(g.d * g.d - 0.25 * L * L, 0.0625 * L * L));
    g.ideal[0] = g.mid[0] + nrm[0] * height, g.ideal[1] = g.mid[1] + nrm[1] * height;
    g.R = (1.2 + 0.6 * pass) * std::max(g.d, L);
    const double qmin[] = {0.35, 0.2, 0.08, 0.02, 0.0};
    g.q_floor = qmin[std::min(pass, 4)];
    return g;
  }

  // Active front nodes within R of the ideal point on the edge's left, nearest first, and the
  // ideal point itself (node -1) in the first three passes unless a node already sits close.
  void gather_candidates(int e, const Reach& g) {
    const int a = front_.a(e), b = front_.b(e);
    cand_.clear();
    front_.nodes_near(g.ideal, g.R, [&](int n) {
      if (n == a || n == b || !front_.active(n)) return;
      const double* C = front_.p(n);
      const double dist = std::hypot(C[0] - g.ideal[0], C[1] - g.ideal[1]);
      if (dist <= g.R && orient2d(g.A, g.B, C) > 0) cand_.emplace_back(dist, n);
    });
    bool crowded = false;
    for (const auto& c : cand_) crowded |= c.first < 0.45 * g.d;
    if (!crowded && front_.fails(e) < 3) cand_.emplace_back(0.5 * g.d, -1);
    std::sort(cand_.begin(), cand_.end());
  }

  // The first candidate that makes a valid triangle with edge e: counter-clockwise, of the
  // pass's quality, no active node inside, new sides crossing no front edge. Returns its node
  // (the ideal point becomes a new node), or -1.
  int choose_apex(int e, const Reach& g) {
    const int a = front_.a(e), b = front_.b(e);
    for (const auto& c : cand_) {
      const int n = c.second;
      const double* C = n >= 0 ? front_.p(n) : g.ideal;
      if (orient2d(g.A, g.B, C) <= 0) continue;
      if (quality(g.A, g.B, C) < g.q_floor) continue;
      // sides (b, c) and (c, a): closing an existing front edge, or new and crossing nothing
      const int bc = n >= 0 ? front_.find(b, n) : -1, ca = n >= 0 ? front_.find(n, a) : -1;
      if (n >= 0 && ((bc < 0 && front_.find(n, b) >= 0) || (ca < 0 && front_.find(a, n) >= 0))) continue;
      if (!free_of_nodes(a, b, n, C, g)) continue;
      // a new point is added tentatively; if rejected it stays behind as an inactive stray,
      // dropped at the end
      const int cn = n >= 0 ? n : front_.add_node(g.ideal);
      if (new_sides_cross(e, cn, bc < 0, ca < 0, g)) continue;
      return cn;
    }
    return -1;
  }

  // No active node other than the corners inside or on the triangle (A, B, C).
  bool free_of_nodes(int a, int b, int n, const double* C, const Reach& g) const {
    bool ok = true;
    front_.nodes_near(g.mid, g.R + g.d, [&](int x) {
      if (!ok || x == a || x == b || x == n || !front_.active(x)) return;
      const double* X = front_.p(x);
      if (orient2d(g.A, g.B, X) >= 0 && orient2d(g.B, C, X) >= 0 && orient2d(C, g.A, X) >= 0) ok = false;
    });
    return ok;
  }

  // Whether a new side (b, c) or (c, a) of edge e's triangle with apex c meets a front edge.
  bool new_sides_cross(int e, int c, bool new_bc, bool new_ca, const Reach& g) {
    const int a = front_.a(e), b = front_.b(e);
    bool cross = false;
    front_.edges_near(g.mid, g.R + g.d, [&](int f) {
      if (cross || f == e) return;
      const int fa = front_.a(f), fb = front_.b(f);
      if (new_bc && segments_conflict(front_, b, c, fa, fb)) cross = true;
      if (!cross && new_ca && segments_conflict(front_, c, a, fa, fb)) cross = true;
    });
    return cross;
  }

  // The triangle (a, b, c) on edge e: e leaves the front, each other side closes the front
  // edge opposite it or enters the front.
  void add_triangle(int e, int c) {
    const int a = front_.a(e), b = front_.b(e);
    tris_.push_back({a, b, c});
    front_.remove_edge(e);
    front_.clear_pending(c);
    const int bc = front_.find(b, c);
    if (bc >= 0)
      front_.remove_edge(bc);
    else
      enqueue(front_.add_edge(c, b));
    const int ca = front_.find(c, a);
    if (ca >= 0)
      front_.remove_edge(ca);
    else
      enqueue(front_.add_edge(a, c));
  }

  // Edge e found no triangle in this pass: back in the queue behind every edge of fewer
  // fails, or an error after params.passes.
  void retry_later(int e, const Reach& g) {
    if (++front_.fails(e) > params_.passes) {
      std::ostringstream s;
      s << "the face's advancing front could not be closed near (" << g.mid[0] << ", " << g.mid[1]
        << ") in the face's parameters; try a smaller mesh size there";
      throw Error(ErrorCode::MeshingFailed, s.str());
    }
    enqueue(e);
  }

  using Item = std::pair<double, int>;  // (priority, edge)
  const FaceFrontParams& params_;
  std::vector<double> xy_;  ///< every node's (u, v), the input's first
  double mean_len_;
  FaceFront front_;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue_;
  std::vector<std::array<int, 3>> tris_;
  std::vector<std::pair<double, int>> cand_;  ///< (distance to the ideal point, node; -1 = the ideal point)
};

// ============================================================================ after the front

/// Delaunay flips among the new triangles T (#T by 3, counter-clockwise over the points xy):
/// an edge is flipped when the opposite apex lies in the other triangle's circumcircle and
/// both new triangles are counter-clockwise; edges in `fixed` (undirected keys) never flip.
/// At most `sweeps` sweeps, until one flips nothing.
void delaunay_flips(MatX3i& T, const std::vector<double>& xy, const std::unordered_set<uint64_t>& fixed, int sweeps) {
  const int nt = static_cast<int>(T.rows());
  const double* p = xy.data();
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    std::unordered_map<uint64_t, std::pair<int, int>> adj;  // undirected edge -> (tri, tri)
    adj.reserve(nt * 2);
    for (int t = 0; t < nt; ++t)
      for (int k = 0; k < 3; ++k) {
        auto& slot = adj.try_emplace(undirected_key(T(t, k), T(t, (k + 1) % 3)), -1, -1).first->second;
        (slot.first < 0 ? slot.first : slot.second) = t;
      }
    std::vector<char> touched(nt, 0);
    int flips = 0;
    for (const auto& [key, pr] : adj) {
      if (pr.second < 0 || fixed.count(key)) continue;
      const int t0 = pr.first, t1 = pr.second;
      if (touched[t0] || touched[t1]) continue;
      const int u = static_cast<int>(key >> 32), v = static_cast<int>(key & 0xffffffffu);
      auto apex = [&](int t) {
        for (int k = 0; k < 3; ++k)
          if (T(t, k) != u && T(t, k) != v) return T(t, k);
        return -1;
      };
      // orient t0 as (a, b, r) with edge a->b shared, apex r; t1's apex s
      int a = -1, b = -1;
      for (int k = 0; k < 3; ++k)
        if ((T(t0, k) == u && T(t0, (k + 1) % 3) == v) || (T(t0, k) == v && T(t0, (k + 1) % 3) == u))
          a = T(t0, k), b = T(t0, (k + 1) % 3);
      const int r = apex(t0), s = apex(t1);
      if (a < 0 || r < 0 || s < 0) continue;
      if (incircle(p + 2 * a, p + 2 * b, p + 2 * r, p + 2 * s) <= 0) continue;
      // the flipped pair (r, a, s) and (s, b, r) must both be counter-clockwise
      if (orient2d(p + 2 * r, p + 2 * a, p + 2 * s) <= 0 || orient2d(p + 2 * s, p + 2 * b, p + 2 * r) <= 0) continue;
      T.row(t0) << r, a, s;
      T.row(t1) << s, b, r;
      touched[t0] = touched[t1] = 1;
      ++flips;
    }
    if (flips == 0) break;
  }
}

/// Laplacian smoothing of the nodes from `first` on that triangles of T use (the new ones):
/// each to the centre of its neighbours, kept only if no triangle around it inverts and the
/// worst quality there does not drop. `iterations` sweeps.
void smooth_new_nodes(const MatX3i& T, std::vector<double>& xy, int first, int iterations) {
  const int ntot = static_cast<int>(xy.size() / 2);
  const TriangleStars star = triangle_stars(T, T.rows(), ntot);
  auto worst = [&](int n) {  // the worst quality around n, -1 if a triangle is inverted
    double w = 1e300;
    for (const int* t = star.begin(n); t != star.end(n); ++t) {
      const double *a = &xy[2 * T(*t, 0)], *b = &xy[2 * T(*t, 1)], *c = &xy[2 * T(*t, 2)];
      if (orient2d(a, b, c) <= 0) return -1.0;
      w = std::min(w, quality(a, b, c));
    }
    return w;
  };
  for (int it = 0; it < iterations; ++it)
    for (int n = first; n < ntot; ++n) {
      if (star.size(n) == 0) continue;
      double c[2] = {0, 0};
      int k = 0;
      for (const int* t = star.begin(n); t != star.end(n); ++t)
        for (int j = 0; j < 3; ++j)
          if (T(*t, j) != n) c[0] += xy[2 * T(*t, j)], c[1] += xy[2 * T(*t, j) + 1], ++k;
      c[0] /= k, c[1] /= k;
      const double old[2] = {xy[2 * n], xy[2 * n + 1]};
      const double before = worst(n);
      xy[2 * n] = c[0], xy[2 * n + 1] = c[1];
      if (worst(n) < before) xy[2 * n] = old[0], xy[2 * n + 1] = old[1];
    }
}

/// The result: the input points (same indices), then the new nodes the triangles use in the
/// order they first appear (rejected ideal points left behind are dropped), and T renumbered.
FaceFrontResult compact(const std::vector<double>& xy, int np, const MatX3i& T) {
  const int ntot = static_cast<int>(xy.size() / 2);
  std::vector<int> remap(ntot, -1);
  for (int n = 0; n < np; ++n) remap[n] = n;
  int next = np;
  for (long t = 0; t < T.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (remap[T(t, k)] < 0) remap[T(t, k)] = next++;
  FaceFrontResult out;
  out.P.resize(next, 2);
  for (int n = 0; n < ntot; ++n)
    if (remap[n] >= 0) out.P(remap[n], 0) = xy[2 * n], out.P(remap[n], 1) = xy[2 * n + 1];
  out.T.resize(T.rows(), 3);
  for (long t = 0; t < T.rows(); ++t)
    for (int k = 0; k < 3; ++k) out.T(t, k) = remap[T(t, k)];
  return out;
}

/// The edges no flip may change: the initial front's and the pre-placed triangles'.
std::unordered_set<uint64_t> input_edges(const FaceFrontInput& in, const std::vector<Edge>& start) {
  std::unordered_set<uint64_t> fixed;
  for (auto [a, b] : start) fixed.insert(undirected_key(a, b));
  for (long k = 0; k < in.triangles.rows(); ++k)
    for (int e = 0; e < 3; ++e) fixed.insert(undirected_key(in.triangles(k, e), in.triangles(k, (e + 1) % 3)));
  return fixed;
}

}  // namespace

FaceFrontResult fill_face(const FaceFrontInput& in, const FaceFrontParams& params, const Progress& progress) {
  const std::vector<Edge> start = initial_edges(in);
  if (start.empty() && in.isolated.empty()) {
    FaceFrontResult out;
    out.P = in.P;
    return out;
  }
  FaceFill fill(in, params, start);
  fill.run(progress);
  fill.check_isolated_reached(in.isolated);
  const auto& tris = fill.triangles();
  MatX3i T(static_cast<long>(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t) T.row(static_cast<long>(t)) << tris[t][0], tris[t][1], tris[t][2];
  std::vector<double>& xy = fill.points();
  delaunay_flips(T, xy, input_edges(in, start), params.flip_sweeps);
  const int np = static_cast<int>(in.P.rows());
  smooth_new_nodes(T, xy, np, params.smoothing_iterations);
  return compact(xy, np, T);
}

}  // namespace topopt::mesh
