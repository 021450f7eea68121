// The 3D front and its spatial search (see tet_front.h).
#include "mesh/volume/tet_front.h"

#include <algorithm>

#include "mesh/core/predicates.h"
#include "mesh/core/tet_quality.h"

namespace topopt::mesh {

using Vec3 = Eigen::Vector3d;
using predicates::orient3d;

namespace {

using Point2 = std::array<double, 2>;

/// The coplanar case of segment_meets_triangle, decided in the plane with the 2D predicate on
/// the projection that keeps the triangle non-degenerate: meet unless separated.
bool coplanar_segment_meets_triangle(const std::vector<Vec3>& P, int u, int v, int x, int y, int z, bool u_shared,
                                     bool v_shared) {
  const Vec3 n = (P[y] - P[x]).cross(P[z] - P[x]);
  int drop = 0;
  n.cwiseAbs().maxCoeff(&drop);
  const int i0 = (drop + 1) % 3, i1 = (drop + 2) % 3;
  auto q = [&](int k) { return Point2{P[k][i0], P[k][i1]}; };
  const Point2 U = q(u), Vv = q(v), X = q(x), Y = q(y), Z = q(z);
  const int o = predicates::orient2d(X.data(), Y.data(), Z.data());
  auto inside = [&](const Point2& p) {
    const int a = predicates::orient2d(X.data(), Y.data(), p.data()) * o,
              b = predicates::orient2d(Y.data(), Z.data(), p.data()) * o,
              c = predicates::orient2d(Z.data(), X.data(), p.data()) * o;
    return a > 0 && b > 0 && c > 0;
  };
  auto crosses = [&](const Point2& a, const Point2& b, const Point2& c, const Point2& d) {  // proper crossing
    const int s1 = predicates::orient2d(a.data(), b.data(), c.data()),
              s2 = predicates::orient2d(a.data(), b.data(), d.data());
    const int s3 = predicates::orient2d(c.data(), d.data(), a.data()),
              s4 = predicates::orient2d(c.data(), d.data(), b.data());
    return s1 * s2 < 0 && s3 * s4 < 0;
  };
  if ((!u_shared && inside(U)) || (!v_shared && inside(Vv))) return true;
  if (crosses(U, Vv, X, Y) || crosses(U, Vv, Y, Z) || crosses(U, Vv, Z, X)) return true;
  const Point2 mid{0.5 * (U[0] + Vv[0]), 0.5 * (U[1] + Vv[1])};
  return inside(mid);
}

/// Are the boxes of triangle t and [lo, hi] apart (exact: comparisons of the input doubles)?
bool boxes_apart(const std::vector<Vec3>& P, const Tri& t, const Vec3& lo, const Vec3& hi) {
  for (int k = 0; k < 3; ++k) {
    const double flo = std::min({P[t[0]][k], P[t[1]][k], P[t[2]][k]}),
                 fhi = std::max({P[t[0]][k], P[t[1]][k], P[t[2]][k]});
    if (fhi < lo[k] || flo > hi[k]) return true;
  }
  return false;
}

}  // namespace

bool segment_meets_triangle(const std::vector<Vec3>& P, int u, int v, int x, int y, int z) {
  const bool u_shared = u == x || u == y || u == z, v_shared = v == x || v == y || v == z;
  if (u_shared && v_shared) return false;  // the segment is an edge of the triangle
  // separated boxes: no predicate needed (exact: comparisons of the input doubles)
  for (int k = 0; k < 3; ++k) {
    const double slo = std::min(P[u][k], P[v][k]), shi = std::max(P[u][k], P[v][k]);
    const double tlo = std::min({P[x][k], P[y][k], P[z][k]}), thi = std::max({P[x][k], P[y][k], P[z][k]});
    if (shi < tlo || slo > thi) return false;
  }
  const double *pu = P[u].data(), *pv = P[v].data(), *px = P[x].data(), *py = P[y].data(), *pz = P[z].data();
  const int su = u_shared ? 0 : orient3d(px, py, pz, pu), sv = v_shared ? 0 : orient3d(px, py, pz, pv);
  if (su == sv && su != 0) return false;
  if (su == 0 && sv == 0) return coplanar_segment_meets_triangle(P, u, v, x, y, z, u_shared, v_shared);
  // the segment crosses (or touches) the plane: where does the line pass the triangle?
  const int a = orient3d(pu, pv, px, py), b = orient3d(pu, pv, py, pz), c = orient3d(pu, pv, pz, px);
  const bool hit = (a >= 0 && b >= 0 && c >= 0) || (a <= 0 && b <= 0 && c <= 0);
  if (!hit) return false;
  // contact only at a shared vertex: the touching endpoint is that vertex
  if (su == 0 && u_shared) return false;
  if (sv == 0 && v_shared) return false;
  return true;
}

TetFront::TetFront(const std::vector<Vec3>& P, double cell, const Vec3& origin)
    : P_(P), faces_grid_(origin.data(), cell), nodes_grid_(origin.data(), cell) {}

int TetFront::add_face(int a, int b, int c) {
  const FaceKey k = face_key(a, b, c);
  auto it = index_.find(k);
  if (it != index_.end()) {  // the opposite face is already on the front: both close
    kill(it->second);
    return -1;
  }
  const int id = static_cast<int>(faces_.size());
  faces_.push_back({a, b, c});
  alive_.push_back(1);
  index_.emplace(k, id);
  const Vec3 lo = P_[a].cwiseMin(P_[b]).cwiseMin(P_[c]), hi = P_[a].cwiseMax(P_[b]).cwiseMax(P_[c]);
  faces_grid_.insert(id, lo.data(), hi.data());
  for (int v : {a, b, c}) {
    if (static_cast<int>(active_.size()) <= v) active_.resize(v + 1, 0), in_grid_.resize(v + 1, 0);
    // a node that left the front may come back (a removed tet), so nodes stay in the grid
    if (active_[v]++ == 0 && !in_grid_[v])
      nodes_grid_.insert(v, P_[v].data(), P_[v].data(), (hi - lo).maxCoeff()), in_grid_[v] = 1;
  }
  ++count_;
  return id;
}

void TetFront::kill(int id) {
  if (!alive_[id]) return;
  alive_[id] = 0;
  index_.erase(face_key(faces_[id][0], faces_[id][1], faces_[id][2]));
  for (int v : faces_[id]) --active_[v];
  --count_;
}

void TetFront::reopen(const Tet& t) {
  for (const auto& o : kTetFace) add_face(t[o[0]], t[o[2]], t[o[1]]);
}

std::array<int, 3> TetFront::close_with(int f, int p, std::vector<Tet>& tets) {
  const Tri t = faces_[f];
  tets.push_back({t[0], t[1], t[2], p});
  kill(f);
  const int tv[4] = {t[0], t[1], t[2], p};
  std::array<int, 3> added;
  for (int k = 0; k < 3; ++k)  // the tet's outward faces other than (a, c, b): into the region
    added[k] = add_face(tv[kTetFace[k][0]], tv[kTetFace[k][1]], tv[kTetFace[k][2]]);
  return added;
}

std::vector<int> TetFront::alive_faces() const {
  std::vector<int> out;
  for (size_t id = 0; id < faces_.size(); ++id)
    if (alive_[id]) out.push_back(static_cast<int>(id));
  return out;
}

int TetFront::any_alive() const {
  for (size_t i = 0; i < alive_.size(); ++i)
    if (alive_[i]) return static_cast<int>(i);
  return -1;
}

void TetFront::faces_near(const Vec3& lo, const Vec3& hi, std::vector<int>& out) {
  out.clear();
  faces_grid_.query(lo.data(), hi.data(), out, [&](int f) { return alive_[f] != 0; });
}

void TetFront::nodes_near(const Vec3& lo, const Vec3& hi, std::vector<int>& out) {
  out.clear();
  nodes_grid_.query(lo.data(), hi.data(), out, [](int) { return true; });
  out.erase(std::remove_if(out.begin(), out.end(), [&](int v) { return !active(v); }), out.end());
}

bool TetFront::admits(int a, int b, int c, int p, double qmin, int self) {
  const std::vector<Vec3>& P = P_;
  if (orient3d(P[a].data(), P[b].data(), P[c].data(), P[p].data()) <= 0) return false;
  if (radius_ratio(P[a], P[b], P[c], P[p]) < qmin) return false;
  const Vec3 tlo = P[a].cwiseMin(P[b]).cwiseMin(P[c]).cwiseMin(P[p]),
             thi = P[a].cwiseMax(P[b]).cwiseMax(P[c]).cwiseMax(P[p]);
  const Vec3 pad = Vec3::Constant(1e-9 * (thi - tlo).norm());
  faces_near(tlo - pad, thi + pad, near_faces_);
  // The edges ab, bc, ca are already part of the front and cross nothing: only the new edges
  // against front faces, and front edges against the new faces, need checking.
  const Tri new_faces[3] = {{a, b, p}, {b, c, p}, {c, a, p}};
  const FaceKey new_keys[3] = {face_key(a, b, p), face_key(b, c, p), face_key(c, a, p)};
  for (int g : near_faces_) {
    if (g == self) continue;
    const Tri& t = faces_[g];
    if (boxes_apart(P, t, tlo, thi)) continue;
    const FaceKey kt = face_key(t[0], t[1], t[2]);
    const bool closing = kt == new_keys[0] || kt == new_keys[1] || kt == new_keys[2];
    for (int v : {a, b, c})  // an edge of a face the tet closes against lies on it: allowed
      if (!closing && segment_meets_triangle(P, v, p, t[0], t[1], t[2])) return false;
    for (int i = 0; i < 3; ++i) {
      if (new_keys[i] == kt) continue;  // closing against that face
      for (int k = 0; k < 3; ++k)
        if (segment_meets_triangle(P, t[k], t[(k + 1) % 3], new_faces[i][0], new_faces[i][1], new_faces[i][2]))
          return false;
    }
  }
  // front nodes inside the new tet: every front node is a corner of a front face, and a node
  // inside the tet's box has its faces' boxes meeting it, so the faces found above hold them all
  if (seen_node_.size() < P.size()) seen_node_.resize(P.size() + P.size() / 2 + 16, 0);
  if (++seen_ticket_ == 0) std::fill(seen_node_.begin(), seen_node_.end(), 0), seen_ticket_ = 1;
  for (int g : near_faces_)
    for (int q : faces_[g]) {
      if (seen_node_[q] == seen_ticket_ || q == a || q == b || q == c || q == p) continue;
      seen_node_[q] = seen_ticket_;
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
  return true;
}

}  // namespace topopt::mesh
