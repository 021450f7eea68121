// Edge flips and collapses on the result surface (see remesh.h).
#include "result/remesh.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "result/crossing_guard.h"
#include "result/editable_surface.h"
#include "result/result_check.h"

namespace topopt::result {
namespace {

using Tri = std::array<int, 3>;

/// Two triangles count as one plane when their unit normals' dot product is at least 1 − this
/// (about 1.4e-6 rad apart): the pieces of one mesh triangle cut at level crossings, rounding aside.
constexpr double kCoplanar = 1e-12;

/// The surface as editable triangles with each point's triangles.
class Remesher {
 public:
  Remesher(TriSurface& s, const RemeshParams& p, const FaceProjector& onto)
      : s_(s),
        p_(p),
        onto_(onto),
        m_(s.F, s.tag, s.V.rows()),
        guard_(s_.V, m_),
        given_points_(static_cast<int>(s.V.rows())) {
    if (s_.point_face.size() != s_.V.rows()) s_.point_face = VecXi::Zero(s_.V.rows());
    if (onto_.nondesign_faces && onto_.onto_nondesign) nd_face_ = onto_.nondesign_faces(s_);
    nd_face_.resize(s_.F.rows(), -1);
  }

  /// Sweeps until a sweep changes nothing or params.passes sweeps ran.
  void run() {
    for (int pass = 0; pass < p_.passes; ++pass) {
      long changes = 0;
      const int n = m_.triangles();  // a pass visits the triangles it found (splits add some)
      for (int t = 0; t < n; ++t)
        if (m_.alive(t) && angle(t) < p_.target_angle) changes += improve(t);
      if (changes == 0) break;
    }
  }

  /// Writes the live triangles and the used points back into s.
  RemeshReport finish() {
    const std::vector<char> used = m_.used_points();
    std::vector<int> new_index(used.size(), -1);
    std::vector<int> old_of;
    for (int i = 0; i < static_cast<int>(used.size()); ++i)
      if (used[i]) new_index[i] = static_cast<int>(old_of.size()), old_of.push_back(i);
    const long np = static_cast<long>(old_of.size());
    MatX3d V(np, 3);
    VecXi lock(np), point_face(np);
    for (long i = 0; i < np; ++i) {
      const int old = old_of[i];
      V.row(i) = s_.V.row(old), lock[i] = s_.lock[old], point_face[i] = s_.point_face.size() ? s_.point_face[old] : 0;
      report_.kept_points.push_back(old < given_points_ ? old : -1);
    }
    m_.live(s_.F, s_.tag, &new_index);
    s_.V = V, s_.lock = lock, s_.point_face = point_face;
    return report_;
  }

 private:
  double angle(int t) const { return angle_of(m_.tri(t)); }
  double angle_of(const Tri& t) const { return min_triangle_angle(s_.V, t[0], t[1], t[2]); }
  /// The curved non-design face triangle t is a chord of (FaceProjector::nondesign_faces), or -1.
  int nd_face(int t) const { return m_.tag(t) < 0 ? nd_face_[t] : -1; }
  /// The curved non-design face both triangles e (an edge's two) are chords of, or -1.
  int shared_nd_face(const std::vector<int>& e) const {
    return e.size() == 2 && m_.tag(e[0]) == m_.tag(e[1]) && nd_face(e[0]) == nd_face(e[1]) ? nd_face(e[0]) : -1;
  }
  bool planar(int tag) const {
    return tag > 0 && tag < static_cast<int>(s_.face_plane.size()) && s_.face_plane[tag].head<3>().norm() > 0;
  }

