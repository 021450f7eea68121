// Local 1 -> 8 refinement near the iso-level with a conformal closure (see iso_surface_refine.h).
#include "result/iso_surface_refine.h"

#include <algorithm>
#include <array>
#include <map>
#include <unordered_map>
#include <vector>

#include "common/error.h"
#include "common/face_key.h"
#include "fem/tet_element.h"
#include "mesh/core/predicates.h"

namespace topopt::result {
namespace {

/// The six edges of a tet by local node pairs; a midpoint's slot in `Tet10` is 4 + the edge's index.
constexpr int kTetEdge[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

/// #V by 3: at each node, the volume-weighted mean of the gradients of the linear field (node
/// values f) over the design tets around it; zero at nodes of no design tet.
MatX3d node_gradients(const TetMesh& mesh, const VecXd& f) {
  const bool tagged = mesh.domain.size() == mesh.T.rows();
  MatX3d g = MatX3d::Zero(mesh.V.rows(), 3);
  VecXd w = VecXd::Zero(mesh.V.rows());
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (tagged && mesh.domain[t] != 0) continue;
    double N[12] = {};  // ∂N_a/∂x_c of the tet's linear shape functions (fem::tet_gradients)
    const double vol = fem::tet_gradients(mesh, t, N) / 6;
    if (!(vol > 0)) continue;  // the mesh's tets are positive: never taken on a valid mesh
    Eigen::Vector3d grad = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) grad += f[mesh.T(t, a)] * Eigen::Vector3d(N[3 * a], N[3 * a + 1], N[3 * a + 2]);
    for (int a = 0; a < 4; ++a) g.row(mesh.T(t, a)) += vol * grad.transpose(), w[mesh.T(t, a)] += vol;
  }
  for (long i = 0; i < g.rows(); ++i)
    if (w[i] > 0) g.row(i) /= w[i];
  return g;
}

/// Builds the refined mesh: its points with their densities, its tets and Ω's boundary triangles.
class Refiner {
 public:
  Refiner(const TetMesh& mesh, const VecXd& rho) : in_(mesh), grad_(node_gradients(mesh, rho)) {
    for (long i = 0; i < mesh.V.rows(); ++i) pts_.push_back(mesh.V.row(i)), val_.push_back(rho[i]);
  }

  /// Marks the design tets to split: those the level crosses and their design face neighbours;
  /// gives all their edges a midpoint.
  void mark(double threshold) {
    const long nt = in_.T.rows();
    split_.assign(nt, 0);
    std::unordered_map<FaceKey, std::vector<long>, FaceKeyHash> around;
    for (long t = 0; t < nt; ++t)
      for (const auto& o : kTetFace) around[face_key(in_.T(t, o[0]), in_.T(t, o[1]), in_.T(t, o[2]))].push_back(t);
    for (long t = 0; t < nt; ++t) {
      if (!is_design(t) || !crossed(t, threshold)) continue;
      split_[t] = 1;
      for (const auto& o : kTetFace)
        for (long u : around[face_key(in_.T(t, o[0]), in_.T(t, o[1]), in_.T(t, o[2]))])
          if (is_design(u)) split_[u] = 1;
    }
    for (long t = 0; t < nt; ++t)
      if (split_[t])
        for (const auto& e : kTetEdge) midpoint(in_.T(t, e[0]), in_.T(t, e[1]));
  }

  /// Every input tet into the output: split ones 1 -> 8, ones with some split edges coned from
  /// their centre, the others as they are.
  void fill(RefinedField& out) {
    for (long t = 0; t < in_.T.rows(); ++t) {
      const int dom = in_.domain.size() == in_.T.rows() ? in_.domain[t] : 0;
      if (split_[t]) {
        split_tet(t, dom), ++out.refined;
      } else if (has_split_edge(t)) {
        cone_tet(t, dom), ++out.closed;
      } else {
        add_tet({in_.T(t, 0), in_.T(t, 1), in_.T(t, 2), in_.T(t, 3)}, dom);
      }
    }
  }

