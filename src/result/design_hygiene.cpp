// Design hygiene (see design_hygiene.h).
#include "result/design_hygiene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <set>
#include <sstream>
#include <unordered_map>

#include "common/adjacency.h"
#include "common/face_key.h"
#include "common/number_text.h"
#include "common/triangle_closest.h"
#include "result/iso_surface.h"
#include "result/join_bridges.h"

namespace topopt::result {

namespace {

using Point = Eigen::Vector3d;

/// Union-find over n items with path halving.
struct Groups {
  std::vector<int> parent;
  explicit Groups(long n) : parent(n) {
    for (long i = 0; i < n; ++i) parent[i] = static_cast<int>(i);
  }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void join(int a, int b) { parent[find(a)] = find(b); }
};

Point node(const TetMesh& mesh, int v) { return mesh.V.row(v).transpose(); }

std::string mm3(double v) { return amount_text(v, " mm³"); }

/// Volume, non-design solids, anchoring and centre of each labelled piece of the result shape
/// (labels: level_components at `threshold` of the node densities nd).
struct Pieces {
  std::vector<double> volume;
  std::vector<std::set<int>> nondesign;
  std::vector<char> touch;    // kAnchorSupport | kAnchorLoad of the anchor nodes inside it
  std::vector<Point> centre;  // volume-weighted
};

Pieces measure_pieces(const TetMesh& mesh, const VecXd& nd, double threshold, const VecXi& label, int count,
                      const std::vector<char>& anchors) {
  Pieces p{std::vector<double>(count, 0), std::vector<std::set<int>>(count), std::vector<char>(count, 0),
           std::vector<Point>(count, Point::Zero())};
  for (long t = 0; t < mesh.T.rows(); ++t) {
    const int c = label[t];
    if (c < 0) continue;
    const double v = kept_tet_volume(mesh, nd, threshold, t);
    p.volume[c] += v;
    p.centre[c] += v * tet_centre(mesh, t);
    if (mesh.domain[t] != 0) p.nondesign[c].insert(mesh.domain[t]);
    if (!anchors.empty())
      for (int k = 0; k < 4; ++k)
        if (mesh.domain[t] != 0 || nd[mesh.T(t, k)] >= threshold) p.touch[c] |= anchors[mesh.T(t, k)];
  }
  for (int c = 0; c < count; ++c) p.centre[c] /= std::max(p.volume[c], 1e-300);
  return p;
}

/// What piece_fates looks at of each piece.
std::vector<PieceFacts> facts_of(const Pieces& p) {
  std::vector<PieceFacts> facts(p.volume.size());
  for (size_t c = 0; c < facts.size(); ++c) facts[c] = {p.touch[c], !p.nondesign[c].empty(), p.volume[c]};
  return facts;
}

std::string at(const Point& x) {
  std::ostringstream s;
  s.precision(3);
  s << "around (" << x[0] << ", " << x[1] << ", " << x[2] << ") mm";
  return s.str();
}

/// Sets the design tets of piece c (labels #T, level_components) to void: every tet around a
/// node of the piece inside the level is one of them, so those nodes fall to density 0 and
/// nothing of the piece is left in the node densities.
void remove_piece(const TetMesh& mesh, const VecXi& label, int c, std::vector<char>& solid, VecXd& out) {
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (label[t] == c && mesh.domain[t] == 0) out[t] = 0, solid[t] = 0;
}

/// Why piece c is apart, in words.
std::string apart_because(char touch, bool have_anchors) {
  if (touch & kAnchorLoad) return "carries a load that does not reach the supports";
  if (touch & kAnchorSupport) return "holds a support but no load";
  return have_anchors ? "touches no support and no load" : "lies apart from the largest piece";
}

/// The warning for a piece of `what` (the design, the result surface) taken out.
std::string removed_warning(const std::string& what, double volume, const Point& centre, const std::string& why) {
  return "removed a loose piece of " + what + " (" + mm3(volume) + ", " + at(centre) + "): it " + why;
}

/// The warning for a piece apart but kept (its non-design solids nd_tags, or none).
std::string named_warning(const std::vector<int>& nd_tags, double volume, const Point& centre, const std::string& why) {
  return (nd_tags.empty() ? "a piece of the design" : solids_named(nd_tags)) + " " +
         (nd_tags.size() > 1 ? "are" : "is") +
         " not connected by the design to the rest that carries the loads (a piece of " + mm3(volume) + ", " +
         at(centre) + ", that " + why + "): lower the threshold or raise the volume fraction";
}

/// Takes the pieces of the result shape (at `threshold` of the node densities nd) that carry
/// no load to a support out of the design (out, solid) when they are design material with no
/// load on it, or names their non-design solids; warns when the material carrying loads is
/// itself in several pieces.
void remove_pieces(const TetMesh& mesh, const VecXd& nd, double threshold, const std::vector<char>& anchors,
                   std::vector<char>& solid, VecXd& out, HygieneReport& report) {
  int count = 0;
  const VecXi label = level_components(mesh, nd, threshold, count);
  const Pieces p = measure_pieces(mesh, nd, threshold, label, count, anchors);
  const std::vector<PieceFate> fate = piece_fates(facts_of(p));
  report.pieces = count;
  std::vector<std::string> main_names;
  for (int c = 0; c < count; ++c) {
    const std::vector<int> nd_tags(p.nondesign[c].begin(), p.nondesign[c].end());
    if (fate[c] == PieceFate::Carries) {
      ++report.anchored_pieces;
      main_names.push_back(nd_tags.empty() ? "design material only" : solids_named(nd_tags));
      continue;
    }
    const std::string why = apart_because(p.touch[c], !anchors.empty());
    const bool removed = fate[c] == PieceFate::Removed;
    report.apart.push_back({p.volume[c], nd_tags, removed});
    if (removed) {
      remove_piece(mesh, label, c, solid, out);
      report.warnings.push_back(removed_warning("the design", p.volume[c], p.centre[c], why));
    } else {
      report.warnings.push_back(named_warning(nd_tags, p.volume[c], p.centre[c], why));
    }
  }
  if (report.anchored_pieces > 1) {
    std::string list;
    for (size_t i = 0; i < main_names.size(); ++i) list += (i ? "; " : "") + main_names[i];
    report.warnings.push_back("the design falls apart into " + std::to_string(report.anchored_pieces) +
                              " pieces that each hold supports or loads (" + list +
                              "): check that every load reaches a support; lower the threshold or raise the "
                              "volume fraction");
  }
}

/// Per tet (#T): whether it has a node on a tet labelled c (labels #T) — the void itself and
/// the tets around it.
std::vector<char> touching_label(const TetMesh& mesh, const VecXi& label, int c) {
  std::vector<char> on_piece(mesh.V.rows(), 0);
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (label[t] == c)
      for (int k = 0; k < 4; ++k) on_piece[mesh.T(t, k)] = 1;
  std::vector<char> touches(mesh.T.rows(), 0);
  for (long t = 0; t < mesh.T.rows(); ++t)
    for (int k = 0; k < 4; ++k) touches[t] |= on_piece[mesh.T(t, k)];
  return touches;
}

/// Fills (or counts) the void pieces of the crisp design (void tets, face-connected) that touch
/// no boundary face of the mesh: a filled one becomes solid with the design tets around it at
/// density 1 as well (the solid tets of its wall may hold low densities that would leave a
/// smaller cavity in the node densities). closed (#T) gets the tets of those voids.
void fill_crisp_voids(const TetMesh& mesh, const MatX4i& nb, const HygieneParams& params, std::vector<char>& solid,
                      VecXd& out, HygieneReport& report, std::vector<char>& closed) {
  std::vector<char> empty(solid.size());
  for (size_t t = 0; t < solid.size(); ++t) empty[t] = !solid[t];
  int count = 0;
  const VecXi label = tet_components(nb, empty, count);
  std::vector<char> open(count, 0);
  std::vector<double> volume(count, 0);
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (label[t] < 0) continue;
    volume[label[t]] += tet_volume(mesh, t);
    for (int k = 0; k < 4; ++k) open[label[t]] |= nb(t, k) < 0;
  }
  closed.assign(mesh.T.rows(), 0);
  for (long t = 0; t < mesh.T.rows(); ++t) closed[t] = label[t] >= 0 && !open[label[t]];
  for (int c = 0; c < count; ++c) {
    if (open[c]) continue;
    if (!params.fill_voids) {
      ++report.voids_kept, report.void_volume_kept += volume[c];
      continue;
    }
    ++report.voids_filled, report.void_volume_filled += volume[c];
    const std::vector<char> touches = touching_label(mesh, label, c);
    for (long t = 0; t < mesh.T.rows(); ++t)
      if (touches[t] && mesh.domain[t] == 0) out[t] = 1, solid[t] = 1;
  }
}

/// Fills (or counts) the closed voids of the result shape (at `threshold` of the node
/// densities nd) that the crisp design does not hold (fill_crisp_voids ran first; `counted`,
/// #T: the tets of the closed voids it counted, skipped here): the nodes below the threshold joined by the design tets'
/// edges with both ends below it (a linear field's region below the level in one tet is convex; non-design nodes are
/// solid), a void closed when none of its nodes lies on the mesh boundary (nb: tet neighbours). Filling sets the design
/// tets holding its nodes, and the design tets around those, to density 1, so every node of the void rises to 1. Its
/// volume is what of the tets holding its nodes lies below the level.
void fill_level_voids(const TetMesh& mesh, const MatX4i& nb, const VecXd& nd, double threshold,
                      const HygieneParams& params, const std::vector<char>& counted, std::vector<char>& solid,
                      VecXd& out, HygieneReport& report) {
  const long nv = mesh.V.rows(), nt = mesh.T.rows();
  std::vector<char> empty(nv, 0), open(nv, 0);
  for (long v = 0; v < nv; ++v) empty[v] = nd[v] < threshold;
  for (long t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) {
      if (mesh.domain[t] != 0) empty[mesh.T(t, k)] = 0;
      if (nb(t, k) < 0)
        for (int j : kTetFace[k]) open[mesh.T(t, j)] = 1;
    }
  Groups groups(nv);
  for (long t = 0; t < nt; ++t)
    for (int a = 0; a < 4 && mesh.domain[t] == 0; ++a)
      for (int b = a + 1; b < 4; ++b)
        if (empty[mesh.T(t, a)] && empty[mesh.T(t, b)]) groups.join(mesh.T(t, a), mesh.T(t, b));
  for (long v = 0; v < nv; ++v)
    if (empty[v] && open[v]) open[groups.find(static_cast<int>(v))] = 1;
  std::vector<double> volume(nv, 0.0);  // per void (its root node)
  std::vector<int> root_of(nt, -1);     // the void a design tet holds nodes of
  for (long t = 0; t < nt; ++t)
    for (int k = 0; k < 4 && mesh.domain[t] == 0; ++k)
      if (empty[mesh.T(t, k)]) {
        root_of[t] = groups.find(mesh.T(t, k));
        volume[root_of[t]] += tet_volume(mesh, t) - kept_tet_volume(mesh, nd, threshold, t);
        break;
      }
  for (long t = 0; t < nt; ++t)  // a void the crisp design holds is counted there
    if (root_of[t] >= 0 && counted[t]) open[root_of[t]] = 1;
  for (long v = 0; v < nv; ++v) {
    if (!empty[v] || groups.find(static_cast<int>(v)) != v || open[v]) continue;
    if (!params.fill_voids) {
      ++report.voids_kept, report.void_volume_kept += volume[v];
      continue;
    }
    ++report.voids_filled, report.void_volume_filled += volume[v];
  }
  if (!params.fill_voids) return;
  // the tets holding the void's nodes and the design tets around them (their walls may hold
  // low densities that would leave a smaller cavity in the node densities)
  std::vector<char> near(nv, 0);
  for (long t = 0; t < nt; ++t)
    if (root_of[t] >= 0 && !open[root_of[t]])
      for (int k = 0; k < 4; ++k) near[mesh.T(t, k)] = 1;
  for (long t = 0; t < nt; ++t)
    if (mesh.domain[t] == 0 && (near[mesh.T(t, 0)] || near[mesh.T(t, 1)] || near[mesh.T(t, 2)] || near[mesh.T(t, 3)]))
      out[t] = 1, solid[t] = 1;
}

/// The warnings about filled or kept voids, once for all rounds.
void warn_voids(HygieneReport& report) {
  if (report.voids_filled)
    report.warnings.push_back("filled " + std::to_string(report.voids_filled) + " closed internal void(s) of " +
                              mm3(report.void_volume_filled) +
                              " in all, which no tool or powder could leave (optimization.fill_voids: false keeps "
                              "them)");
  if (report.voids_kept)
    report.warnings.push_back("the design keeps " + std::to_string(report.voids_kept) + " closed internal void(s) of " +
                              mm3(report.void_volume_kept) + " in all (optimization.fill_voids is false)");
}

/// Adds what a later round of cleaning did (removed pieces, filled voids) to the first round's
/// report; the pieces it only names again are named already.
void add_round(const HygieneReport& later, HygieneReport& report) {
  for (const DesignPiece& piece : later.apart)
    if (piece.removed) report.apart.push_back(piece);
  for (const std::string& w : later.warnings)
    if (w.rfind("removed a loose piece", 0) == 0) report.warnings.push_back(w);
  report.voids_filled += later.voids_filled, report.void_volume_filled += later.void_volume_filled;
}

bool changed_design(const HygieneReport& round) {
  for (const DesignPiece& piece : round.apart)
    if (piece.removed) return true;
  return round.voids_filled > 0;
}

}  // namespace

