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
#include "common/triangle_closest.h"
#include "result/iso_surface.h"

namespace topopt::result {

namespace {

using Point = Eigen::Vector3d;

Point node(const TetMesh& mesh, int v) { return mesh.V.row(v).transpose(); }

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

/// "non-design solid 2", "non-design solids 2 and 3", "non-design solids 1, 2 and 4".
std::string solids_named(const std::vector<int>& tags) {
  std::ostringstream s;
  s << (tags.size() == 1 ? "non-design solid " : "non-design solids ");
  for (size_t i = 0; i < tags.size(); ++i) s << (i == 0 ? "" : i + 1 == tags.size() ? " and " : ", ") << tags[i];
  return s.str();
}

std::string mm3(double v) {
  std::ostringstream s;
  s.precision(v < 10 ? 2 : 4);
  s << v << " mm³";
  return s.str();
}

/// Volume, non-design solids, anchoring and centre of each labelled piece.
struct Pieces {
  std::vector<double> volume;
  std::vector<std::set<int>> nondesign;
  std::vector<char> touch;    // kAnchorSupport | kAnchorLoad of the anchor nodes in it
  std::vector<char> main;     // carries the loads (see measure_pieces)
  std::vector<Point> centre;  // volume-weighted
};

Pieces measure_pieces(const TetMesh& mesh, const VecXi& label, int count, const std::vector<char>& anchors) {
  Pieces p{std::vector<double>(count, 0), std::vector<std::set<int>>(count), std::vector<char>(count, 0),
           std::vector<char>(count, 0), std::vector<Point>(count, Point::Zero())};
  for (long t = 0; t < mesh.T.rows(); ++t) {
    const int c = label[t];
    if (c < 0) continue;
    const double v = tet_volume(mesh, t);
    p.volume[c] += v;
    p.centre[c] += v * tet_centre(mesh, t);
    if (mesh.domain[t] != 0) p.nondesign[c].insert(mesh.domain[t]);
    if (!anchors.empty())
      for (int k = 0; k < 4; ++k) p.touch[c] |= anchors[mesh.T(t, k)];
  }
  for (int c = 0; c < count; ++c) p.centre[c] /= std::max(p.volume[c], 1e-300);
  // the pieces that carry loads to supports; failing those, the ones with either; failing
  // those (no anchors given), the largest piece
  const char both = kAnchorSupport | kAnchorLoad;
  const bool any_both = std::any_of(p.touch.begin(), p.touch.end(), [&](char a) { return (a & both) == both; });
  for (int c = 0; c < count; ++c) p.main[c] = any_both ? (p.touch[c] & both) == both : p.touch[c] != 0;
  if (count > 0 && std::none_of(p.main.begin(), p.main.end(), [](char a) { return a; }))
    p.main[std::max_element(p.volume.begin(), p.volume.end()) - p.volume.begin()] = 1;
  return p;
}

std::string at(const Point& x) {
  std::ostringstream s;
  s.precision(3);
  s << "around (" << x[0] << ", " << x[1] << ", " << x[2] << ") mm";
  return s.str();
}

/// Per tet (#T): whether it has a node on a tet labelled c (labels #T) — the piece itself and
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

/// Sets piece c (labels #T) to void, and the design tets around it that are not solid either
/// (their densities would otherwise hold a ghost of the piece in the node densities).
void remove_piece(const TetMesh& mesh, const VecXi& label, int c, std::vector<char>& solid, VecXd& out) {
  const std::vector<char> touches = touching_label(mesh, label, c);
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (mesh.domain[t] != 0 || (solid[t] && label[t] != c)) continue;
    if (touches[t]) out[t] = 0, solid[t] = 0;
  }
}

/// Why piece c is apart, in words.
std::string apart_because(char touch, bool have_anchors) {
  if (touch & kAnchorLoad) return "carries a load that does not reach the supports";
  if (touch & kAnchorSupport) return "holds a support but no load";
  return have_anchors ? "touches no support and no load" : "lies apart from the largest piece";
}

/// Takes the pieces that carry no load to a support out of the design (out, solid) when they
/// are design material with no load on it, or names their non-design solids; warns when the
/// material carrying loads is itself in several pieces.
void remove_pieces(const TetMesh& mesh, const std::vector<char>& anchors, std::vector<char>& solid, VecXd& out,
                   HygieneReport& report) {
  int count = 0;
  const VecXi label = node_components(mesh, solid, count);
  const Pieces p = measure_pieces(mesh, label, count, anchors);
  report.pieces = count;
  std::vector<std::string> main_names;
  for (int c = 0; c < count; ++c) {
    const std::vector<int> nd(p.nondesign[c].begin(), p.nondesign[c].end());
    if (p.main[c]) {
      ++report.anchored_pieces;
      main_names.push_back(nd.empty() ? "design material only" : solids_named(nd));
      continue;
    }
    const std::string why = apart_because(p.touch[c], !anchors.empty());
    const bool removed = nd.empty() && !(p.touch[c] & kAnchorLoad);
    report.apart.push_back({p.volume[c], nd, removed});
    if (removed) {
      remove_piece(mesh, label, c, solid, out);
      report.warnings.push_back("removed a loose piece of the design (" + mm3(p.volume[c]) + ", " + at(p.centre[c]) +
                                "): it " + why);
    } else {
      report.warnings.push_back(
          (nd.empty() ? "a piece of the design" : solids_named(nd)) + " " + (nd.size() > 1 ? "are" : "is") +
          " not connected by the design to the rest that carries the loads (a piece of " + mm3(p.volume[c]) + ", " +
          at(p.centre[c]) + ", that " + why + "): lower the threshold or raise the volume fraction");
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

/// Sets void piece c (labels #T) solid, and the design tets around it to density 1 as well
/// (the solid tets of its wall may hold low densities that would leave a smaller cavity in
/// the node densities).
void fill_void(const TetMesh& mesh, const VecXi& label, int c, std::vector<char>& solid, VecXd& out) {
  const std::vector<char> touches = touching_label(mesh, label, c);
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (touches[t] && mesh.domain[t] == 0) out[t] = 1, solid[t] = 1;
}

/// Fills (or counts) the void pieces that touch no boundary face of the mesh.
void fill_voids(const TetMesh& mesh, const MatX4i& nb, const HygieneParams& params, std::vector<char>& solid,
                VecXd& out, HygieneReport& report) {
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
  for (int c = 0; c < count; ++c) {
    if (open[c]) continue;
    if (!params.fill_voids) {
      ++report.voids_kept, report.void_volume_kept += volume[c];
      continue;
    }
    ++report.voids_filled, report.void_volume_filled += volume[c];
    fill_void(mesh, label, c, solid, out);
  }
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

namespace {

/// Labels the masked tets (#T) by connected piece, 0 .. count-1 (unmasked: -1), by flood fill;
/// each_neighbour(t, visit) calls visit(n) for the tets n next to tet t.
template <class EachNeighbour>
VecXi flood_labels(long nt, const std::vector<char>& mask, int& count, const EachNeighbour& each_neighbour) {
  VecXi label = VecXi::Constant(nt, -1);
  count = 0;
  std::vector<int> stack;
  for (long s = 0; s < nt; ++s) {
    if (!mask[s] || label[s] >= 0) continue;
    label[s] = count;
    stack.assign(1, static_cast<int>(s));
    while (!stack.empty()) {
      const int t = stack.back();
      stack.pop_back();
      each_neighbour(t, [&](int n) {
        if (mask[n] && label[n] < 0) label[n] = count, stack.push_back(n);
      });
    }
    ++count;
  }
  return label;
}

}  // namespace

VecXi node_components(const TetMesh& mesh, const std::vector<char>& mask, int& count) {
  // the masked tets around each node
  const Adjacency around = group_pairs(static_cast<int>(mesh.V.rows()), [&](auto emit) {
    for (long t = 0; t < mesh.T.rows(); ++t)
      if (mask[t])
        for (int k = 0; k < 4; ++k) emit(mesh.T(t, k), static_cast<int>(t));
  });
  return flood_labels(mesh.T.rows(), mask, count, [&](int t, const auto& visit) {
    for (int k = 0; k < 4; ++k)
      for (int n : around.row(mesh.T(t, k))) visit(n);
  });
}

VecXi tet_components(const MatX4i& neighbours, const std::vector<char>& mask, int& count) {
  return flood_labels(neighbours.rows(), mask, count, [&](int t, const auto& visit) {
    for (int k = 0; k < 4; ++k)
      if (neighbours(t, k) >= 0) visit(neighbours(t, k));
  });
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

VecXd clean_design(const TetMesh& mesh, const VecXd& density, double threshold, const std::vector<char>& anchors,
                   const HygieneParams& params, HygieneReport& report) {
  report = HygieneReport{};
  const MatX4i nb = tet_neighbours(mesh.T);
  VecXd out = density;
  // Taking a piece out lowers the node densities of the tets around it, filling a void raises
  // them, so the crisp design of the cleaned densities can hold a piece or a void the first
  // round did not see: clean again until a round changes nothing, so that the design handed
  // over is clean by the same test (at most kRounds rounds).
  constexpr int kRounds = 4;
  std::vector<char> solid;
  for (int round = 0; round < kRounds; ++round) {
    solid = crisp_tets(mesh, node_densities(mesh, out), threshold);
    HygieneReport found;
    remove_pieces(mesh, anchors, solid, out, found);
    fill_voids(mesh, nb, params, solid, out, found);
    if (round == 0)
      report = std::move(found);
    else
      add_round(found, report);
    if (!changed_design(round == 0 ? report : found)) break;
  }
  warn_voids(report);
  solid = crisp_tets(mesh, node_densities(mesh, out), threshold);
  report.min_feature = min_feature_size(mesh, nb, solid, report.min_feature_at);
  return out;
}

}  // namespace topopt::result
