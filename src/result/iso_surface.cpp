// Marching tetrahedra on the tagged mesh (see iso_surface.h).
#include "result/iso_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <queue>
#include <unordered_map>

#include "common/error.h"
#include "common/face_key.h"

namespace topopt::result {
namespace {

/// Value of the level-set function at a node: never exactly 0 (a node on the threshold
/// counts as inside), so every crossing lies strictly inside an edge.
inline double level(const VecXd& node_density, int node, double threshold) {
  double v = node_density[node] - threshold;
  return v == 0 ? 1e-12 : v;
}

double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d) {
  return std::abs((b - a).dot((c - a).cross(d - a))) / 6.0;
}

/// Volume of the part of tet p[0..3] where the linear function with node values f >= 0.
double kept_volume(const std::array<Eigen::Vector3d, 4>& p, const std::array<double, 4>& f) {
  int pos[4], neg[4], np = 0, nn = 0;
  for (int i = 0; i < 4; ++i) (f[i] >= 0 ? pos[np++] : neg[nn++]) = i;
  double vol = tet_volume(p[0], p[1], p[2], p[3]);
  auto cut = [&](int i, int j) { return Eigen::Vector3d(p[i] + f[i] / (f[i] - f[j]) * (p[j] - p[i])); };
  if (np == 0) return 0;
  if (np == 4) return vol;
  if (np == 1) {
    int a = pos[0];
    double r = 1;
    for (int j = 0; j < 4; ++j)
      if (j != a) r *= f[a] / (f[a] - f[j]);
    return vol * r;
  }
  if (np == 3) {
    int d = neg[0];
    double r = 1;
    for (int j = 0; j < 4; ++j)
      if (j != d) r *= -f[d] / (f[j] - f[d]);
    return vol * (1 - r);
  }
  // two in (a, b), two out (c, d): the prism a p_ac p_ad | b p_bc p_bd
  int a = pos[0], b = pos[1], c = neg[0], d = neg[1];
  Eigen::Vector3d A0 = p[a], A1 = cut(a, c), A2 = cut(a, d), B0 = p[b], B1 = cut(b, c), B2 = cut(b, d);
  return tet_volume(A0, A1, A2, B2) + tet_volume(A0, A1, B1, B2) + tet_volume(A0, B0, B1, B2);
}

/// Parity of the permutation (a, b, c, d) of (0, 1, 2, 3): true if even.
bool even_permutation(int a, int b, int c, int d) {
  int v[4] = {a, b, c, d}, inv = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) inv += v[i] > v[j];
  return inv % 2 == 0;
}

/// Indexed by Ω's face number (0..the largest in mesh.face): (n, d) of the face's plane
/// n·x = d when all its boundary triangles (mesh.F) lie in one plane, else (0, 0, 0, 0).
std::vector<Eigen::Vector4d> planar_faces(const TetMesh& mesh) {
  const int max_face = mesh.face.size() ? mesh.face.maxCoeff() : 0;
  std::vector<Eigen::Vector4d> plane(max_face + 1, Eigen::Vector4d::Zero());
  std::vector<char> bad(max_face + 1, 0), seen(max_face + 1, 0);
  for (long k = 0; k < mesh.F.rows(); ++k) {
    const int f = mesh.face.size() ? mesh.face[k] : 0;
    if (f <= 0) continue;
    const Eigen::Vector3d a = mesh.V.row(mesh.F(k, 0)), b = mesh.V.row(mesh.F(k, 1)), c = mesh.V.row(mesh.F(k, 2));
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() == 0) continue;
    n.normalize();
    if (!seen[f]) {
      seen[f] = 1;
      plane[f] << n, n.dot(a);
    } else if (!bad[f]) {
      const Eigen::Vector3d n0 = plane[f].head<3>();
      if (n.dot(n0) < 1 - 1e-9 || std::abs(n0.dot(a) - plane[f][3]) > 1e-7 * (1 + std::abs(plane[f][3]))) bad[f] = 1;
    }
  }
  for (int f = 0; f <= max_face; ++f)
    if (bad[f]) plane[f].setZero();
  return plane;
}

}  // namespace