Point tet_centre(const TetMesh& mesh, long t) {
  return 0.25 *
         (node(mesh, mesh.T(t, 0)) + node(mesh, mesh.T(t, 1)) + node(mesh, mesh.T(t, 2)) + node(mesh, mesh.T(t, 3)));
}

double tet_volume(const TetMesh& mesh, long t) {
  const Point a = node(mesh, mesh.T(t, 0));
  return std::abs(
             (node(mesh, mesh.T(t, 1)) - a).cross(node(mesh, mesh.T(t, 2)) - a).dot(node(mesh, mesh.T(t, 3)) - a)) /
         6;
}

std::string solids_named(const std::vector<int>& tags) {
  std::ostringstream s;
  s << (tags.size() == 1 ? "non-design solid " : "non-design solids ");
  for (size_t i = 0; i < tags.size(); ++i) s << (i == 0 ? "" : i + 1 == tags.size() ? " and " : ", ") << tags[i];
  return s.str();
}

std::vector<PieceFacts> level_piece_facts(const TetMesh& mesh, const VecXd& nd, double threshold, const VecXi& label,
                                          int count, const std::vector<char>& anchors) {
  return facts_of(measure_pieces(mesh, nd, threshold, label, count, anchors));
}

MatX4i tet_neighbours(const MatX4i& T) {
  MatX4i nb = MatX4i::Constant(T.rows(), 4, -1);
  std::unordered_map<FaceKey, long, FaceKeyHash> open;
  open.reserve(2 * T.rows());
  for (long t = 0; t < T.rows(); ++t)
    for (int k = 0; k < 4; ++k) {
      const int* f = kTetFace[k];
      const FaceKey key = face_key(T(t, f[0]), T(t, f[1]), T(t, f[2]));
      auto [it, fresh] = open.emplace(key, 4 * t + k);
      if (fresh) continue;
      const long other = it->second;
      nb(t, k) = static_cast<int>(other / 4);
      nb(other / 4, other % 4) = static_cast<int>(t);
      open.erase(it);
    }
  return nb;
}

