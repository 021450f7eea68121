// Small cavities of the volume front filled from single points (see front_cavities.h).
#include "mesh/volume/front_cavities.h"

#include <algorithm>
#include <unordered_map>

#include "mesh/core/predicates.h"
#include "mesh/core/tet_quality.h"

namespace topopt::mesh {

using Vec3 = Eigen::Vector3d;
using predicates::orient3d;

namespace {

bool has(const Tri& t, int x) { return t[0] == x || t[1] == x || t[2] == x; }

/// The nodes of the faces, with repeats.
std::vector<int> nodes_of(const TetFront& front, const std::vector<int>& faces) {
  std::vector<int> nodes;
  for (int f : faces)
    for (int v : front.face(f)) nodes.push_back(v);
  return nodes;
}

/// A point of the box [lo, hi] from the generator state `seed` (a linear congruential
/// generator, so that runs repeat exactly).
Vec3 spread_point(const Vec3& lo, const Vec3& hi, unsigned& seed) {
  Vec3 x;
  for (int d = 0; d < 3; ++d) {
    seed = seed * 1664525u + 1013904223u;
    x[d] = lo[d] + (hi[d] - lo[d]) * ((seed >> 8) & 0xFFFF) / 65535.0;
  }
  return x;
}

/// Closes every live face of `faces` that does not hold p and admits the tet (face, p);
/// returns how many.
long close_faces_with(TetFront& front, std::vector<Tet>& tets, const std::vector<int>& faces, int p) {
  long made = 0;
  for (int f : faces) {
    if (!front.alive(f)) continue;
    const Tri t = front.face(f);
    if (has(t, p) || !front.admits(t[0], t[1], t[2], p, 0.0, f)) continue;
    front.close_with(f, p, tets);
    ++made;
  }
  return made;
}

/// The cavity (faces cf on nodes cn) takes in the tets behind its faces, which go back to the
/// front; then its faces are the live front faces around its nodes, closed under shared
/// nodes. False when no tet was taken in or no face is left.
bool grow_cavity(TetFront& front, const std::vector<Vec3>& P, std::vector<Tet>& tets, std::vector<int>& cf,
                 std::vector<int>& cn) {
  std::unordered_map<FaceKey, int, FaceKeyHash> owner;
  for (size_t t = 0; t < tets.size(); ++t)
    if (tets[t][0] >= 0)
      for (const auto& o : kTetFace) owner[face_key(tets[t][o[0]], tets[t][o[1]], tets[t][o[2]])] = static_cast<int>(t);
  int absorbed = 0;
  for (int f : cf) {
    if (!front.alive(f)) continue;
    const Tri& t = front.face(f);
    auto it = owner.find(face_key(t[0], t[1], t[2]));
    if (it == owner.end() || tets[it->second][0] < 0) continue;
    front.reopen(tets[it->second]);
    tets[it->second][0] = -1;
    ++absorbed;
  }
  if (!absorbed) return false;
  std::vector<char> near(P.size(), 0);
  for (int v : cn) near[v] = 1;
  auto touches = [&](const Tri& t) { return near[t[0]] || near[t[1]] || near[t[2]]; };
  for (bool more = true; more;) {  // close under shared nodes
    more = false;
    for (int id : front.alive_faces())
      if (touches(front.face(id)))
        for (int v : front.face(id))
          if (!near[v]) near[v] = 1, more = true;
  }
  cf.clear();
  for (int id : front.alive_faces())
    if (touches(front.face(id))) cf.push_back(id);
  cn = nodes_of(front, cf);
  return !cf.empty();
}

/// The apex that sees every face of the cavity (faces cf, sorted unique nodes cn) with the
/// best worst tet: one of its nodes, its nodes' centroid or one of 399 points spread over their
/// box (appended to P when chosen); -1 when none sees them all.
int best_apex(const TetFront& front, std::vector<Vec3>& P, const std::vector<int>& cf, const std::vector<int>& cn) {
  auto sees_all = [&](int apex) {
    for (int f : cf) {
      const Tri& t = front.face(f);
      if (has(t, apex)) continue;
      if (orient3d(P[t[0]].data(), P[t[1]].data(), P[t[2]].data(), P[apex].data()) <= 0) return false;
    }
    return true;
  };
  auto worst_quality = [&](int apex) {
    double w = 1;
    for (int f : cf) {
      const Tri& t = front.face(f);
      if (!has(t, apex)) w = std::min(w, radius_ratio(P[t[0]], P[t[1]], P[t[2]], P[apex]));
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
    const Vec3 x = trial > 0 ? spread_point(clo, chi, seed) : centre;
    P.push_back(x);
    const int id = static_cast<int>(P.size()) - 1;
    if (sees_all(id)) {
      const double w = worst_quality(id);
      if (w > best) best = w, apex = -2, best_point = x;
    }
    P.pop_back();
  }
  if (apex == -2) {
    P.push_back(best_point);
    apex = static_cast<int>(P.size()) - 1;
  }
  return apex;
}

/// The last resort: the cavity filled in up to ten pieces, each from the point (a node of its
/// live faces, their centroid or a point spread over their box) with which the most faces
/// make valid tets. Faces born in the cavity since `first_piece_face` join it.
void fill_in_pieces(TetFront& front, std::vector<Vec3>& P, std::vector<Tet>& tets, const std::vector<int>& cf,
                    size_t first_piece_face) {
  for (int piece = 0; piece < 10; ++piece) {
    std::vector<int> live;
    for (int f : cf)
      if (front.alive(f)) live.push_back(f);
    for (size_t id = first_piece_face; id < front.capacity(); ++id)
      if (front.alive(static_cast<int>(id))) live.push_back(static_cast<int>(id));
    std::sort(live.begin(), live.end());
    live.erase(std::unique(live.begin(), live.end()), live.end());
    if (live.empty()) break;
    std::vector<int> nodes = nodes_of(front, live);
    Vec3 lo3 = P[nodes[0]], hi3 = lo3, mid3 = Vec3::Zero();
    for (int v : nodes) lo3 = lo3.cwiseMin(P[v]), hi3 = hi3.cwiseMax(P[v]), mid3 += P[v];
    mid3 /= static_cast<double>(3 * live.size());
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    std::vector<Vec3> trial{mid3};
    unsigned sd = 777u + static_cast<unsigned>(piece);
    for (int q = 0; q < 30; ++q) trial.push_back(spread_point(lo3, hi3, sd));
    auto count_valid = [&](int p) {
      int c = 0;
      for (int f : live) {
        const Tri& t = front.face(f);
        if (!has(t, p) && front.admits(t[0], t[1], t[2], p, 0.0, f)) ++c;
      }
      return c;
    };
    int best_count = 0, best_node = -1;
    Vec3 best_x;
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
    close_faces_with(front, tets, live, p);
  }
}

/// One cavity (faces cf on nodes cn): from one apex, grown up to three times when none sees
/// it whole, in pieces as the last resort.
void close_cavity(TetFront& front, std::vector<Vec3>& P, std::vector<Tet>& tets, std::vector<int> cf,
                  std::vector<int> cn, const Progress& progress) {
  const size_t first_piece_face = front.capacity();
  for (int grow = 0; grow < 4; ++grow) {
    if (grow > 0 && !grow_cavity(front, P, tets, cf, cn)) break;
    std::sort(cn.begin(), cn.end());
    cn.erase(std::unique(cn.begin(), cn.end()), cn.end());
    const int apex = best_apex(front, P, cf, cn);
    if (apex < 0) {
      progress.info("advancing front: no point sees all " + std::to_string(cf.size()) + " faces of a cavity");
      if (grow < 3) continue;
      fill_in_pieces(front, P, tets, cf, first_piece_face);
      break;
    }
    // every tet checked against the whole front as it is made (the faces gathered for a grown
    // cavity are not always one closed cavity); what is left goes to the caller's next round
    long made = 0;
    for (long n = close_faces_with(front, tets, cf, apex); n > 0; n = close_faces_with(front, tets, cf, apex))
      made += n;
    progress.info("advancing front: filled " + std::to_string(made) + " of a cavity's " + std::to_string(cf.size()) +
                  " faces from one point");
    break;
  }
}

}  // namespace

std::vector<std::vector<int>> front_components(const TetFront& front) {
  const std::vector<int> faces = front.alive_faces();
  std::unordered_map<int, std::vector<int>> by_node;
  for (int f : faces)
    for (int v : front.face(f)) by_node[v].push_back(f);
  std::vector<int> comp(front.capacity(), -1);
  int ncomp = 0;
  for (int f : faces) {
    if (comp[f] >= 0) continue;
    std::vector<int> stack{f};
    comp[f] = ncomp;
    while (!stack.empty()) {
      const int g = stack.back();
      stack.pop_back();
      for (int v : front.face(g))
        for (int h : by_node[v])
          if (comp[h] < 0) comp[h] = ncomp, stack.push_back(h);
    }
    ++ncomp;
  }
  std::vector<std::vector<int>> out(ncomp);
  for (int f : faces) out[comp[f]].push_back(f);
  return out;
}

void close_cavities(TetFront& front, std::vector<Vec3>& P, std::vector<Tet>& tets, const Progress& progress) {
  for (const std::vector<int>& cf : front_components(front)) {
    progress.check_cancel("volume meshing (closing cavities)");
    close_cavity(front, P, tets, cf, nodes_of(front, cf), progress);
  }
}

}  // namespace topopt::mesh