  /// Flips the best edge of t if that helps, else collapses its shortest edge. 1 if changed.
  int improve(int t) {
    std::array<int, 3> order = {0, 1, 2};  // edges k: (t[k], t[k+1]), longest first
    auto len = [&](int k) { return (s_.V.row(m_.tri(t)[k]) - s_.V.row(m_.tri(t)[(k + 1) % 3])).squaredNorm(); };
    std::sort(order.begin(), order.end(), [&](int x, int y) { return len(x) > len(y); });
    for (int k : order)
      if (flip(m_.tri(t)[k], m_.tri(t)[(k + 1) % 3])) return 1;
    for (int i = 2; i >= 0; --i) {
      const int a = m_.tri(t)[order[i]], b = m_.tri(t)[(order[i] + 1) % 3];
      if (collapse(a, b) || collapse(b, a)) return 1;
    }
    for (int v : m_.tri(t))
      if (relocate(v)) return 1;
    return angle(t) < p_.split_angle ? split_needle(t) : 0;
  }

  /// Where a point splitting edge ab goes (`at`), its lock and cut-line face, or false when ab
  /// may not be split: its two triangles on the free-form region (a free point at the midpoint),
  /// on one planar Ω face (inside it), one free-form and one on a planar face (on the face's cut
  /// line), on two planar faces (on the edge between them; the midpoint lies on both planes), on
  /// one curved Ω face that `onto` knows (the midpoint projected onto its surface), or in one
  /// plane with a non-design triangle among them (nondesign_split). Other curved faces keep their edges.
  bool split_point(int a, int b, int& lock, int& face, Eigen::Vector3d& at) const {
    const std::vector<int> e = m_.edge_triangles(a, b);
    if (e.size() != 2 || (!p_.planar_faces && (m_.tag(e[0]) != 0 || m_.tag(e[1]) != 0))) return false;
    const int f0 = m_.tag(e[0]), f1 = m_.tag(e[1]);
    at = 0.5 * (s_.V.row(a) + s_.V.row(b)).transpose();
    if (f0 < 0 || f1 < 0) return nondesign_split(e, lock, face) || onto_nondesign_face(e, a, b, lock, face, at);
    if (f0 > 0 && f0 == f1 && !planar(f0)) {  // inside a curved face: onto its surface
      lock = 1, face = 0;
      return onto_.onto_face && projected(at, a, b, [&](Eigen::Vector3d& x) { return onto_.onto_face(f0, x); });
    }
    if (f0 > 0 && f1 > 0 && planar(f0) != planar(f1)) return on_curved_and_plane(f0, f1, a, b, lock, face, at);
    for (int t : e)
      if (m_.tag(t) > 0 && !planar(m_.tag(t))) return false;
    lock = (f0 == 0 && f1 == 0) ? 0 : 1;
    face = (f0 == 0) != (f1 == 0) ? std::max(f0, f1) : 0;
    return true;
  }

  /// Whether edge ab on the B-Rep edge between a curved Ω face and a planar one (f0, f1 in either
  /// order) may be split: the midpoint `at`, projected onto the curved face's surface (`onto`),
  /// still lies on the planar face's plane to 1e-9 of the edge, so it is a point of both faces (a
  /// straight line or a circle on a cylinder cut by a plane normal to its axis). The new point is
  /// a fixed point of Ω's edges (lock 1, on no cut line).
  bool on_curved_and_plane(int f0, int f1, int a, int b, int& lock, int& face, Eigen::Vector3d& at) const {
    const int curved = planar(f0) ? f1 : f0, flat = planar(f0) ? f0 : f1;
    const double len = (s_.V.row(a) - s_.V.row(b)).norm();
    const Eigen::Vector3d mid = at;
    lock = 1, face = 0;
    if (!onto_.onto_face || !onto_.onto_face(curved, at) || (at - mid).norm() > 0.25 * len) return false;
    const Eigen::Vector4d& plane = s_.face_plane[flat];
    return std::abs(plane.head<3>().dot(at) - plane[3]) <= 1e-9 * len * plane.head<3>().norm();
  }