std::vector<char> crisp_tets(const TetMesh& mesh, const VecXd& node_density, double threshold) {
  std::vector<char> solid(mesh.T.rows());
  for (long t = 0; t < mesh.T.rows(); ++t) {
    const double mean = 0.25 * (node_density[mesh.T(t, 0)] + node_density[mesh.T(t, 1)] + node_density[mesh.T(t, 2)] +
                                node_density[mesh.T(t, 3)]);
    solid[t] = mesh.domain[t] != 0 || mean >= threshold;
  }
  return solid;
}

VecXi level_components(const TetMesh& mesh, const VecXd& node_density, double threshold, int& count) {
  const long nv = mesh.V.rows(), nt = mesh.T.rows();
  std::vector<char> inside(nv, 0);  // inside the level (a design tet's region reaches the node)
  for (long v = 0; v < nv; ++v) inside[v] = node_density[v] >= threshold;
  // a design tet's region joins its nodes inside the level; a non-design tet is solid whole
  Groups groups(nv);
  for (long t = 0; t < nt; ++t) {
    const bool whole = mesh.domain[t] != 0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        if (whole || (inside[mesh.T(t, a)] && inside[mesh.T(t, b)])) groups.join(mesh.T(t, a), mesh.T(t, b));
  }
  std::vector<int> piece_of_root(nv, -1);
  VecXi label = VecXi::Constant(nt, -1);
  count = 0;
  for (long t = 0; t < nt; ++t)
    for (int k = 0; k < 4; ++k) {
      if (!inside[mesh.T(t, k)] && mesh.domain[t] == 0) continue;
      int& piece = piece_of_root[groups.find(mesh.T(t, k))];
      if (piece < 0) piece = count++;
      label[t] = piece;
      break;
    }
  return label;
}