VecXd node_densities(const TetMesh& mesh, const VecXd& density) {
  const long nv = mesh.V.rows();
  VecXd sum = VecXd::Zero(nv), wsum = VecXd::Zero(nv);
  std::vector<char> design_node(nv, 0);
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (mesh.domain.size() == mesh.T.rows() && mesh.domain[t] != 0) continue;
    const double v = tet_volume(mesh.V.row(mesh.T(t, 0)), mesh.V.row(mesh.T(t, 1)), mesh.V.row(mesh.T(t, 2)),
                                mesh.V.row(mesh.T(t, 3)));
    for (int a = 0; a < 4; ++a) {
      sum[mesh.T(t, a)] += v * density[t];
      wsum[mesh.T(t, a)] += v;
    }
  }
  VecXd out(nv);
  for (long i = 0; i < nv; ++i) out[i] = wsum[i] > 0 ? sum[i] / wsum[i] : 1.0;
  return out;
}

double kept_tet_volume(const TetMesh& mesh, const VecXd& node_density, double threshold, long t) {
  std::array<Eigen::Vector3d, 4> p;
  std::array<double, 4> f;
  const bool design = mesh.domain.size() != mesh.T.rows() || mesh.domain[t] == 0;
  for (int a = 0; a < 4; ++a)
    p[a] = mesh.V.row(mesh.T(t, a)), f[a] = design ? level(node_density, mesh.T(t, a), threshold) : 1.0;
  return kept_volume(p, f);
}

double kept_design_volume(const TetMesh& mesh, const VecXd& node_density, double threshold) {
  double total = 0;
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (mesh.domain.size() != mesh.T.rows() || mesh.domain[t] == 0)
      total += kept_tet_volume(mesh, node_density, threshold, t);
  return total;
}

namespace {

/// Node densities within this of the threshold count as lying on it.
constexpr double kOnThreshold = 1e-9;
/// How far off_plateau moves the threshold past the plateau (at most half the gap to the next value).
constexpr double kPlateauStep = 1e-6;

/// `t` moved off the node densities lying on it (within kOnThreshold: a plateau of equal
/// densities, as extrusion or a grey region gives), to just below or just above them, whichever
/// keeps the design volume nearer `target`. On the plateau each node's side would be set by the
/// filter's rounding, not by the design. Unchanged when no node lies that close.
double off_plateau(const TetMesh& mesh, const VecXd& node_density, double t, double target) {
  double below = 0, above = 1, low = 2, high = -1;
  for (long i = 0; i < node_density.size(); ++i) {
    const double d = node_density[i];
    if (std::abs(d - t) <= kOnThreshold)
      low = std::min(low, d), high = std::max(high, d);
    else if (d < t)
      below = std::max(below, d);
    else
      above = std::min(above, d);
  }
  if (high < low) return t;
  const double down = low - std::min(kPlateauStep, 0.5 * (low - below));
  const double up = high + std::min(kPlateauStep, 0.5 * (above - high));
  const double miss_down = std::abs(kept_design_volume(mesh, node_density, down) - target);
  return miss_down <= std::abs(kept_design_volume(mesh, node_density, up) - target) ? down : up;
}

}  // namespace

double threshold_for_volume(const TetMesh& mesh, const VecXd& node_density, double volume_fraction) {
  if (!(volume_fraction > 0 && volume_fraction < 1))
    throw Error(ErrorCode::InvalidParameter, "the volume fraction must lie strictly between 0 and 1");
  const double target = volume_fraction * kept_design_volume(mesh, node_density, -1.0);
  double lo = 0, hi = 1;
  for (int k = 0; k < 50; ++k) {
    double mid = 0.5 * (lo + hi);
    (kept_design_volume(mesh, node_density, mid) > target ? lo : hi) = mid;
  }
  return off_plateau(mesh, node_density, 0.5 * (lo + hi), target);
}

namespace {

/// The least share of an edge between a level crossing and the edge's nodes, whatever the
/// margin: a crossing much closer to a node than this is not representable apart from the
/// node in double precision (its rounded position can leave the edge, or equal the node) and
/// the exact self-intersection check then finds folded or degenerate triangles there. It
/// moves the surface by at most a millionth of an edge.
constexpr double kLeastCrossingShare = 1e-6;

/// Builds the result surface piece by piece: its points (mesh nodes and level crossings on mesh
/// edges, each made once), its triangles with their tags, and each point's lock and cut-line
/// face (TriSurface's fields).
class IsoSurfaceBuilder {
 public:
  IsoSurfaceBuilder(const TetMesh& mesh, const VecXd& node_density, double threshold, double margin)
      : mesh_(mesh), tagged_(mesh.domain.size() == mesh.T.rows()) {
    values_.resize(mesh.V.rows());
    for (long i = 0; i < mesh.V.rows(); ++i) values_[i] = level(node_density, static_cast<int>(i), threshold);
    keep_crossings_off_nodes(std::max(margin, kLeastCrossingShare));
  }