  /// Whether the edge of triangles e (two, at least one non-design) may be split at its midpoint:
  /// both triangles lie in one plane (to kCoplanar) and the other is non-design or on a planar Ω
  /// face (the border of a non-design footprint on it), so the midpoint lies on the non-design
  /// solid's face as it was. The new point is a fixed non-design point (lock 2).
  bool nondesign_split(const std::vector<int>& e, int& lock, int& face) const {
    if (!p_.planar_faces) return false;
    for (int t : e)
      if (m_.tag(t) == 0 || (m_.tag(t) > 0 && !planar(m_.tag(t)))) return false;
    const Eigen::Vector3d n0 = normal_of(s_.V, m_.tri(e[0])), n1 = normal_of(s_.V, m_.tri(e[1]));
    if (n0.norm() == 0 || n1.norm() == 0 || n0.normalized().dot(n1.normalized()) < 1 - kCoplanar) return false;
    lock = 2, face = 0;
    return true;
  }

  /// Moves the midpoint `at` of edge ab onto a curved face's true surface (`onto`); true when that
  /// worked and moved it less than a quarter of the edge (the edge is a chord of that surface).
  template <class Onto>
  bool projected(Eigen::Vector3d& at, int a, int b, const Onto& onto) const {
    const Eigen::Vector3d mid = at;
    return onto(at) && (at - mid).norm() < 0.25 * (s_.V.row(a) - s_.V.row(b)).norm();
  }

  /// Whether edge ab of triangles e (two, non-design) may be split with the new point on the true
  /// surface of the curved non-design face both triangles are chords of (nondesign_faces): `at`,
  /// the midpoint, projected onto it. The new point is a fixed non-design point (lock 2) on the
  /// solid's face as the input has it (not on the FE mesh's chord of it).
  bool onto_nondesign_face(const std::vector<int>& e, int a, int b, int& lock, int& face, Eigen::Vector3d& at) const {
    const int id = shared_nd_face(e);
    if (!p_.planar_faces || id < 0) return false;
    lock = 2, face = 0;
    return projected(at, a, b, [&](Eigen::Vector3d& x) { return onto_.onto_nondesign(id, x); });
  }

  /// Adds a point at `at` with the given lock and cut-line face.
  void add_point(const Eigen::Vector3d& at, int lock, int face) {
    const long n = s_.V.rows();
    s_.V.conservativeResize(n + 1, 3), s_.lock.conservativeResize(n + 1), s_.point_face.conservativeResize(n + 1);
    s_.V.row(n) = at.transpose();
    s_.lock[n] = lock, s_.point_face[n] = face;
  }

  /// Mends needle t (corner a with the smallest angle, opposite the short edge bc): splits its
  /// longest edge ab at the midpoint p (split_point says where that is allowed) and flips the other
  /// long edge ac into p's opposite edge, so that (p, b, c) replaces the needle. Keeps both when
  /// the smallest angle of the triangles around p is larger than the one of the triangles they
  /// replace; else flips back and collapses p into b, which gives the triangles as they were.
  /// 1 if kept.
  int split_needle(int t) {
    const Tri& q = m_.tri(t);
    int k = 0;  // the corner with the smallest angle: opposite the shortest edge
    auto len = [&](int i, int j) { return (s_.V.row(i) - s_.V.row(j)).squaredNorm(); };
    for (int i = 1; i < 3; ++i)
      if (len(q[(i + 1) % 3], q[(i + 2) % 3]) < len(q[(k + 1) % 3], q[(k + 2) % 3])) k = i;
    int a = q[k], b = q[(k + 1) % 3], c = q[(k + 2) % 3];
    if (len(a, c) > len(a, b)) std::swap(b, c);
    int lock = 0, face = 0;
    Eigen::Vector3d at;
    if (!split_point(a, b, lock, face, at)) return 0;
    const std::vector<int> across = m_.edge_triangles(a, c);
    if (across.size() != 2 || m_.tag(across[0]) != m_.tag(across[1])) return 0;  // ac cannot flip
    double worst_before = angle(t);
    for (int u : m_.edge_triangles(a, b)) worst_before = std::min(worst_before, angle(u));
    for (int u : across) worst_before = std::min(worst_before, angle(u));
    add_point(at, lock, face);
    const std::vector<int> halved = m_.edge_triangles(a, b);
    const int p = m_.split_edge(a, b);
    for (int u : halved) nd_face_.push_back(nd_face_[u]);  // the new halves, in that order
    std::vector<int> flipped_to;  // the far corners of the edges flipped into edges of p, in order
    const int e = m_.third(across[0] == t ? across[1] : across[0], a, c);
    if (flip(a, c)) flipped_to.push_back(e);
    flip_link(p, flipped_to);
    double worst_after = 180;
    for (int u : m_.star(p)) worst_after = std::min(worst_after, angle(u));
    if (worst_after > worst_before + 1e-9 && !guard_.crosses(star_triangles(p), m_.star(p))) {
      for (int u : m_.star(p)) guard_.add(u);
      ++report_.splits;
      return 1;
    }
    undo_split(p, b, flipped_to);
    for (int u : m_.star(b)) guard_.add(u);  // every triangle the split changed had p, now b
    return 0;
  }