std::vector<PieceFate> piece_fates(const std::vector<PieceFacts>& pieces) {
  const size_t n = pieces.size();
  const char both = kAnchorSupport | kAnchorLoad;
  const bool any_both =
      std::any_of(pieces.begin(), pieces.end(), [&](const PieceFacts& p) { return (p.touch & both) == both; });
  std::vector<char> main(n, 0);
  for (size_t c = 0; c < n; ++c) main[c] = any_both ? (pieces[c].touch & both) == both : pieces[c].touch != 0;
  if (n > 0 && std::none_of(main.begin(), main.end(), [](char a) { return a; })) {
    size_t largest = 0;
    for (size_t c = 1; c < n; ++c)
      if (pieces[c].volume > pieces[largest].volume) largest = c;
    main[largest] = 1;
  }
  std::vector<PieceFate> fate(n);
  for (size_t c = 0; c < n; ++c)
    fate[c] = main[c]                                                    ? PieceFate::Carries
              : !pieces[c].nondesign && !(pieces[c].touch & kAnchorLoad) ? PieceFate::Removed
                                                                         : PieceFate::Named;
  return fate;
}

double min_feature_size(const TetMesh& mesh, const MatX4i& neighbours, const std::vector<char>& solid,
                        std::array<double, 3>& at) {
  const long nt = mesh.T.rows();
  std::vector<Point> centre(nt), nearest(nt);
  std::vector<long> face(nt, -1);  // the nearest boundary face, as 4 × tet + k
  std::vector<double> dist(nt, std::numeric_limits<double>::infinity());
  using Item = std::pair<double, long>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  auto offer = [&](long t, long f) {  // f's nearest point to t's centre, if nearer than t's
    const int* k = kTetFace[f % 4];
    const long o = f / 4;
    const Point q = closest_on_triangle(centre[t], node(mesh, mesh.T(o, k[0])), node(mesh, mesh.T(o, k[1])),
                                        node(mesh, mesh.T(o, k[2])));
    const double d = (centre[t] - q).norm();
    if (d >= dist[t]) return;
    dist[t] = d, nearest[t] = q, face[t] = f;
    queue.push({d, t});
  };
  for (long t = 0; t < nt; ++t) centre[t] = tet_centre(mesh, t);
  // seeds: the solid's boundary faces (on the mesh boundary or against a void tet)
  for (long t = 0; t < nt; ++t)
    for (int k = 0; k < 4 && solid[t]; ++k)
      if (neighbours(t, k) < 0 || !solid[neighbours(t, k)]) offer(t, 4 * t + k);
  // each solid tet tries the nearest faces of its neighbours (Danielsson's propagation)
  while (!queue.empty()) {
    const auto [d, t] = queue.top();
    queue.pop();
    if (d > dist[t]) continue;
    for (int k = 0; k < 4; ++k) {
      const int n = neighbours(t, k);
      if (n >= 0 && solid[n]) offer(n, face[t]);
    }
  }
  // a member's middle: neighbours whose nearest surface points lie on opposite sides (more
  // than 120° apart seen from them); the member is as thick as those points are apart
  double best = std::numeric_limits<double>::infinity();
  for (long t = 0; t < nt; ++t) {
    if (!solid[t] || mesh.domain[t] != 0 || !std::isfinite(dist[t])) continue;
    const Point a = nearest[t] - centre[t];
    for (int k = 0; k < 4; ++k) {
      const int n = neighbours(t, k);
      if (n < 0 || !solid[n] || !std::isfinite(dist[n])) continue;
      const Point b = nearest[n] - centre[n];
      if (a.dot(b) >= -0.5 * a.norm() * b.norm()) continue;
      const double thickness = (nearest[t] - nearest[n]).norm();
      if (thickness < best) {
        best = thickness;
        const Point mid = 0.5 * (centre[t] + centre[n]);
        at = {mid[0], mid[1], mid[2]};
      }
    }
  }
  return std::isfinite(best) ? best : 0;
}