  /// Ω's boundary triangles, subdivided as the faces of the tets under them, orientation and tags kept.
  void boundary(TetMesh& m) {
    std::vector<std::array<int, 3>> tris;
    std::vector<int> face, nd;
    const bool has_face = in_.face.size() == in_.F.rows(), has_nd = in_.nd_face.size() == in_.F.rows();
    for (long k = 0; k < in_.F.rows(); ++k)
      for (const auto& tri : split_face(in_.F(k, 0), in_.F(k, 1), in_.F(k, 2))) {
        tris.push_back(tri);
        face.push_back(has_face ? in_.face[k] : 0);
        nd.push_back(has_nd ? in_.nd_face[k] : 0);
      }
    m.F.resize(static_cast<long>(tris.size()), 3);
    for (size_t i = 0; i < tris.size(); ++i) m.F.row(static_cast<long>(i)) << tris[i][0], tris[i][1], tris[i][2];
    if (has_face) m.face = Eigen::Map<VecXi>(face.data(), static_cast<long>(face.size()));
    if (has_nd) m.nd_face = Eigen::Map<VecXi>(nd.data(), static_cast<long>(nd.size()));
  }

  /// The points, densities and tets built.
  void finish(RefinedField& out) {
    TetMesh& m = out.mesh;
    m.V.resize(static_cast<long>(pts_.size()), 3);
    for (size_t i = 0; i < pts_.size(); ++i) m.V.row(static_cast<long>(i)) = pts_[i];
    out.node_density = Eigen::Map<VecXd>(val_.data(), static_cast<long>(val_.size()));
    m.T.resize(static_cast<long>(tets_.size()), 4);
    for (size_t i = 0; i < tets_.size(); ++i)
      m.T.row(static_cast<long>(i)) << tets_[i][0], tets_[i][1], tets_[i][2], tets_[i][3];
    if (in_.domain.size() == in_.T.rows()) m.domain = Eigen::Map<VecXi>(dom_.data(), static_cast<long>(dom_.size()));
  }

 private:
  bool is_design(long t) const { return in_.domain.size() != in_.T.rows() || in_.domain[t] == 0; }

  bool crossed(long t, double threshold) const {
    int above = 0;
    for (int a = 0; a < 4; ++a) above += val_[in_.T(t, a)] >= threshold;
    return above > 0 && above < 4;
  }

  int add_point(const Eigen::Vector3d& x, double v) {
    pts_.push_back(x), val_.push_back(v);
    return static_cast<int>(pts_.size()) - 1;
  }

  /// The midpoint of edge ab (made once): its density by cubic Hermite interpolation along the
  /// edge, f(½) = (fa + fb) / 2 + (ga − gb)·(b − a) / 8, clamped to [0, 1].
  int midpoint(int a, int b) {
    const auto key = std::minmax(a, b);
    const auto found = mid_.find(key);
    if (found != mid_.end()) return found->second;
    const Eigen::Vector3d xa = in_.V.row(a), xb = in_.V.row(b);
    const double v = 0.5 * (val_[a] + val_[b]) + (grad_.row(a) - grad_.row(b)).dot((xb - xa).transpose()) / 8;
    const int p = add_point(0.5 * (xa + xb), std::clamp(v, 0.0, 1.0));
    mid_.emplace(key, p);
    return p;
  }

  int midpoint_if_any(int a, int b) const {
    const auto found = mid_.find(std::minmax(a, b));
    return found == mid_.end() ? -1 : found->second;
  }

  bool has_split_edge(long t) const {
    for (const auto& e : kTetEdge)
      if (midpoint_if_any(in_.T(t, e[0]), in_.T(t, e[1])) >= 0) return true;
    return false;
  }

  /// Appends tet q with domain tag dom, turned positive (orientation by the exact predicate).
  void add_tet(std::array<int, 4> q, int dom) {
    const int o =
        mesh::predicates::orient3d(pts_[q[0]].data(), pts_[q[1]].data(), pts_[q[2]].data(), pts_[q[3]].data());
    if (o == 0) throw Error(ErrorCode::MeshingFailed, "refining the result mesh made a flat tet (internal error)");
    if (o < 0) std::swap(q[2], q[3]);
    tets_.push_back(q), dom_.push_back(dom);
  }

