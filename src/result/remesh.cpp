// Edge flips and collapses on the result surface (see remesh.h).
#include "result/remesh.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "result/result_check.h"

namespace topopt::result {
namespace {

using Tri = std::array<int, 3>;

/// Two triangles count as one plane when their unit normals' dot product is at least 1 − this
/// (about 1.4e-6 rad apart): the pieces of one mesh triangle cut at level crossings, rounding aside.
constexpr double kCoplanar = 1e-12;

Eigen::Vector3d normal_of(const MatX3d& V, const Tri& t) {
  const Eigen::Vector3d a = V.row(t[0]), b = V.row(t[1]), c = V.row(t[2]);
  return (b - a).cross(c - a);
}

/// The surface as editable triangles with each point's triangles.
class Remesher {
 public:
  Remesher(TriSurface& s, const RemeshParams& p) : s_(s), p_(p), alive_(s.F.rows(), 1), star_(s.V.rows()) {
    tris_.resize(s.F.rows());
    for (long t = 0; t < s.F.rows(); ++t) {
      tris_[t] = {s.F(t, 0), s.F(t, 1), s.F(t, 2)};
      for (int k = 0; k < 3; ++k) star_[s.F(t, k)].push_back(static_cast<int>(t));
    }
    tags_.assign(s.tag.data(), s.tag.data() + s.tag.size());
  }

  /// Sweeps until a sweep changes nothing or params.passes sweeps ran.
  void run() {
    for (int pass = 0; pass < p_.passes; ++pass) {
      long changes = 0;
      for (size_t t = 0; t < tris_.size(); ++t)
        if (alive_[t] && angle(static_cast<int>(t)) < p_.target_angle) changes += improve(static_cast<int>(t));
      if (changes == 0) break;
    }
  }

  /// Writes the live triangles and the used points back into s.
  RemeshReport finish() {
    std::vector<int> new_index(s_.V.rows(), -1);
    for (size_t t = 0; t < tris_.size(); ++t)
      if (alive_[t])
        for (int v : tris_[t])
          if (new_index[v] < 0) new_index[v] = 0;
    for (int i = 0; i < static_cast<int>(new_index.size()); ++i)
      if (new_index[i] == 0)
        new_index[i] = static_cast<int>(report_.kept_points.size()), report_.kept_points.push_back(i);
    const long np = static_cast<long>(report_.kept_points.size());
    MatX3d V(np, 3);
    VecXi lock(np), point_face(np);
    for (long i = 0; i < np; ++i) {
      const int old = report_.kept_points[i];
      V.row(i) = s_.V.row(old), lock[i] = s_.lock[old], point_face[i] = s_.point_face.size() ? s_.point_face[old] : 0;
    }
    std::vector<Tri> live;
    std::vector<int> tags;
    for (size_t t = 0; t < tris_.size(); ++t)
      if (alive_[t])
        live.push_back({new_index[tris_[t][0]], new_index[tris_[t][1]], new_index[tris_[t][2]]}),
            tags.push_back(tags_[t]);
    s_.F.resize(static_cast<long>(live.size()), 3);
    for (size_t t = 0; t < live.size(); ++t) s_.F.row(t) << live[t][0], live[t][1], live[t][2];
    s_.tag = Eigen::Map<VecXi>(tags.data(), static_cast<long>(tags.size()));
    s_.V = V, s_.lock = lock, s_.point_face = point_face;
    return report_;
  }

 private:
  double angle(int t) const { return min_triangle_angle(s_.V, tris_[t][0], tris_[t][1], tris_[t][2]); }
  double angle_of(const Tri& t) const { return min_triangle_angle(s_.V, t[0], t[1], t[2]); }
  bool planar(int tag) const {
    return tag > 0 && tag < static_cast<int>(s_.face_plane.size()) && s_.face_plane[tag].head<3>().norm() > 0;
  }
  /// Triangles the remesher may change: the free-form region, and Ω's planar faces if allowed.
  bool workable(int t) const { return tags_[t] == 0 || (p_.planar_faces && planar(tags_[t])); }

  /// The live triangles with both a and b.
  std::vector<int> edge_triangles(int a, int b) const {
    std::vector<int> out;
    for (int t : star_[a])
      if (alive_[t] && std::count(tris_[t].begin(), tris_[t].end(), b)) out.push_back(t);
    return out;
  }
  std::vector<int> neighbours(int a) const {
    std::vector<int> out;
    for (int t : star_[a])
      if (alive_[t])
        for (int v : tris_[t])
          if (v != a) out.push_back(v);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }

  /// Flips the best edge of t if that helps, else collapses its shortest edge. 1 if changed.
  int improve(int t) {
    std::array<int, 3> order = {0, 1, 2};  // edges k: (t[k], t[k+1]), longest first
    auto len = [&](int k) { return (s_.V.row(tris_[t][k]) - s_.V.row(tris_[t][(k + 1) % 3])).squaredNorm(); };
    std::sort(order.begin(), order.end(), [&](int x, int y) { return len(x) > len(y); });
    for (int k : order)
      if (flip(tris_[t][k], tris_[t][(k + 1) % 3])) return 1;
    for (int i = 2; i >= 0; --i) {
      const int a = tris_[t][order[i]], b = tris_[t][(order[i] + 1) % 3];
      if (collapse(a, b) || collapse(b, a)) return 1;
    }
    for (int v : tris_[t])
      if (relocate(v)) return 1;
    return 0;
  }

  /// The planar Ω face whose interior point v is (on Ω's boundary, not on the cut line, and
  /// every triangle around it on that one planar face), or 0. Such a point may move and go
  /// within the face's plane: the face stays where it was, its edges and the cut line too.
  int face_interior(int v) const {
    if (s_.lock[v] != 1 || !p_.planar_faces || (s_.point_face.size() && s_.point_face[v] != 0)) return 0;
    int f = 0;
    for (int t : star_[v])
      if (alive_[t]) {
        if (f != 0 && tags_[t] != f) return 0;
        f = tags_[t];
      }
    return planar(f) ? f : 0;
  }

  /// The planar Ω face whose cut line v lies on (on the line of that one face, every triangle
  /// around it on the face or the free-form region), or 0.
  int cut_line_face(int v) const {
    if (s_.lock[v] != 1 || !p_.planar_faces || s_.point_face.size() == 0) return 0;
    const int f = s_.point_face[v];
    if (!planar(f)) return 0;
    for (int t : star_[v])
      if (alive_[t] && tags_[t] != 0 && tags_[t] != f) return 0;
    return f;
  }

  /// v's neighbours along the cut line of face f: edges with a triangle of f and one free-form.
  std::vector<int> line_neighbours(int v, int f) const {
    std::vector<int> out;
    for (int w : neighbours(v)) {
      const std::vector<int> e = edge_triangles(v, w);
      if (e.size() == 2 && ((tags_[e[0]] == 0 && tags_[e[1]] == f) || (tags_[e[0]] == f && tags_[e[1]] == 0)))
        out.push_back(w);
    }
    return out;
  }

  /// Where relocate moves v towards and the normal of the plane the move stays in: a free point,
  /// the mean of its neighbours in the plane of its star (area-weighted normal); a point inside a
  /// planar Ω face, the mean of its neighbours in the face's plane; a point of a planar face's cut
  /// line, the mean of its two neighbours on that line, in the face's plane (as the smoothing moves
  /// it). face: the planar face (0 for a free point). False when v may not move.
  bool relocation_target(int v, Eigen::Vector3d& mean, Eigen::Vector3d& n, int& face) const {
    face = face_interior(v);
    std::vector<int> nb;
    if (s_.lock[v] == 0 || face != 0) {
      nb = neighbours(v);
      if (nb.size() < 3) return false;
    } else {
      face = cut_line_face(v);
      if (face == 0) return false;
      nb = line_neighbours(v, face);
      if (nb.size() != 2) return false;
    }
    mean.setZero();
    for (int w : nb) mean += s_.V.row(w).transpose();
    mean /= static_cast<double>(nb.size());
    n.setZero();
    if (face != 0) n = s_.face_plane[face].head<3>();
    for (int t : star_[v])
      if (face == 0 && alive_[t]) n += normal_of(s_.V, tris_[t]);
    if (n.norm() == 0) return false;
    n.normalize();
    return true;
  }