namespace {

/// The cleaning rounds of clean_design on `out` (#T, changed in place): `report` gets the first
/// round's findings and what later rounds removed or filled.
void clean_rounds(const TetMesh& mesh, const MatX4i& nb, double threshold, const std::vector<char>& anchors,
                  const HygieneParams& params, VecXd& out, HygieneReport& report) {
  // Taking a piece out lowers the node densities of the tets around it, filling a void raises
  // them, so the crisp design of the cleaned densities can hold a piece or a void the first
  // round did not see: clean again until a round changes nothing, so that the design handed
  // over is clean by the same test (at most kRounds rounds).
  constexpr int kRounds = 4;
  for (int round = 0; round < kRounds; ++round) {
    const VecXd nd = node_densities(mesh, out);
    std::vector<char> solid = crisp_tets(mesh, nd, threshold);
    HygieneReport found;
    remove_pieces(mesh, nd, threshold, anchors, solid, out, found);
    // the voids of what the removals left: the crisp design's, then the cut's that it misses
    std::vector<char> counted;
    fill_crisp_voids(mesh, nb, params, solid, out, found, counted);
    const bool changed = changed_design(found);
    fill_level_voids(mesh, nb, changed ? node_densities(mesh, out) : nd, threshold, params, counted, solid, out, found);
    if (round == 0)
      report = std::move(found);
    else
      add_round(found, report);
    if (!changed_design(round == 0 ? report : found)) break;
  }
}

}  // namespace