  /// The triangles around point v, as point triples.
  std::vector<Tri> star_triangles(int v) const {
    std::vector<Tri> out;
    for (int t : m_.star(v)) out.push_back(m_.tri(t));
    return out;
  }

  /// Flips the edges opposite p in its triangles where that raises the smallest angle of the two
  /// triangles (flip): halving a neighbour of the needle can leave a thin half, which a flip
  /// towards p's far side mends. Each flip makes an edge from p to the far corner, added to
  /// `flipped_to`. Two rounds over p's star.
  void flip_link(int p, std::vector<int>& flipped_to) {
    for (int round = 0; round < 2; ++round) {
      const std::vector<int> star = m_.star(p);
      for (int t : star) {
        if (!m_.alive(t)) continue;
        const Tri& q = m_.tri(t);
        const int k = static_cast<int>(std::find(q.begin(), q.end(), p) - q.begin());
        const int u = q[(k + 1) % 3], w = q[(k + 2) % 3];
        const std::vector<int> e = m_.edge_triangles(u, w);
        if (e.size() != 2) continue;
        const int x = m_.third(e[0] == t ? e[1] : e[0], u, w);
        if (flip(u, w)) flipped_to.push_back(x);
      }
    }
  }

  /// Undoes split_needle's split at p: flips back the edges from p to `flipped_to` (latest
  /// first), then collapses p into b, which gives the triangles as they were.
  void undo_split(int p, int b, const std::vector<int>& flipped_to) {
    for (auto x = flipped_to.rbegin(); x != flipped_to.rend(); ++x) {
      EditableSurface::Flip f;
      if (m_.flip_of(p, *x, f)) m_.flip(p, *x, f), --report_.flips;
    }
    if (m_.link_condition(b, p)) m_.collapse(p, b);
  }

  /// The planar Ω face whose interior point v is (on Ω's boundary, not on the cut line, and
  /// every triangle around it on that one planar face), or 0. Such a point may move and go
  /// within the face's plane: the face stays where it was, its edges and the cut line too.
  int face_interior(int v) const {
    if (s_.lock[v] != 1 || !p_.planar_faces || (s_.point_face.size() && s_.point_face[v] != 0)) return 0;
    int f = 0;
    for (int t : m_.star(v)) {
      if (f != 0 && m_.tag(t) != f) return 0;
      f = m_.tag(t);
    }
    return planar(f) ? f : 0;
  }

  /// The planar Ω face whose cut line v lies on (on the line of that one face, every triangle
  /// around it on the face or the free-form region), or 0.
  int cut_line_face(int v) const {
    if (s_.lock[v] != 1 || !p_.planar_faces || s_.point_face.size() == 0) return 0;
    const int f = s_.point_face[v];
    if (!planar(f)) return 0;
    for (int t : m_.star(v))
      if (m_.tag(t) != 0 && m_.tag(t) != f) return 0;
    return f;
  }