  /// Moves point v towards its relocation_target, within the target's plane, by the full step or
  /// half of it, when that raises the smallest angle of its triangles and turns none by more than
  /// max_normal_turn (a point of a planar Ω face ends on the face's plane to rounding).
  bool relocate(int v) {
    Eigen::Vector3d mean, n;
    int face = 0;
    if (!relocation_target(v, mean, n, face)) return false;
    double worst_before = 180;
    for (int t : star_[v])
      if (alive_[t]) worst_before = std::min(worst_before, angle(t));
    const Eigen::Vector3d p0 = s_.V.row(v).transpose();
    Eigen::Vector3d step = mean - p0;
    step -= step.dot(n) * n;
    const double cos_turn = std::cos(p_.max_normal_turn * M_PI / 180);
    for (double share : {1.0, 0.5}) {
      std::vector<Eigen::Vector3d> normals;
      for (int t : star_[v])
        if (alive_[t]) normals.push_back(normal_of(s_.V, tris_[t]));
      Eigen::Vector3d p = p0 + share * step;
      if (face != 0) p -= (n.dot(p) - s_.face_plane[face][3]) * n;  // on the plane to rounding
      s_.V.row(v) = p.transpose();
      double worst_after = 180;
      bool turned = false;
      size_t k = 0;
      for (int t : star_[v]) {
        if (!alive_[t]) continue;
        const Eigen::Vector3d n1 = normal_of(s_.V, tris_[t]), n0 = normals[k++];
        turned |= n1.norm() == 0 || n0.norm() == 0 || n0.normalized().dot(n1.normalized()) < cos_turn;
        worst_after = std::min(worst_after, angle(t));
      }
      if (!turned && worst_after > worst_before + 1e-9) {
        ++report_.moves;
        return true;
      }
      s_.V.row(v) = p0.transpose();
    }
    return false;
  }

  /// Flips edge ab when its two triangles share a tag and lie nearly in one plane (on the
  /// free-form region: bent less than flat_dihedral; on a planar Ω face: its plane; on any other
  /// face: one plane to kCoplanar), and the flip raises their smallest angle. Flips move no point.
  bool flip(int a, int b) {
    const std::vector<int> e = edge_triangles(a, b);
    if (e.size() != 2 || tags_[e[0]] != tags_[e[1]]) return false;
    int t1 = e[0], t2 = e[1];
    // t1 holds the directed edge a -> b
    auto has_ab = [&](int t) {
      for (int k = 0; k < 3; ++k)
        if (tris_[t][k] == a && tris_[t][(k + 1) % 3] == b) return true;
      return false;
    };
    if (!has_ab(t1)) std::swap(t1, t2);
    if (!has_ab(t1)) return false;
    const int c = third(t1, a, b), d = third(t2, a, b);
    if (c == d || edge_triangles(c, d).size() > 0) return false;
    const Eigen::Vector3d n1 = normal_of(s_.V, tris_[t1]), n2 = normal_of(s_.V, tris_[t2]);
    if (n1.norm() == 0 || n2.norm() == 0) return false;
    // elsewhere (non-design faces, curved Ω faces) only within one plane: the surface stays put
    if (!workable(t1) && n1.normalized().dot(n2.normalized()) < 1 - kCoplanar) return false;
    if (tags_[t1] == 0 && n1.normalized().dot(n2.normalized()) < std::cos(p_.flat_dihedral * M_PI / 180)) return false;
    const Tri u = {a, d, c}, w = {d, b, c};
    const Eigen::Vector3d m = n1.normalized() + n2.normalized();
    if (normal_of(s_.V, u).dot(m) <= 0 || normal_of(s_.V, w).dot(m) <= 0) return false;
    if (std::min(angle_of(u), angle_of(w)) <= std::min(angle_of(tris_[t1]), angle_of(tris_[t2])) + 1e-9) return false;
    tris_[t1] = u, tris_[t2] = w;
    star_[d].push_back(t1), star_[c].push_back(t2);
    drop(b, t1), drop(a, t2);
    ++report_.flips;
    return true;
  }

  int third(int t, int a, int b) const {
    for (int v : tris_[t])
      if (v != a && v != b) return v;
    return -1;
  }
  void drop(int v, int t) { star_[v].erase(std::remove(star_[v].begin(), star_[v].end(), t), star_[v].end()); }