VecXd clean_design(const TetMesh& mesh, const VecXd& density, double threshold, const std::vector<char>& anchors,
                   const HygieneParams& params, HygieneReport& report) {
  report = HygieneReport{};
  const MatX4i nb = tet_neighbours(mesh.T);
  std::vector<Bridge> bridges;
  VecXd out = params.join_non_design
                  ? join_non_design_solids(mesh, nb, density, threshold, anchors, params.bridge_size, bridges,
                                           params.build_direction)
                  : density;
  clean_rounds(mesh, nb, threshold, anchors, params, out, report);
  if (params.min_member_size > 0) {  // the minimum member size held on the clean design, then its voids closed
    MemberEnforcement members;
    out = enforce_min_member(mesh, out, threshold, anchors, {params.min_member_size}, members);
    if (members.tets_added > 0) {
      HygieneReport again;
      clean_rounds(mesh, nb, threshold, anchors, params, out, again);
      add_round(again, report);
    }
    report.members = members;
  }
  warn_voids(report);
  for (const Bridge& b : bridges)
    if (b.joined) report.warnings.push_back(bridge_warning(b));
  report.bridges = std::move(bridges);
  if (const std::string w = member_warning(report.members); !w.empty()) report.warnings.push_back(w);
  const std::vector<char> solid = crisp_tets(mesh, node_densities(mesh, out), threshold);
  report.min_feature = min_feature_size(mesh, nb, solid, report.min_feature_at);
  return out;
}