  /// v's neighbours along the cut line of face f: edges with a triangle of f and one free-form.
  std::vector<int> line_neighbours(int v, int f) const {
    std::vector<int> out;
    for (int w : m_.neighbours(v)) {
      const std::vector<int> e = m_.edge_triangles(v, w);
      if (e.size() == 2 && ((m_.tag(e[0]) == 0 && m_.tag(e[1]) == f) || (m_.tag(e[0]) == f && m_.tag(e[1]) == 0)))
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
      nb = m_.neighbours(v);
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
    for (int t : m_.star(v))
      if (face == 0) n += normal_of(s_.V, m_.tri(t));
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
    for (int t : m_.star(v)) worst_before = std::min(worst_before, angle(t));
    const Eigen::Vector3d p0 = s_.V.row(v).transpose();
    Eigen::Vector3d step = mean - p0;
    step -= step.dot(n) * n;
    const double cos_turn = std::cos(p_.max_normal_turn * M_PI / 180);
    for (double share : {1.0, 0.5}) {
      std::vector<Eigen::Vector3d> normals;
      for (int t : m_.star(v)) normals.push_back(normal_of(s_.V, m_.tri(t)));
      Eigen::Vector3d p = p0 + share * step;
      if (face != 0) p -= (n.dot(p) - s_.face_plane[face][3]) * n;  // on the plane to rounding
      s_.V.row(v) = p.transpose();
      double worst_after = 180;
      bool turned = false;
      size_t k = 0;
      for (int t : m_.star(v)) {
        const Eigen::Vector3d n1 = normal_of(s_.V, m_.tri(t)), n0 = normals[k++];
        turned |= n1.norm() == 0 || n0.norm() == 0 || n0.normalized().dot(n1.normalized()) < cos_turn;
        worst_after = std::min(worst_after, angle(t));
      }
      if (!turned && worst_after > worst_before + 1e-9 && !guard_.crosses(star_triangles(v), m_.star(v))) {
        for (int t : m_.star(v)) guard_.add(t);
        ++report_.moves;
        return true;
      }
      s_.V.row(v) = p0.transpose();
    }
    return false;
  }

  /// The cosine of the largest bend of the edge between triangles t1 and t2 (one tag) that a flip
  /// may turn: flat_dihedral on the free-form region, curved_dihedral on a curved Ω face (its four
  /// points stay on the face, the new triangles are chords of it as the old ones were) and between
  /// two chords of one curved non-design face (nondesign_faces), 90 on a planar Ω face (its
  /// triangles lie in its plane), and one plane to kCoplanar on the non-design solids' other faces
  /// (a tag names a solid, not a face: the flip must not cut an edge of it).
  double flip_min_cos(int t1, int t2) const {
    const int tag = m_.tag(t1);
    const double curved = std::cos(p_.curved_dihedral * M_PI / 180);
    if (tag == 0) return std::cos(p_.flat_dihedral * M_PI / 180);
    if (tag > 0 && p_.planar_faces) return planar(tag) ? 0 : curved;
    return p_.planar_faces && shared_nd_face({t1, t2}) >= 0 ? curved : 1 - kCoplanar;
  }

  /// Flips edge ab when its two triangles share a tag and bend less than flip_min_cos allows, and the
  /// flip raises their smallest angle. Flips move no point.
  bool flip(int a, int b) {
    EditableSurface::Flip f;
    if (!m_.flip_of(a, b, f)) return false;
    const Eigen::Vector3d n1 = normal_of(s_.V, m_.tri(f.t1)), n2 = normal_of(s_.V, m_.tri(f.t2));
    if (n1.norm() == 0 || n2.norm() == 0) return false;
    if (n1.normalized().dot(n2.normalized()) < flip_min_cos(f.t1, f.t2)) return false;
    const Eigen::Vector3d m = n1.normalized() + n2.normalized();
    if (normal_of(s_.V, f.u).dot(m) <= 0 || normal_of(s_.V, f.w).dot(m) <= 0) return false;
    if (std::min(angle_of(f.u), angle_of(f.w)) <= std::min(angle(f.t1), angle(f.t2)) + 1e-9) return false;
    if (guard_.crosses({f.u, f.w}, {f.t1, f.t2})) return false;
    m_.flip(a, b, f);
    guard_.add(f.t1), guard_.add(f.t2);
    ++report_.flips;
    return true;
  }

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
    for (int t : m_.star(v)) {
      const Eigen::Vector3d n = normal_of(s_.V, m_.tri(t));
      if (f == 0) f = m_.tag(t), n0 = n.normalized();
      if (m_.tag(t) != f || f == 0 || n.norm() == 0) return false;
      if (s_.lock[v] == 2 && n.normalized().dot(n0) < 1 - kCoplanar) return false;
    }
    if (s_.lock[v] == 2)  // not on the border of a non-design solid's footprint on an Ω face
      for (int w : m_.neighbours(v))
        if (s_.lock[w] != 2) return false;
    return f != 0 && (s_.lock[v] == 2 || f > 0);
  }