  /// Triangle (a, b, c) split along its split edges, each piece turning as (a, b, c): four
  /// triangles at the midpoints when all three edges are split, a fan from the face's centre
  /// when one or two are, itself when none. The same for every tet and boundary list sharing it.
  std::vector<std::array<int, 3>> split_face(int a, int b, int c) {
    const int m[3] = {midpoint_if_any(a, b), midpoint_if_any(b, c), midpoint_if_any(c, a)};
    const int n = (m[0] >= 0) + (m[1] >= 0) + (m[2] >= 0);
    if (n == 0) return {{a, b, c}};
    if (n == 3) return {{a, m[0], m[2]}, {m[0], b, m[1]}, {m[2], m[1], c}, {m[0], m[1], m[2]}};
    const int v[3] = {a, b, c};
    std::vector<int> ring;
    for (int k = 0; k < 3; ++k) {
      ring.push_back(v[k]);
      if (m[k] >= 0) ring.push_back(m[k]);
    }
    const int centre = face_centre(a, b, c);
    std::vector<std::array<int, 3>> out;
    for (size_t k = 0; k < ring.size(); ++k) out.push_back({ring[k], ring[(k + 1) % ring.size()], centre});
    return out;
  }

  int face_centre(int a, int b, int c) {
    const FaceKey key = face_key(a, b, c);
    const auto found = centre_.find(key);
    if (found != centre_.end()) return found->second;
    const int p = add_point((pts_[a] + pts_[b] + pts_[c]) / 3, (val_[a] + val_[b] + val_[c]) / 3);
    centre_.emplace(key, p);
    return p;
  }

  /// Red refinement: four corner tets and the inner octahedron cut along its shortest diagonal.
  void split_tet(long t, int dom) {
    std::array<int, 10> p;  // corners 0..3, then the midpoints of kTetEdge
    for (int a = 0; a < 4; ++a) p[a] = in_.T(t, a);
    for (int e = 0; e < 6; ++e) p[4 + e] = midpoint(p[kTetEdge[e][0]], p[kTetEdge[e][1]]);
    auto slot = [&](int i, int j) {  // the midpoint of corners i, j
      for (int e = 0; e < 6; ++e)
        if ((kTetEdge[e][0] == i && kTetEdge[e][1] == j) || (kTetEdge[e][0] == j && kTetEdge[e][1] == i))
          return p[4 + e];
      return -1;
    };
    for (int a = 0; a < 4; ++a) {
      std::array<int, 4> q;
      for (int b = 0; b < 4; ++b) q[b] = b == a ? p[a] : slot(a, b);
      add_tet(q, dom);
    }
    // opposite edge pairs (0,5), (1,4), (2,3) of kTetEdge give the octahedron's three diagonals
    int best = 0;
    double shortest = 0;
    for (int e = 0; e < 3; ++e) {
      const double len = (pts_[p[4 + e]] - pts_[p[9 - e]]).squaredNorm();
      if (e == 0 || len < shortest) best = e, shortest = len;
    }
    const int d0 = p[4 + best], d1 = p[9 - best];
    // the other four midpoints in a cycle: each next to the two that share a corner with it
    std::vector<int> rest;
    for (int e = 0; e < 3; ++e)
      if (e != best) rest.push_back(4 + e), rest.push_back(9 - e);
    const int ring[4] = {p[rest[0]], p[rest[2]], p[rest[1]], p[rest[3]]};
    for (int k = 0; k < 4; ++k) add_tet({d0, d1, ring[k], ring[(k + 1) % 4]}, dom);
  }

  /// Closure: the tet's faces split as their neighbours split them, coned to the tet's centre.
  void cone_tet(long t, int dom) {
    int v[4];
    double mean = 0;
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) v[a] = in_.T(t, a), x += pts_[v[a]], mean += val_[v[a]];
    const int centre = add_point(x / 4, mean / 4);
    for (const auto& o : kTetFace)
      for (const auto& tri : split_face(v[o[0]], v[o[1]], v[o[2]])) add_tet({tri[0], tri[1], tri[2], centre}, dom);
  }

  const TetMesh& in_;
  const MatX3d grad_;
  std::vector<Eigen::Vector3d> pts_;
  std::vector<double> val_;
  std::vector<char> split_;
  std::map<std::pair<int, int>, int> mid_;
  std::unordered_map<FaceKey, int, FaceKeyHash> centre_;
  std::vector<std::array<int, 4>> tets_;
  std::vector<int> dom_;
};

}  // namespace

RefinedField refine_near_level(const TetMesh& mesh, const VecXd& node_density, double threshold) {
  RefinedField out;
  Refiner r(mesh, node_density);
  r.mark(threshold);
  r.fill(out);
  r.boundary(out.mesh);
  r.finish(out);
  return out;
}

}  // namespace topopt::result
