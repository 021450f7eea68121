// Bridges for the non-design solids the optimum leaves apart (see join_bridges.h).
#include "result/join_bridges.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <set>

#include "common/number_text.h"
#include "common/triangle_closest.h"
#include "mesh/core/spatial_grid.h"
#include "result/iso_surface.h"

namespace topopt::result {

namespace {

constexpr int kNotchRounds = 8;  // fill_notches: rounds at most

using Point = Eigen::Vector3d;

/// 3 × the mean edge length of the design tets (of all tets when there is no design tet).
double default_size(const TetMesh& mesh) {
  double sum = 0;
  long n = 0;
  for (int pass = 0; pass < 2 && n == 0; ++pass)
    for (long t = 0; t < mesh.T.rows(); ++t) {
      if (pass == 0 && mesh.domain[t] != 0) continue;
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) sum += (mesh.V.row(mesh.T(t, a)) - mesh.V.row(mesh.T(t, b))).norm(), ++n;
    }
  return n ? 3 * sum / n : 0;
}

/// The pieces of the result shape at `threshold` of the densities: labels (#T), and fates.
struct Shape {
  VecXi label;
  std::vector<PieceFacts> facts;
  std::vector<PieceFate> fate;
};

Shape shape_of(const TetMesh& mesh, const VecXd& density, double threshold, const std::vector<char>& anchors) {
  const VecXd nd = node_densities(mesh, density);
  Shape s;
  int count = 0;
  s.label = level_components(mesh, nd, threshold, count);
  s.facts = level_piece_facts(mesh, nd, threshold, s.label, count, anchors);
  s.fate = piece_fates(s.facts);
  return s;
}

/// The cheapest path of tets from any tet with from[t] to one with to[t] (Dijkstra over the
/// face neighbours; a step costs the centres' distance × bridge_penalty of the tet entered,
/// 1 for a non-design tet). Returns the path's tets from `from` to `to`; empty if none.
std::vector<long> cheapest_path(const TetMesh& mesh, const MatX4i& nb, const std::vector<Point>& centre,
                                const VecXd& density, const std::vector<char>& from, const std::vector<char>& to) {
  const long nt = mesh.T.rows();
  std::vector<double> cost(nt, std::numeric_limits<double>::infinity());
  std::vector<long> previous(nt, -1);
  using Item = std::pair<double, long>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (long t = 0; t < nt; ++t)
    if (from[t]) cost[t] = 0, queue.push({0.0, t});
  long end = -1;
  while (!queue.empty()) {
    const auto [c, t] = queue.top();
    queue.pop();
    if (c > cost[t]) continue;
    if (to[t]) {
      end = t;
      break;
    }
    for (int k = 0; k < 4; ++k) {
      const int n = nb(t, k);
      if (n < 0) continue;
      const double step = (centre[n] - centre[t]).norm() * (mesh.domain[n] != 0 ? 1.0 : bridge_penalty(density[n]));
      if (c + step >= cost[n]) continue;
      cost[n] = c + step, previous[n] = t;
      queue.push({cost[n], n});
    }
  }
  std::vector<long> path;
  for (long t = end; t >= 0; t = previous[t]) path.push_back(t);
  std::reverse(path.begin(), path.end());
  return path;
}

/// Per node (#V): within `radius` of the polyline through `points`.
std::vector<char> nodes_near(const TetMesh& mesh, const std::vector<Point>& points, double radius) {
  Point lo = points[0], hi = points[0];
  for (const Point& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  lo.array() -= radius, hi.array() += radius;
  std::vector<char> near(mesh.V.rows(), 0);
  for (long v = 0; v < mesh.V.rows(); ++v) {
    const Point x = mesh.V.row(v).transpose();
    if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any()) continue;
    for (size_t i = 0; i + 1 < points.size() && !near[v]; ++i)
      near[v] = distance_to_segment(x, points[i], points[i + 1]) <= radius;
    if (points.size() == 1) near[v] = (x - points[0]).norm() <= radius;
  }
  return near;
}

/// Per node (#V): under the polyline `points` along −build (unit) and within `radius` of it across
/// build, i.e. in the shadow the polyline's tube of that radius casts down the build direction —
/// the node's height along build below the axis's height at the nearest point across build.
std::vector<char> nodes_under(const TetMesh& mesh, const std::vector<Point>& points, double radius,
                              const Eigen::Vector3d& build) {
  const auto across = [&](const Point& x) -> Point { return x - x.dot(build) * build; };
  std::vector<char> under(mesh.V.rows(), 0);
  for (long v = 0; v < mesh.V.rows(); ++v) {
    const Point x = mesh.V.row(v).transpose(), xa = across(x);
    for (size_t i = 0; i + 1 < points.size() && !under[v]; ++i) {
      const Point a = across(points[i]), b = across(points[i + 1]);
      const double s = segment_parameter(xa, a, b);
      if ((xa - (a + s * (b - a))).norm() > radius) continue;
      const double height = (1 - s) * points[i].dot(build) + s * points[i + 1].dot(build);
      under[v] = x.dot(build) <= height;
    }
  }
  return under;
}

/// Per node (#V): a node of a non-design tet, or at or above `threshold` of the node densities
/// of `density` (#T): material.
std::vector<char> solid_nodes(const TetMesh& mesh, const VecXd& density, double threshold) {
  const VecXd nd = node_densities(mesh, density);
  std::vector<char> solid(mesh.V.rows(), 0);
  for (long v = 0; v < mesh.V.rows(); ++v) solid[v] = nd[v] >= threshold;
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (mesh.domain[t] != 0)
      for (int k = 0; k < 4; ++k) solid[mesh.T(t, k)] = 1;
  return solid;
}

/// Per node (#V): on a triangle of Ω's boundary whose outward normal lies within 60° of −build
/// (unit): where Ω ends below, nothing to build under it.
std::vector<char> nodes_on_floor_of_omega(const TetMesh& mesh, const Eigen::Vector3d& build) {
  std::vector<char> floor(mesh.V.rows(), 0);
  for (long f = 0; f < mesh.F.rows(); ++f) {
    const Point a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Point n = (b - a).cross(c - a);
    if (n.dot(build) < -0.5 * n.norm())
      for (int k = 0; k < 3; ++k) floor[mesh.F(f, k)] = 1;
  }
  return floor;
}

/// Per node (#V): the wall that carries the tube of `radius` round the polyline `points` down the
/// unit `build` direction to the material below it — the nodes under the tube (nodes_under), not
/// material (`solid`, #V) themselves, save those with a material node of that shadow above them
/// within `column` across the build and a gap of at least `gap` between that material and what
/// lies under it there (material, or Ω's floor). The wall stops on the first material under the
/// tube (a member of the design, a non-design solid), not at the plate: what lies under that
/// material is its own to print — unless the void under it is thinner than `gap`, which is filled
/// as before (a ceiling a millimetre over the plate is no less an overhang than the tube's).
std::vector<char> wall_under(const TetMesh& mesh, const std::vector<Point>& points, double radius,
                             const Eigen::Vector3d& build, double column, double gap, const std::vector<char>& solid) {
  std::vector<char> wall = nodes_under(mesh, points, radius, build);
  const std::vector<char> floor = nodes_on_floor_of_omega(mesh, build);
  std::vector<long> below_ends, material;  // the shadow's material nodes and those of Ω's floor
  for (long v = 0; v < mesh.V.rows(); ++v) {
    if (wall[v] && solid[v]) material.push_back(v);
    if (wall[v] && (solid[v] || floor[v])) below_ends.push_back(v);
  }
  const auto in_column = [&](const Point& d) { return (d - d.dot(build) * build).norm() <= column; };
  for (long v = 0; v < mesh.V.rows(); ++v) {
    if (!wall[v]) continue;
    if (solid[v]) {  // material already: flagged, it would set the void tets around it solid
      wall[v] = 0;
      continue;
    }
    const Point x = mesh.V.row(v).transpose();
    double above = std::numeric_limits<double>::infinity(), below = -above;  // heights over and under v
    for (long m : material)
      if (const Point d = mesh.V.row(m).transpose() - x; d.dot(build) > 0 && in_column(d))
        above = std::min(above, mesh.V.row(m).dot(build));
    if (std::isinf(above)) continue;
    for (long m : below_ends)
      if (const Point d = mesh.V.row(m).transpose() - x; d.dot(build) <= 0 && in_column(d))
        below = std::max(below, mesh.V.row(m).dot(build));
    if (above - below >= gap) wall[v] = 0;
  }
  return wall;
}

/// The path's polyline (tet centres) with each end carried on by `length` along its last step:
/// the tube then ends inside the pieces it joins, not at their first tet's centre.
std::vector<Point> extended_ends(std::vector<Point> points, double length) {
  if (points.size() < 2) return points;
  const Point head = points[0] - points[1], tail = points.back() - points[points.size() - 2];
  if (head.norm() > 0) points.insert(points.begin(), points[0] + length * head.normalized());
  if (tail.norm() > 0) points.push_back(points.back() + length * tail.normalized());
  return points;
}

/// Fills the notches left at the tet level: round after round, every design tet with a node
/// flagged in `inner` (#V) whose four nodes all touch the solid (a node of a non-design tet or
/// of a crisp tet of the densities at `threshold`) is set to density 1, until a round sets none
/// or after `rounds`: the one-element crevices and notches the closing's node sampling leaves,
/// filled from their narrow end. Returns the material added (Σ volume × the density gained).
double fill_notches(const TetMesh& mesh, const std::vector<char>& inner, double threshold, int rounds, VecXd& density) {
  double added = 0;
  const auto& T = mesh.T;
  for (int round = 0; round < rounds; ++round) {
    const std::vector<char> solid = crisp_tets(mesh, node_densities(mesh, density), threshold);
    std::vector<char> touch(mesh.V.rows(), 0);
    for (long t = 0; t < T.rows(); ++t)
      if (solid[t])
        for (int k = 0; k < 4; ++k) touch[T(t, k)] = 1;
    long filled = 0;
    for (long t = 0; t < T.rows(); ++t) {
      if (mesh.domain[t] != 0 || density[t] >= 1) continue;
      if (!(inner[T(t, 0)] || inner[T(t, 1)] || inner[T(t, 2)] || inner[T(t, 3)])) continue;
      if (!(touch[T(t, 0)] && touch[T(t, 1)] && touch[T(t, 2)] && touch[T(t, 3)])) continue;
      added += tet_volume(mesh, t) * (1 - std::max(density[t], 0.0));
      density[t] = 1, ++filled;
    }
    if (filled == 0) break;
  }
  return added;
}

/// The nodes flagged in `keep` (#V) in the product's spatial grid (mesh/core/spatial_grid.h), cells
/// of `radius`, to visit those within `radius` of a point.
struct NodeBalls {
  const TetMesh& mesh;
  double radius;
  mesh::SpatialGrid<3> grid;
  NodeBalls(const TetMesh& m, const std::vector<char>& keep, double r)
      : mesh(m), radius(r), grid(Point(m.V.colwise().minCoeff()).data(), r) {
    for (long v = 0; v < m.V.rows(); ++v)
      if (keep[v]) {
        const Point x = m.V.row(v).transpose();
        grid.insert(static_cast<int>(v), x.data(), x.data());
      }
  }
  /// Calls f(u) for every kept node u within `radius` of x.
  template <class F>
  void around(const Point& x, F&& f) const {
    const Point lo = x.array() - radius, hi = x.array() + radius;
    grid.for_each(lo.data(), hi.data(), [&](int u) {
      if ((mesh.V.row(u).transpose() - x).norm() <= radius) f(static_cast<long>(u));
    });
  }
};

/// Closes the junctions of a bridge: the morphological closing, by a ball of `radius`, of the
/// solid nodes (on a non-design tet, or at or above `threshold` of the node densities) near the
/// bridge's axis (the polyline `axis`): a node within `reach` of the axis is closed when every
/// node within `radius` of it lies within `radius` of a solid node (dilation, then erosion).
/// Every design tet whose four nodes are closed or solid is set to density 1: the crevices and
/// knife-edge shelves a tube of whole tets leaves where it meets a piece's side, gaps narrower
/// than 2 × radius, fill as fillets of that radius; flat and convex sides stay as they were.
/// Returns the material added (Σ volume × the density gained).
double close_junctions(const TetMesh& mesh, const std::vector<Point>& axis, double reach, double radius,
                       double threshold, VecXd& density) {
  const long nv = mesh.V.rows();
  const std::vector<char> solid = solid_nodes(mesh, density, threshold);
  const std::vector<char> inner = nodes_near(mesh, axis, reach);               // may close
  const std::vector<char> outer = nodes_near(mesh, axis, reach + 2 * radius);  // what decides
  const NodeBalls grid(mesh, outer, radius);
  std::vector<char> dilated(nv, 0);
  for (long v = 0; v < nv; ++v) {
    if (!outer[v]) continue;
    grid.around(mesh.V.row(v).transpose(), [&](long u) { dilated[v] |= solid[u]; });
  }
  std::vector<char> closed(nv, 0);
  for (long v = 0; v < nv; ++v) {
    if (!inner[v] || solid[v]) {
      closed[v] = solid[v];
      continue;
    }
    bool all = true;
    grid.around(mesh.V.row(v).transpose(), [&](long u) { all = all && dilated[u]; });
    closed[v] = all;
  }
  double added = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (mesh.domain[t] != 0 || density[t] >= 1) continue;
    const auto& T = mesh.T;
    if (!(inner[T(t, 0)] || inner[T(t, 1)] || inner[T(t, 2)] || inner[T(t, 3)])) continue;
    if (!(closed[T(t, 0)] && closed[T(t, 1)] && closed[T(t, 2)] && closed[T(t, 3)])) continue;
    added += tet_volume(mesh, t) * (1 - std::max(density[t], 0.0));
    density[t] = 1;
  }
  return added + fill_notches(mesh, inner, threshold, kNotchRounds, density);
}

}  // namespace