  /// Whether the non-design triangles around crease point v (lock 2, every triangle around it
  /// free-form or of solid `solid`, at least one free-form) lie on the face of reference triangle
  /// `ref` (of that solid): in its plane (to kCoplanar), or chords of its curved face
  /// (nondesign_faces). A neighbour of v on that face may then take v's place and the triangles
  /// stay on the face.
  bool crease_on_one_face(int v, int ref) const {
    if (!p_.planar_faces || s_.lock[v] != 2 || m_.tag(ref) >= 0) return false;
    const int solid = m_.tag(ref), id = nd_face(ref);
    const Eigen::Vector3d n0 = normal_of(s_.V, m_.tri(ref));
    if (n0.norm() == 0) return false;
    bool crease = false;
    for (int t : m_.star(v)) {
      crease |= m_.tag(t) == 0;
      if (m_.tag(t) == 0) continue;
      if (m_.tag(t) != solid) return false;
      const Eigen::Vector3d n = normal_of(s_.V, m_.tri(t));
      const bool flat = n.norm() > 0 && n.normalized().dot(n0.normalized()) >= 1 - kCoplanar;
      if (!flat && (id < 0 || nd_face(t) != id)) return false;
    }
    return crease;
  }

  /// Whether v, a point of the crease where the free-form surface meets a non-design solid's face
  /// (lock 2, every triangle around it free-form or of that solid, at least one free-form), may go
  /// into its non-design neighbour u (lock 2) without any point moving, v's non-design triangles
  /// lying in one plane or on one curved face (crease_on_one_face), so that with u in v's place
  /// they still lie on that face: across non-design triangles (both triangles on uv the solid's;
  /// the crease then runs through u), or along the crease (uv is a crease edge: one triangle on it
  /// free-form, one the solid's; the crease then runs straight from v's other crease neighbour to
  /// u, the solid's face keeping its place, its border shifting within it; only where the crease
  /// passes v once: two crease edges). The free-form
  /// triangles around v follow (collapse checks their turn and angles). A needle whose other long
  /// edge is the crease is mended this way: its crease point goes into the border point across its
  /// short edge, or along the crease when that would turn the free-form side too far.
  bool crease_removable(int v, int u) const {
    if (s_.lock[u] != 2) return false;
    const std::vector<int> e = m_.edge_triangles(u, v);
    if (e.size() != 2) return false;
    const int nd = m_.tag(e[0]) < 0 ? e[0] : e[1], other = nd == e[0] ? e[1] : e[0];
    if (m_.tag(nd) >= 0 || (m_.tag(other) != m_.tag(nd) && m_.tag(other) != 0)) return false;
    if (m_.tag(other) == 0 && crease_edges(v) != 2) return false;  // along: the crease passes v once
    return crease_on_one_face(v, nd);
  }