  /// Whether v may be removed by a collapse into a neighbour without any point moving, the face it
  /// lies inside staying where it is: every triangle around v has one tag f != 0, and either v is
  /// a point of Ω's face f (lock 1, not on its cut line; a curved face keeps its points, the
  /// triangles stay chords of it) or v is a non-design point (lock 2) whose triangles lie in one
  /// plane and whose neighbours are all non-design points (the FE mesh's own boundary triangles
  /// re-triangulated within their plane, the border of a non-design footprint kept).
  bool removable_inside(int v) const {
    if (!p_.planar_faces || s_.lock[v] == 0 || (s_.point_face.size() && s_.point_face[v] != 0)) return false;
    int f = 0;
    Eigen::Vector3d n0 = Eigen::Vector3d::Zero();
    for (int t : star_[v]) {
      if (!alive_[t]) continue;
      const Eigen::Vector3d n = normal_of(s_.V, tris_[t]);
      if (f == 0) f = tags_[t], n0 = n.normalized();
      if (tags_[t] != f || f == 0 || n.norm() == 0) return false;
      if (s_.lock[v] == 2 && n.normalized().dot(n0) < 1 - kCoplanar) return false;
    }
    if (s_.lock[v] == 2)  // not on the border of a non-design solid's footprint on an Ω face
      for (int w : neighbours(v))
        if (s_.lock[w] != 2) return false;
    return f != 0 && (s_.lock[v] == 2 || f > 0);
  }

  /// Whether point v may go into its neighbour u: v free, inside a planar Ω face, removable from
  /// inside a face (removable_inside), or on the cut line of an Ω face with uv along that line
  /// (one triangle of the face and one of the free-form on it; on a curved face no point moves,
  /// the line keeps its other points).
  bool may_go(int v, int u) const {
    if (s_.lock[v] == 0 || face_interior(v) != 0 || removable_inside(v)) return true;
    if (s_.lock[v] != 1 || !p_.planar_faces) return false;
    const int f = s_.point_face.size() ? s_.point_face[v] : 0;
    if (f <= 0) return false;
    const std::vector<int> e = edge_triangles(u, v);
    if (e.size() != 2) return false;
    const bool along = (tags_[e[0]] == 0 && tags_[e[1]] == f) || (tags_[e[0]] == f && tags_[e[1]] == 0);
    // v's triangles all on the free-form region or on face f
    for (int t : star_[v])
      if (alive_[t] && tags_[t] != 0 && tags_[t] != f) return false;
    return along;
  }

  /// Collapses v into u when may_go and the result keeps the surface manifold and no worse.
  bool collapse(int v, int u) {
    if (!may_go(v, u)) return false;
    const std::vector<int> shared = edge_triangles(u, v);
    if (shared.size() != 2) return false;
    // link condition: u and v share exactly the two opposite points
    std::vector<int> nu = neighbours(u), nv = neighbours(v), common;
    std::set_intersection(nu.begin(), nu.end(), nv.begin(), nv.end(), std::back_inserter(common));
    if (common.size() != 2) return false;
    double worst_before = 180, worst_after = 180;
    const double cos_turn = std::cos(p_.max_normal_turn * M_PI / 180);
    for (int t : star_[v]) {
      if (!alive_[t]) continue;
      worst_before = std::min(worst_before, angle(t));
      if (std::count(shared.begin(), shared.end(), t)) continue;
      Tri moved = tris_[t];
      std::replace(moved.begin(), moved.end(), v, u);
      const Eigen::Vector3d n0 = normal_of(s_.V, tris_[t]), n1 = normal_of(s_.V, moved);
      if (n1.norm() == 0 || n0.norm() == 0 || n0.normalized().dot(n1.normalized()) < cos_turn) return false;
      worst_after = std::min(worst_after, angle_of(moved));
    }
    if (worst_after <= worst_before) return false;
    for (int t : shared) {
      alive_[t] = 0;
      for (int w : tris_[t]) drop(w, t);
    }
    for (int t : star_[v])
      if (alive_[t]) std::replace(tris_[t].begin(), tris_[t].end(), v, u), star_[u].push_back(t);
    star_[v].clear();
    ++report_.collapses;
    return true;
  }

  TriSurface& s_;
  const RemeshParams& p_;
  std::vector<Tri> tris_;
  std::vector<int> tags_;
  std::vector<char> alive_;
  std::vector<std::vector<int>> star_;
  RemeshReport report_;
};

}  // namespace

RemeshReport remesh_surface(TriSurface& s, const RemeshParams& params) {
  Remesher r(s, params);
  r.run();
  return r.finish();
}

}  // namespace topopt::result