double bridge_penalty(double rho) { return 1 + (kVoidPenalty - 1) * (1 - std::clamp(rho, 0.0, 1.0)); }

VecXd join_non_design_solids(const TetMesh& mesh, const MatX4i& neighbours, const VecXd& density, double threshold,
                             const std::vector<char>& anchors, double size, std::vector<Bridge>& bridges,
                             const Eigen::Vector3d& build) {
  const long nt = mesh.T.rows();
  const Shape before = shape_of(mesh, density, threshold, anchors);
  std::vector<char> carrying(nt, 0);  // the load-carrying pieces' tets, and those joined to them
  std::vector<int> apart;             // the pieces to join
  for (size_t c = 0; c < before.fate.size(); ++c)
    if (before.fate[c] == PieceFate::Named && before.facts[c].nondesign) apart.push_back(static_cast<int>(c));
  if (apart.empty()) return density;
  for (long t = 0; t < nt; ++t)
    carrying[t] = before.label[t] >= 0 && before.fate[before.label[t]] == PieceFate::Carries;
  const double edge = default_size(mesh) / 3;  // the design tets' mean edge
  if (size <= 0) size = 3 * edge;
  std::vector<Point> centre(nt);
  for (long t = 0; t < nt; ++t) centre[t] = tet_centre(mesh, t);
  VecXd out = density;
  std::vector<long> first_tet;  // a tet of each bridged piece, to check it is joined
  for (int c : apart) {
    Bridge bridge;
    bridge.size = size;
    std::set<int> tags;
    std::vector<char> piece(nt, 0);
    for (long t = 0; t < nt; ++t)
      if (before.label[t] == c) {
        piece[t] = 1;
        if (mesh.domain[t] != 0) tags.insert(mesh.domain[t]);
      }
    bridge.nondesign.assign(tags.begin(), tags.end());
    first_tet.push_back(std::find(piece.begin(), piece.end(), 1) - piece.begin());
    const std::vector<long> path = cheapest_path(mesh, neighbours, centre, out, piece, carrying);
    if (path.empty()) {
      bridges.push_back(bridge);
      continue;
    }
    std::vector<Point> points;
    for (long t : path) points.push_back(centre[t]);
    for (size_t i = 0; i + 1 < points.size(); ++i) bridge.length += (points[i + 1] - points[i]).norm();
    // the tube runs on a radius into both pieces, so that it ends inside them
    const std::vector<Point> axis = extended_ends(points, 0.5 * size);
    std::vector<char> near = nodes_near(mesh, axis, 0.5 * size);
    // the path's own nodes too: a chain of nodes inside the level from the piece to the
    // load-carrying one, whatever the size against the elements
    for (long t : path)
      for (int k = 0; k < 4; ++k) near[mesh.T(t, k)] = 1;
    if (build.squaredNorm() > 0) {  // a wall under the tube: no ceiling to print it on
      const std::vector<char> under =
          wall_under(mesh, axis, 0.5 * size, build, 0.5 * edge, size, solid_nodes(mesh, out, threshold));
      for (size_t v = 0; v < near.size(); ++v) near[v] |= under[v];
    }
    for (long t = 0; t < nt; ++t) {
      if (piece[t]) carrying[t] = 1;
      if (mesh.domain[t] != 0 ||
          !(near[mesh.T(t, 0)] || near[mesh.T(t, 1)] || near[mesh.T(t, 2)] || near[mesh.T(t, 3)]))
        continue;
      bridge.volume += tet_volume(mesh, t) * (1 - std::clamp(out[t], 0.0, 1.0));
      out[t] = 1, carrying[t] = 1;
    }
    const VecXd tube = out;
    bridge.volume += close_junctions(mesh, axis, size, 0.5 * size, threshold, out);
    for (long t = 0; t < nt; ++t)
      if (out[t] != tube[t]) carrying[t] = 1;
    bridges.push_back(bridge);
  }
  // joined: the piece now lies in a load-carrying piece of the result shape
  const Shape after = shape_of(mesh, out, threshold, anchors);
  for (size_t i = 0; i < apart.size(); ++i) {
    Bridge& b = bridges[bridges.size() - apart.size() + i];
    const int c = after.label[first_tet[i]];
    b.joined = b.length > 0 && c >= 0 && after.fate[c] == PieceFate::Carries;
  }
  return out;
}

std::string bridge_warning(const Bridge& bridge) {
  const std::string it = bridge.nondesign.size() > 1 ? "them" : "it";
  return "joined " + solids_named(bridge.nondesign) + " to the part with a bridge through the design (" +
         amount_text(bridge.volume, " mm³") + " of material added, " + amount_text(bridge.length, " mm") + " long, " +
         amount_text(bridge.size, " mm") + " across): the design left " + it +
         " apart from the supports and loads; \"result\": "
         "{\"join_non_design\": false} leaves " +
         it + " apart instead";
}

}  // namespace topopt::result