  /// How many edges of v are crease edges (one triangle on it free-form, the other non-design).
  int crease_edges(int v) const {
    int n = 0;
    for (int w : m_.neighbours(v)) {
      const std::vector<int> e = m_.edge_triangles(v, w);
      n += e.size() == 2 && ((m_.tag(e[0]) == 0 && m_.tag(e[1]) < 0) || (m_.tag(e[0]) < 0 && m_.tag(e[1]) == 0));
    }
    return n;
  }

  /// Whether point v may go into its neighbour u: v free, inside a planar Ω face, removable from
  /// inside a face (removable_inside) or from a non-design face's crease (crease_removable), or on the cut line of an Ω
  /// face with uv along that line (one triangle of the face and one of the free-form on it; on a curved face no point
  /// moves, the line keeps its other points).
  bool may_go(int v, int u) const {
    if (s_.lock[v] == 0 || face_interior(v) != 0 || removable_inside(v) || crease_removable(v, u)) return true;
    if (s_.lock[v] != 1 || !p_.planar_faces) return false;
    const int f = s_.point_face.size() ? s_.point_face[v] : 0;
    if (f <= 0) return false;
    const std::vector<int> e = m_.edge_triangles(u, v);
    if (e.size() != 2) return false;
    const bool along = (m_.tag(e[0]) == 0 && m_.tag(e[1]) == f) || (m_.tag(e[0]) == f && m_.tag(e[1]) == 0);
    // v's triangles all on the free-form region or on face f
    for (int t : m_.star(v))
      if (m_.tag(t) != 0 && m_.tag(t) != f) return false;
    return along;
  }

  /// Collapses v into u when may_go and the result keeps the surface manifold and no worse.
  bool collapse(int v, int u) {
    if (!may_go(v, u) || !m_.link_condition(u, v)) return false;
    const std::vector<int> shared = m_.edge_triangles(u, v);
    double worst_before = 180, worst_after = 180;
    const double cos_turn = std::cos(p_.max_normal_turn * M_PI / 180);
    std::vector<Tri> made;
    for (int t : m_.star(v)) {
      worst_before = std::min(worst_before, angle(t));
      if (std::count(shared.begin(), shared.end(), t)) continue;
      Tri moved = m_.tri(t);
      std::replace(moved.begin(), moved.end(), v, u);
      const Eigen::Vector3d n0 = normal_of(s_.V, m_.tri(t)), n1 = normal_of(s_.V, moved);
      if (n1.norm() == 0 || n0.norm() == 0 || n0.normalized().dot(n1.normalized()) < cos_turn) return false;
      worst_after = std::min(worst_after, angle_of(moved));
      made.push_back(moved);
    }
    if (worst_after <= worst_before || guard_.crosses(made, m_.star(v))) return false;
    m_.collapse(v, u);
    for (int t : m_.star(u)) guard_.add(t);
    ++report_.collapses;
    return true;
  }

  TriSurface& s_;
  const RemeshParams& p_;
  const FaceProjector& onto_;
  EditableSurface m_;
  CrossingGuard guard_;       ///< every edit is refused when its triangles would cross the surface
  int given_points_;          ///< the points s had; split_needle adds points after them
  std::vector<int> nd_face_;  ///< per triangle (index of m_): its curved non-design face (nondesign_faces) or -1
  RemeshReport report_;
};

}  // namespace

RemeshReport remesh_surface(TriSurface& s, const RemeshParams& params, const FaceProjector& onto) {
  Remesher r(s, params, onto);
  r.run();
  return r.finish();
}

}  // namespace topopt::result
