// The last sliver pass on a finished tagged tet mesh (see sliver_pass.h).
#include "mesh/volume/sliver_pass.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <unordered_map>
#include <utility>

#include "common/face_key.h"
#include "mesh/core/predicates.h"
#include "mesh/core/tet_quality.h"
#include "mesh/volume/node_stars.h"
#include "mesh/volume/tet_improve.h"

namespace topopt::mesh {

using Vec3 = Eigen::Vector3d;

namespace {

/// The mesh in the fills' working formats, and the boundary triangles' faces by key: the
/// B-Rep face and the load-pad face in one code (a node may slide only among triangles of
/// one code).
struct Work {
  std::vector<Vec3> P;
  std::vector<Tet> tets;
  std::vector<int> domain;
  std::unordered_map<FaceKey, long long, FaceKeyHash> boundary;
};

double rho(const std::vector<Vec3>& P, const Tet& t) { return radius_ratio(P[t[0]], P[t[1]], P[t[2]], P[t[3]]); }

/// The tets below `floor`, worst first, as (radius ratio, tet); `worst` gets the lowest of all.
std::vector<std::pair<double, int>> tets_below(const Work& w, double floor, double* worst) {
  std::vector<std::pair<double, int>> out;
  double low = 1;
  for (size_t t = 0; t < w.tets.size(); ++t) {
    const double r = rho(w.P, w.tets[t]);
    low = std::min(low, r);
    if (r < floor) out.push_back({r, static_cast<int>(t)});
  }
  std::sort(out.begin(), out.end());
  if (worst) *worst = low;
  return out;
}

/// The code of a face of v's ball seen `count` times there (by tets a and b when twice): a
/// boundary triangle's face code, an interface's pair of domains (negative), or nothing
/// (false: an inner face). `fixed` is set when the face says v may not move (a face not on the
/// boundary seen once, or seen more than twice).
bool face_code(const Work& w, const FaceKey& key, int count, int a, int b, long long& code, bool& fixed) {
  if (count == 1) {
    const auto it = w.boundary.find(key);
    if (it == w.boundary.end()) return fixed = true;
    code = it->second;
    return true;
  }
  if (count > 2) return fixed = true;
  const int da = w.domain[a], db = w.domain[b];
  if (da == db) return false;
  code = -1 - (static_cast<long long>(std::min(da, db)) * 65536 + std::max(da, db));
  return true;
}

/// How node v may move, from its ball: Free when no face of the ball through v is on the
/// boundary or an interface; Plane (with the unit normal) when all such faces carry one code
/// and every node of them lies in the plane of the largest within `tolerance` of its distance
/// from v; Curved (with their area-weighted normal and the B-Rep face in `face`) when they are
/// one face of Ω's boundary but not one plane and `curved` allows it; Fixed otherwise.
NodeFreedom freedom(const Work& w, const Adjacency::Row& ball, int v, double tolerance, bool curved, Vec3& normal,
                    int& face) {
  std::vector<std::pair<FaceKey, int>> faces;
  for (int q : ball)
    for (int f = 0; f < 4; ++f)
      if (w.tets[q][f] != v) {
        const Tet& t = w.tets[q];
        faces.push_back({face_key(t[kTetFace[f][0]], t[kTetFace[f][1]], t[kTetFace[f][2]]), q});
      }
  std::sort(faces.begin(), faces.end());
  std::vector<FaceKey> on;
  long long first = 0;
  for (size_t i = 0, j; i < faces.size(); i = j) {
    for (j = i; j < faces.size() && faces[j].first == faces[i].first; ++j) {
    }
    long long code = 0;
    bool fixed = false;
    const int b = j - i == 2 ? faces[i + 1].second : -1;
    const bool constraint = face_code(w, faces[i].first, static_cast<int>(j - i), faces[i].second, b, code, fixed);
    if (fixed || (constraint && !on.empty() && code != first)) return NodeFreedom::Fixed;
    if (constraint) first = code, on.push_back(faces[i].first);
  }
  if (on.empty()) return NodeFreedom::Free;
  double largest = 0;
  for (const FaceKey& k : on) {
    const Vec3 n = (w.P[k[1]] - w.P[k[0]]).cross(w.P[k[2]] - w.P[k[0]]);
    if (n.norm() > largest) largest = n.norm(), normal = n / n.norm();
  }
  if (!(largest > 0)) return NodeFreedom::Fixed;
  bool flat = true;
  for (const FaceKey& k : on)
    for (int u : k) flat = flat && std::abs((w.P[u] - w.P[v]).dot(normal)) <= tolerance * (w.P[u] - w.P[v]).norm();
  if (flat) return NodeFreedom::Plane;
  face = static_cast<int>(first >> 32);
  if (!curved || face < 1) return NodeFreedom::Fixed;
  Vec3 sum = Vec3::Zero();  // the tangent plane, from the triangles turned alike (out of their tet)
  for (const auto& [key, q] : faces)
    if (std::binary_search(on.begin(), on.end(), key))
      for (int f = 0; f < 4; ++f) {
        const Tet& t = w.tets[q];
        const int a = t[kTetFace[f][0]], b = t[kTetFace[f][1]], c = t[kTetFace[f][2]];
        if (t[f] != v && face_key(a, b, c) == key) sum += (w.P[b] - w.P[a]).cross(w.P[c] - w.P[a]);
      }
  if (!(sum.norm() > 0)) return NodeFreedom::Fixed;
  normal = sum / sum.norm();
  return NodeFreedom::Curved;
}

/// The worst radius ratio of the tets `ball` and how many are below `floor`; -1 when one of
/// them is not positive (exact orientation).
double ball_worst(const Work& w, const Adjacency::Row& ball, double floor, int& below) {
  double worst = 1;
  below = 0;
  for (int q : ball) {
    const Tet& t = w.tets[q];
    if (predicates::orient3d(w.P[t[0]].data(), w.P[t[1]].data(), w.P[t[2]].data(), w.P[t[3]].data()) <= 0) return -1;
    const double r = rho(w.P, t);
    worst = std::min(worst, r);
    below += r < floor;
  }
  return worst;
}

/// The directions a node tries: 16 spread over its (tangent) plane's circle, or 32 over the
/// sphere (tet_improve's Fibonacci lattice) for a free node.
std::vector<Vec3> directions(NodeFreedom kind, const Vec3& normal) {
  if (kind == NodeFreedom::Free) return sphere_directions(32);
  std::vector<Vec3> d;
  const Vec3 e1 = normal.unitOrthogonal(), e2 = normal.cross(e1);
  for (int i = 0; i < 16; ++i) d.push_back(std::cos(M_PI * i / 8) * e1 + std::sin(M_PI * i / 8) * e2);
  return d;
}

/// tet_improve's pattern search for node v along `dirs`, 24 tries, no more of the ball below
/// floor; with `onto`, each point tried is first moved onto the face by it. Moves v and returns
/// true when that lifts the ball's worst tet.
bool move_node(Work& w, const Adjacency::Row& ball, int v, const std::vector<Vec3>& dirs, double floor,
               const std::function<bool(Vec3&)>& onto = {}) {
  PatternSearchParams search;
  search.directions = dirs;
  search.tries = 24;
  search.floor = floor;
  search.onto = onto;
  const NodeMove m = plan_pattern_search(w.P, w.tets, ball, v, search);
  if (m.empty()) return false;
  w.P[v] = m.to;
  return true;
}

/// A free node: the pattern search, then tet_improve's steepest ascent of the ball's worst
/// tet (its active set lifts a node held by two slivers at once) when that leaves no more of
/// the ball below floor. True when v moved.
bool move_free_node(Work& w, const Adjacency& stars, int v, double floor) {
  const Adjacency::Row ball = stars.row(v);
  int below0 = 0, below = 0;
  if (ball_worst(w, ball, floor, below0) < 0) return false;
  bool moved = move_node(w, ball, v, directions(NodeFreedom::Free, Vec3::UnitZ()), floor);
  const NodeMove m = plan_optimise_node(w.P, w.tets, stars, v);
  if (m.empty()) return moved;
  w.P[v] = m.to;
  if (ball_worst(w, ball, floor, below) >= 0 && below <= below0) return true;
  w.P[v] = m.from;
  return moved;
}

/// One round of moves: the Free and Plane nodes of the tets `order`, worst tet first, each
/// node once. Adds to the report's move counts; returns the number of moves.
long move_sliver_nodes(Work& w, const std::vector<std::pair<double, int>>& order, const SliverPassParams& params,
                       SliverPassReport& report) {
  const double floor = params.floor;
  const Adjacency stars = node_stars(w.P.size(), w.tets);
  std::vector<char> seen(w.P.size(), 0);
  long moved = 0;
  for (const auto& [r, t] : order)
    for (int v : w.tets[t]) {
      if (seen[v]) continue;
      seen[v] = 1;
      Vec3 normal(0, 0, 1);
      int face = 0;
      const NodeFreedom kind =
          freedom(w, stars.row(v), v, params.plane_tolerance, bool(params.onto_face), normal, face);
      if (kind == NodeFreedom::Fixed) continue;
      std::function<bool(Vec3&)> onto;
      if (kind == NodeFreedom::Curved) onto = [&params, face](Vec3& x) { return params.onto_face(face, x); };
      const bool moved_v = kind == NodeFreedom::Free
                               ? move_free_node(w, stars, v, floor)
                               : move_node(w, stars.row(v), v, directions(kind, normal), floor, onto);
      if (!moved_v) continue;
      ++moved;
      ++(kind == NodeFreedom::Free ? report.moved_free
                                   : kind == NodeFreedom::Plane ? report.moved_plane : report.moved_curved);
    }
  return moved;
}

/// The tets of `tets` holding node x have a face through x that no other of them holds: x is
/// on the boundary of these tets (Ω's boundary or an interface), and `outward` gets the
/// area-weighted normal of those faces, turned out of the tets.
bool on_boundary_of(const TetSweep& s, int x, Vec3& outward) {
  std::unordered_map<FaceKey, std::pair<int, Vec3>, FaceKeyHash> seen;
  for (int q : s.stars.row(x))
    for (const auto& o : kTetFace) {
      const Tet& t = s.tets[q];
      const int a = t[o[0]], b = t[o[1]], c = t[o[2]];
      if (a != x && b != x && c != x) continue;
      const Vec3 n = (s.P[b] - s.P[a]).cross(s.P[c] - s.P[a]);  // kTetFace turns a face out of its tet
      auto [it, fresh] = seen.emplace(face_key(a, b, c), std::make_pair(1, n));
      if (!fresh) ++it->second.first;
    }
  outward = Vec3::Zero();
  for (const auto& [key, cn] : seen)
    if (cn.first == 1) outward += cn.second;
  return outward.norm() > 0;
}

/// Node splits at the tets of one domain below `floor` (worst first): for each boundary or
/// interface node x of such a tet (the fills and the moves may not take it off its face), the
/// tets of x's ball re-filled as a star from a new inner point (tet_improve's
/// plan_refill_cavity, its search started a tenth of x's mean edge inside, off x's faces).
/// The faces through x stay (each becomes a tet with the new point), so the boundary and the
/// interfaces keep every triangle; the new point takes x's inner edges. This lifts slivers that
/// hold each other around a boundary node that would have to leave its face to free them (on
/// NIST 6 four tets around one node of a B-spline face, no single or joint move on the face
/// lifts them). Each sliver takes the best of its nodes' stars; kept only when it lifts the
/// worst tet and leaves no more of them below floor. Returns the splits made.
long split_boundary_nodes(std::vector<Vec3>& P, std::vector<Tet>& tets, double floor) {
  std::vector<std::pair<double, int>> order;
  for (size_t t = 0; t < tets.size(); ++t)
    if (rho(P, tets[t]) < floor) order.push_back({rho(P, tets[t]), static_cast<int>(t)});
  if (order.empty()) return 0;
  std::sort(order.begin(), order.end());
  TetSweep s(P, tets);
  long splits = 0;
  for (const auto& [r, t] : order) {
    if (s.touched[t]) continue;
    CavityStar best;
    for (int x : tets[t]) {
      Vec3 outward;
      if (s.locked[x] || !on_boundary_of(s, x, outward)) continue;
      const Adjacency::Row ball = s.stars.row(x);
      double len = 0;
      for (int q : ball)
        for (int y : tets[q]) len += (P[y] - P[x]).norm();
      const Vec3 start = P[x] - 0.1 * len / (3.0 * static_cast<double>(ball.size())) * outward.normalized();
      CavityStar star = plan_refill_cavity(s, std::vector<int>(ball.begin(), ball.end()), floor / kSliverShare, &start);
      if (!star.empty() && star.gain > best.gain) best = std::move(star);
    }
    if (best.empty()) continue;
    apply(s, best);
    ++splits;
  }
  if (splits) s.end();
  return splits;
}

/// Edge removal and 2-3 flips (the best, wide: tet_improve's flip_bad_tets), then wider
/// cavities re-filled from one point (remove_tets_below, 2 sweeps: its points are appended) at
/// the tets below floor, then with `split` node splits at the boundary nodes of what is left
/// (split_boundary_nodes), each domain's tets on their own so that no boundary or interface
/// face changes. Domains keep the order of their first tets. Returns the number of changes.
long flip_within_domains(Work& w, double floor, bool split) {
  std::vector<int> order;
  std::vector<std::vector<Tet>> lists;
  for (size_t t = 0; t < w.tets.size(); ++t) {
    const int d = w.domain[t];
    if (d >= static_cast<int>(lists.size())) lists.resize(d + 1);
    if (lists[d].empty()) order.push_back(d);
    lists[d].push_back(w.tets[t]);
  }
  long flips = 0;
  for (int d : order) {
    bool bad = false;
    for (const Tet& t : lists[d]) bad = bad || rho(w.P, t) < floor;
    if (!bad) continue;
    flips += flip_bad_tets(w.P, lists[d], floor, true, true);
    flips += remove_tets_below(w.P, lists[d], floor, 2);
    if (split) flips += split_boundary_nodes(w.P, lists[d], floor);
  }
  if (!flips) return 0;
  w.tets.clear();
  w.domain.clear();
  for (int d : order) {
    w.tets.insert(w.tets.end(), lists[d].begin(), lists[d].end());
    w.domain.insert(w.domain.end(), lists[d].size(), d);
  }
  return flips;
}

Work load(const TetMesh& mesh) {
  Work w;
  w.P.resize(static_cast<size_t>(mesh.V.rows()));
  for (long i = 0; i < mesh.V.rows(); ++i) w.P[i] = mesh.V.row(i).transpose();
  w.tets.resize(static_cast<size_t>(mesh.T.rows()));
  w.domain.resize(static_cast<size_t>(mesh.T.rows()), 0);
  for (long t = 0; t < mesh.T.rows(); ++t) {
    w.tets[t] = {mesh.T(t, 0), mesh.T(t, 1), mesh.T(t, 2), mesh.T(t, 3)};
    if (mesh.domain.size() == mesh.T.rows()) w.domain[t] = mesh.domain[t];
  }
  return w;
}

void add_boundary(Work& w, const TetMesh& mesh) {
  for (long f = 0; f < mesh.F.rows(); ++f) {
    const long long face = mesh.face.size() == mesh.F.rows() ? mesh.face[f] : 0;
    const long long pad = mesh.nd_face.size() == mesh.F.rows() ? mesh.nd_face[f] : 0;
    w.boundary[face_key(mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2))] = face * (1LL << 32) + pad;
  }
}

void store(const Work& w, TetMesh& mesh) {
  mesh.V.resize(static_cast<long>(w.P.size()), 3);
  for (size_t i = 0; i < w.P.size(); ++i) mesh.V.row(static_cast<long>(i)) = w.P[i].transpose();
  mesh.T.resize(static_cast<long>(w.tets.size()), 4);
  mesh.domain.resize(static_cast<long>(w.tets.size()));
  for (size_t t = 0; t < w.tets.size(); ++t) {
    const long r = static_cast<long>(t);
    mesh.T.row(r) << w.tets[t][0], w.tets[t][1], w.tets[t][2], w.tets[t][3];
    mesh.domain[r] = w.domain[t];
  }
}

}  // namespace

SliverPassReport remove_final_slivers(TetMesh& mesh, const SliverPassParams& params) {
  SliverPassReport report;
  Work w = load(mesh);
  std::vector<std::pair<double, int>> order = tets_below(w, params.floor, &report.worst_before);
  report.below_before = report.below_after = static_cast<long>(order.size());
  report.worst_after = report.worst_before;
  if (order.empty()) return report;
  add_boundary(w, mesh);
  for (int round = 0; round < params.rounds && !order.empty(); ++round) {
    move_sliver_nodes(w, order, params, report);
    report.flips += flip_within_domains(w, params.floor, params.split_boundary_nodes);
    const size_t was = order.size();
    order = tets_below(w, params.floor, &report.worst_after);
    if (order.size() >= was) break;  // rounds while the count falls: moves of 1e-6 are not worth another
  }
  report.below_after = static_cast<long>(order.size());
  store(w, mesh);
  return report;
}

}  // namespace topopt::mesh