  /// Iso-triangles inside every design tet the level crosses, oriented out of the kept side.
  void cut_design_tets() {
    for (long t = 0; t < mesh_.T.rows(); ++t)
      if (is_design(t)) cut_tet(t);
  }

  /// The faces of the mesh's boundary (Ω's: kept parts of design tets' faces, non-design tets'
  /// faces whole) and the void side of the faces between design and non-design tets.
  void add_boundary_and_interfaces() {
    const FaceSides sides = face_sides();
    const std::unordered_map<FaceKey, int, FaceKeyHash> tag_of = boundary_tags();
    for (const auto& [key, owner] : sides.boundary) {
      const auto ft = tag_of.find(key);
      const int tag = ft != tag_of.end() && ft->second != 0 ? ft->second : kUntagged;
      add_boundary_face(owner.first, owner.second, tag);
    }
    for (const auto& [t, i] : sides.interfaces) {
      const int* o = kTetFace[i];
      clip(mesh_.T(t, o[0]), mesh_.T(t, o[1]), mesh_.T(t, o[2]), false, -mesh_.domain[t], 2);
    }
  }

  /// The surface built so far (a boundary face the mesh did not tag gets tag 0).
  TriSurface finish() {
    TriSurface s;
    s.V.resize(pts_.size(), 3);
    for (size_t i = 0; i < pts_.size(); ++i) s.V.row(i) = pts_[i];
    s.F.resize(tris_.size(), 3);
    for (size_t i = 0; i < tris_.size(); ++i) s.F.row(i) << tris_[i][0], tris_[i][1], tris_[i][2];
    s.tag = Eigen::Map<VecXi>(tags_.data(), tags_.size());
    s.lock = Eigen::Map<VecXi>(lock_.data(), lock_.size());
    s.point_face = Eigen::Map<VecXi>(pface_.data(), pface_.size());
    for (int k = 0; k < s.tag.size(); ++k)
      if (s.tag[k] == kUntagged) s.tag[k] = 0;
    s.face_plane = planar_faces(mesh_);
    return s;
  }

 private:
  /// The tag of a boundary face the mesh did not tag (still Ω's boundary) until finish().
  static constexpr int kUntagged = 1 << 29;
  /// Faces of the mesh used by one tet (key -> (tet, local face)), and the faces between a
  /// design and a non-design tet, as (non-design tet, local face).
  struct FaceSides {
    std::unordered_map<FaceKey, std::pair<long, int>, FaceKeyHash> boundary;
    std::vector<std::array<long, 2>> interfaces;
  };

  bool is_design(long t) const { return !tagged_ || mesh_.domain[t] == 0; }
  double f(int node) const { return values_[node]; }

  /// Raises |f| at nodes the level passes too close to, until every crossed edge ab has
  /// |f(a)| >= k |f(b)| and |f(b)| >= k |f(a)| with k = margin / (1 - margin) for the values
  /// as finally adjusted (the same values every triangle then uses): its crossing lies at
  /// least `margin` of the edge from both nodes. A raised node raises its crossed neighbours
  /// in turn (two nodes barely off the level next to each other both follow the larger value
  /// around them), so the values are settled largest first: a node's final value is k times
  /// its largest final crossed neighbour or its own, whichever is larger. Signs stay, so the
  /// surface's topology does not change; only its points move along their edges.
  void keep_crossings_off_nodes(double margin) {
    const double k = margin / (1 - margin);
    const std::vector<std::vector<int>> crossed = crossed_neighbours();
    std::vector<char> settled(values_.size(), 0);
    std::priority_queue<std::pair<double, int>> largest;  // (|f| proposed, node)
    for (size_t i = 0; i < values_.size(); ++i) largest.emplace(std::abs(values_[i]), static_cast<int>(i));
    while (!largest.empty()) {
      const auto [size, a] = largest.top();
      largest.pop();
      if (settled[a]) continue;
      settled[a] = 1;
      values_[a] = values_[a] > 0 ? size : -size;
      for (int b : crossed[a])
        if (!settled[b] && std::abs(values_[b]) < k * size) {
          values_[b] = values_[b] > 0 ? k * size : -k * size;
          largest.emplace(k * size, b);
        }
    }
  }