namespace {

/// The pieces of surface s: triangles sharing points. Returns #Q labels; `count` gets the number.
VecXi surface_components(const TriSurface& s, int& count) {
  Groups groups(s.V.rows());
  for (long q = 0; q < s.F.rows(); ++q) groups.join(s.F(q, 0), s.F(q, 1)), groups.join(s.F(q, 0), s.F(q, 2));
  std::vector<int> piece_of_root(s.V.rows(), -1);
  VecXi label(s.F.rows());
  count = 0;
  for (long q = 0; q < s.F.rows(); ++q) {
    int& piece = piece_of_root[groups.find(s.F(q, 0))];
    if (piece < 0) piece = count++;
    label[q] = piece;
  }
  return label;
}

/// Keeps in s only the triangles whose drop[label[q]] is 0, and the points they use.
void drop_surface_pieces(TriSurface& s, const VecXi& label, const std::vector<char>& drop) {
  std::vector<int> index(s.V.rows(), -1);
  long kept_q = 0;
  int kept_p = 0;
  for (long q = 0; q < s.F.rows(); ++q) {
    if (drop[label[q]]) continue;
    for (int k = 0; k < 3; ++k)
      if (index[s.F(q, k)] < 0) index[s.F(q, k)] = kept_p++;
    s.F.row(kept_q) << index[s.F(q, 0)], index[s.F(q, 1)], index[s.F(q, 2)];
    s.tag[kept_q++] = s.tag[q];
  }
  s.F.conservativeResize(kept_q, 3);
  s.tag.conservativeResize(kept_q);
  MatX3d V(kept_p, 3);
  VecXi lock(kept_p), point_face(kept_p);
  for (long i = 0; i < s.V.rows(); ++i) {
    if (index[i] < 0) continue;
    V.row(index[i]) = s.V.row(i);
    if (s.lock.size() == s.V.rows()) lock[index[i]] = s.lock[i];
    if (s.point_face.size() == s.V.rows()) point_face[index[i]] = s.point_face[i];
  }
  s.V = std::move(V);
  if (s.lock.size()) s.lock = std::move(lock);
  if (s.point_face.size()) s.point_face = std::move(point_face);
}

}  // namespace

int clean_surface_pieces(TriSurface& s, const std::vector<char>& face_anchors, HygieneReport& report) {
  int count = 0;
  const VecXi label = surface_components(s, count);
  if (count <= 1) return 0;
  std::vector<PieceFacts> facts(count);
  std::vector<Point> centre(count, Point::Zero());
  std::vector<std::set<int>> nondesign(count);
  for (long q = 0; q < s.F.rows(); ++q) {
    PieceFacts& f = facts[label[q]];
    const Point a = s.V.row(s.F(q, 0)), b = s.V.row(s.F(q, 1)), c = s.V.row(s.F(q, 2));
    const double v = a.dot(b.cross(c)) / 6;  // the cone from the origin, signed
    f.volume += v, centre[label[q]] += v * (a + b + c) / 4;
    const int tag = s.tag[q];
    if (tag > 0 && tag < static_cast<int>(face_anchors.size())) f.touch |= face_anchors[tag];
    if (tag < 0) nondesign[label[q]].insert(-tag);
    for (int k = 0; k < 3; ++k) f.nondesign |= tag < 0 || (s.lock.size() == s.V.rows() && s.lock[s.F(q, k)] == 2);
  }
  // the rule on the pieces that enclose volume; inner shells (voids) stay as they are
  std::vector<int> piece;
  std::vector<PieceFacts> solid;
  for (int c = 0; c < count; ++c)
    if (facts[c].volume > 0) piece.push_back(c), solid.push_back(facts[c]);
  const std::vector<PieceFate> fate = piece_fates(solid);
  std::set<int> named;  // non-design solids the report names already
  bool design_named = false;
  for (const DesignPiece& p : report.apart) {
    named.insert(p.nondesign.begin(), p.nondesign.end());
    design_named |= p.nondesign.empty() && !p.removed;
  }
  std::vector<char> drop(count, 0);
  int added = 0;
  for (size_t i = 0; i < piece.size(); ++i) {
    const int c = piece[i];
    if (fate[i] == PieceFate::Carries) continue;
    const Point at_c = centre[c] / facts[c].volume;
    const std::string why = apart_because(facts[c].touch, !face_anchors.empty());
    const std::vector<int> nd_tags(nondesign[c].begin(), nondesign[c].end());
    if (fate[i] == PieceFate::Removed) {
      drop[c] = 1;
      report.apart.push_back({facts[c].volume, {}, true});
      report.warnings.push_back(removed_warning("the result surface", facts[c].volume, at_c, why));
      ++added;
      continue;
    }
    const bool new_name = nd_tags.empty()
                              ? !design_named
                              : std::any_of(nd_tags.begin(), nd_tags.end(), [&](int k) { return named.count(k) == 0; });
    if (!new_name) continue;
    report.apart.push_back({facts[c].volume, nd_tags, false});
    report.warnings.push_back(named_warning(nd_tags, facts[c].volume, at_c, why));
    ++added;
  }
  if (std::find(drop.begin(), drop.end(), 1) != drop.end()) drop_surface_pieces(s, label, drop);
  return added;
}

}  // namespace topopt::result