  /// For each node, the nodes across its design-tet edges with the other sign of the level,
  /// sorted, each once (an edge belongs to several tets).
  std::vector<std::vector<int>> crossed_neighbours() const {
    std::vector<std::vector<int>> out(values_.size());
    for (long t = 0; t < mesh_.T.rows(); ++t)
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j) {
          const int a = mesh_.T(t, i), b = mesh_.T(t, j);
          if ((values_[a] > 0) == (values_[b] > 0)) continue;
          out[a].push_back(b), out[b].push_back(a);
        }
    for (std::vector<int>& nb : out) {
      std::sort(nb.begin(), nb.end());
      nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    }
    return out;
  }

  int node_point(int n) {
    auto [it, fresh] = node_point_.emplace(n, static_cast<int>(pts_.size()));
    if (fresh) pts_.push_back(mesh_.V.row(n)), lock_.push_back(0), pface_.push_back(0);
    return it->second;
  }
  // The point where the level crosses the mesh edge ab (made once per edge).
  int edge_point(int a, int b) {
    auto key = std::minmax(a, b);
    auto [it, fresh] = edge_point_.emplace(std::make_pair(key.first, key.second), static_cast<int>(pts_.size()));
    if (fresh) {
      const double fa = f(a), fb = f(b);
      const double w = fa / (fa - fb);
      pts_.push_back(Eigen::Vector3d(mesh_.V.row(a)) +
                     w * (Eigen::Vector3d(mesh_.V.row(b)) - Eigen::Vector3d(mesh_.V.row(a))));
      lock_.push_back(0), pface_.push_back(0);
    }
    return it->second;
  }
  void emit(int a, int b, int c, int tag) {
    tris_.push_back({a, b, c});
    tags_.push_back(tag);
  }

  // Marching tetrahedra in tet t: one triangle around a lone vertex on its side, two across
  // a tet cut between two pairs.
  void cut_tet(long t) {
    int v[4];
    double fv[4];
    int np = 0;
    for (int a = 0; a < 4; ++a) v[a] = mesh_.T(t, a), fv[a] = f(v[a]), np += fv[a] > 0;
    if (np == 0 || np == 4) return;
    if (np == 1 || np == 3) {
      int i = 0;
      while ((fv[i] > 0) != (np == 1)) ++i;  // the lone vertex
      const int* o = kTetFace[i];
      const int p0 = edge_point(v[i], v[o[0]]), p1 = edge_point(v[i], v[o[1]]), p2 = edge_point(v[i], v[o[2]]);
      if (np == 1)
        emit(p0, p1, p2, 0);
      else
        emit(p0, p2, p1, 0);
      return;
    }
    int pos[2], neg[2], kp = 0, kn = 0;
    for (int a = 0; a < 4; ++a) (fv[a] > 0 ? pos[kp++] : neg[kn++]) = a;
    const int a = pos[0], b = pos[1], c = neg[0], d = neg[1];
    const int pac = edge_point(v[a], v[c]), pad = edge_point(v[a], v[d]), pbd = edge_point(v[b], v[d]),
              pbc = edge_point(v[b], v[c]);
    if (even_permutation(a, b, c, d)) {
      emit(pac, pad, pbd, 0), emit(pac, pbd, pbc, 0);
    } else {
      emit(pac, pbc, pbd, 0), emit(pac, pbd, pad, 0);
    }
  }

  FaceSides face_sides() const {
    FaceSides s;
    const long nt = mesh_.T.rows();
    s.boundary.reserve(2 * nt);
    for (long t = 0; t < nt; ++t)
      for (int i = 0; i < 4; ++i) {
        auto key = face_key(mesh_.T(t, kTetFace[i][0]), mesh_.T(t, kTetFace[i][1]), mesh_.T(t, kTetFace[i][2]));
        auto [it, fresh] = s.boundary.emplace(key, std::make_pair(t, i));
        if (fresh) continue;
        const long u = it->second.first;
        const int ui = it->second.second;
        if (is_design(t) != is_design(u))
          s.interfaces.push_back(is_design(t) ? std::array<long, 2>{u, ui} : std::array<long, 2>{t, i});
        s.boundary.erase(it);
      }
    return s;
  }

  // Ω's face tags of the boundary triangles (mesh.F), by key.
  std::unordered_map<FaceKey, int, FaceKeyHash> boundary_tags() const {
    std::unordered_map<FaceKey, int, FaceKeyHash> tag;
    for (long k = 0; k < mesh_.F.rows(); ++k)
      tag[face_key(mesh_.F(k, 0), mesh_.F(k, 1), mesh_.F(k, 2))] = mesh_.face.size() ? mesh_.face[k] : 0;
    return tag;
  }

  // Face i of tet t on Ω's boundary: clipped to the kept side in a design tet; whole on a
  // non-design solid, split where the cut of a neighbouring design face meets its edges (no
  // T-junctions), fanned from its centre.
  void add_boundary_face(long t, int i, int tag) {
    const int* o = kTetFace[i];
    const int v[3] = {mesh_.T(t, o[0]), mesh_.T(t, o[1]), mesh_.T(t, o[2])};
    if (is_design(t)) return clip(v[0], v[1], v[2], true, tag, 1);
    std::vector<int> poly;
    for (int k = 0; k < 3; ++k) {
      const int a = v[k], b = v[(k + 1) % 3];
      poly.push_back(node_point(a));
      if ((f(a) > 0) != (f(b) > 0)) poly.push_back(edge_point(a, b));
    }
    for (int p : poly) lock_[p] = 2;
    if (poly.size() == 3) return emit(poly[0], poly[1], poly[2], tag);
    const int centre = static_cast<int>(pts_.size());
    pts_.push_back(
        (Eigen::Vector3d(mesh_.V.row(v[0])) + Eigen::Vector3d(mesh_.V.row(v[1])) + Eigen::Vector3d(mesh_.V.row(v[2]))) /
        3);
    lock_.push_back(2), pface_.push_back(0);
    for (size_t k = 0; k < poly.size(); ++k) emit(centre, poly[k], poly[(k + 1) % poly.size()], tag);
  }

  // Clips the oriented triangle (x, y, z) to where the level is positive (keep_positive) or
  // negative, and emits the kept polygon fanned from its first point; its points get at least
  // `lock_level`, and on Ω's face `tag` (lock 1) the crossings record that face (-1 when on two).
  void clip(int x, int y, int z, bool keep_positive, int tag, int lock_level) {
    const int v[3] = {x, y, z};
    bool in[3];
    int nin = 0;
    for (int k = 0; k < 3; ++k) {
      in[k] = keep_positive ? f(v[k]) > 0 : f(v[k]) < 0;
      nin += in[k];
    }
    if (nin == 0) return;
    std::vector<int> poly;
    for (int k = 0; k < 3; ++k) {
      const int a = v[k], b = v[(k + 1) % 3];
      if (in[k]) poly.push_back(node_point(a));
      if (in[k] != in[(k + 1) % 3]) {
        const int e = edge_point(a, b);
        poly.push_back(e);
        if (lock_level == 1 && tag > 0 && lock_[e] < 2)  // a point of the cut line; on two faces: fixed
          pface_[e] = (pface_[e] == 0 || pface_[e] == tag) ? tag : -1;
      }
    }
    for (int p : poly) lock_[p] = std::max(lock_[p], lock_level);
    for (size_t k = 1; k + 1 < poly.size(); ++k) emit(poly[0], poly[k], poly[k + 1], tag);
  }

  const TetMesh& mesh_;
  const bool tagged_;
  std::vector<double> values_;  // the level at each node (node density - threshold, never 0)
  std::vector<Eigen::Vector3d> pts_;
  std::vector<int> lock_, pface_;
  std::vector<std::array<int, 3>> tris_;
  std::vector<int> tags_;
  std::unordered_map<int, int> node_point_;        // mesh node -> point
  std::map<std::pair<int, int>, int> edge_point_;  // sorted mesh edge -> point
};

}  // namespace

TriSurface extract_iso_surface(const TetMesh& mesh, const VecXd& node_density, double threshold, double margin) {
  IsoSurfaceBuilder b(mesh, node_density, threshold, margin);
  b.cut_design_tets();
  b.add_boundary_and_interfaces();
  return b.finish();
}

}  // namespace topopt::result
