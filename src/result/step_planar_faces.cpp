// Coplanar triangles grouped into planar faces with straight boundary runs as single edges
// (see step_planar_faces.h).
#include "result/step_planar_faces.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <unordered_map>

#include "common/triangle_closest.h"

namespace topopt::result {
namespace {

using Vec3 = Eigen::Vector3d;

Vec3 point(const TriSurface& s, int i) { return s.V.row(i).transpose(); }

std::uint64_t half_key(int a, int b) {
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) | static_cast<std::uint32_t>(b);
}

/// Twice the area times the unit normal of triangle q.
Vec3 area_normal(const TriSurface& s, long q) {
  const Vec3 a = point(s, s.F(q, 0));
  return (point(s, s.F(q, 1)) - a).cross(point(s, s.F(q, 2)) - a);
}

/// The surface's triangles by half-edge: half[(a, b)] is the triangle holding a -> b.
class HalfEdges {
 public:
  explicit HalfEdges(const TriSurface& s) {
    map_.reserve(static_cast<size_t>(3 * s.F.rows()));
    for (long q = 0; q < s.F.rows(); ++q)
      for (int k = 0; k < 3; ++k) map_[half_key(s.F(q, k), s.F(q, (k + 1) % 3))] = q;
  }
  /// The triangle holding a -> b, or -1.
  long triangle(int a, int b) const {
    const auto it = map_.find(half_key(a, b));
    return it == map_.end() ? -1 : it->second;
  }

 private:
  std::unordered_map<std::uint64_t, long> map_;
};

/// True when triangle q has a plane: an area well above rounding and no edge shorter than
/// OCCT's confusion (as the export's own check of a facet, which names one without area).
bool has_area(const TriSurface& s, long q) {
  const Vec3 a = point(s, s.F(q, 0)), b = point(s, s.F(q, 1)), c = point(s, s.F(q, 2));
  const double shortest = std::min({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  return area_normal(s, q).norm() > 1e-12 * std::max(1.0, (b - a).squaredNorm()) && shortest > 1e-7;
}

/// True when triangle q lies in the plane through `origin` with unit normal `normal`.
bool in_plane(const TriSurface& s, long q, const Vec3& origin, const Vec3& normal, const PlanarFacesParams& params) {
  const Vec3 n = area_normal(s, q);
  if (!has_area(s, q) || n.normalized().dot(normal) < std::cos(params.angular_tolerance)) return false;
  for (int k = 0; k < 3; ++k)
    if (std::abs((point(s, s.F(q, k)) - origin).dot(normal)) > params.linear_tolerance) return false;
  return true;
}

/// A face of the single triangle q (its plane, its three points as the loop).
PlanarFace single(const TriSurface& s, long q) {
  PlanarFace f;
  f.triangles = {q};
  f.loops = {{s.F(q, 0), s.F(q, 1), s.F(q, 2)}};
  f.origin = point(s, s.F(q, 0));
  if (has_area(s, q)) f.normal = area_normal(s, q).normalized();
  return f;
}

/// The points of the triangles `tris` with more than one boundary edge leaving them (where
/// the boundary pinches).
std::vector<int> pinch_points(const TriSurface& s, const std::vector<long>& tris, const HalfEdges& half,
                              const std::vector<char>& in) {
  std::map<int, int> leaving;
  for (long q : tris)
    for (int k = 0; k < 3; ++k) {
      const int a = s.F(q, k), b = s.F(q, (k + 1) % 3);
      const long t = half.triangle(b, a);
      if (t < 0 || !in[t]) ++leaving[a];
    }
  std::vector<int> out;
  for (const auto& [p, n] : leaving)
    if (n > 1) out.push_back(p);
  return out;
}

/// The triangles of `tris` (all marked in `in`) in pieces connected through edges.
std::vector<std::vector<long>> edge_pieces(const TriSurface& s, const std::vector<long>& tris, const HalfEdges& half,
                                           std::vector<char>& in) {
  std::vector<std::vector<long>> out;
  for (long seed : tris) {
    if (in[seed] != 1) continue;
    in[seed] = 2;
    out.push_back({seed});
    for (size_t i = 0; i < out.back().size(); ++i) {
      const long q = out.back()[i];
      for (int k = 0; k < 3; ++k) {
        const long t = half.triangle(s.F(q, (k + 1) % 3), s.F(q, k));
        if (t >= 0 && in[t] == 1) in[t] = 2, out.back().push_back(t);
      }
    }
  }
  for (long q : tris) in[q] = 0;
  return out;
}

/// `f` (triangles in one plane, connected) as faces whose boundaries do not pinch: where it
/// pinches, the triangles at the pinch point become faces of their own and the rest is split
/// into its connected pieces, again until no piece pinches.
void unpinched(const TriSurface& s, PlanarFace f, const HalfEdges& half, std::vector<char>& in,
               std::vector<PlanarFace>& out) {
  std::vector<PlanarFace> todo{std::move(f)};
  while (!todo.empty()) {
    PlanarFace g = std::move(todo.back());
    todo.pop_back();
    auto loops = g.triangles.size() > 1 ? boundary_loops(s, g.triangles) : std::nullopt;
    if (loops || g.triangles.size() == 1) {
      if (loops) g.loops = std::move(*loops);
      out.push_back(std::move(g));
      continue;
    }
    for (long q : g.triangles) in[q] = 1;
    std::vector<char> pinch_point(s.V.rows(), 0);  // only the group's points are ever set
    for (int p : pinch_points(s, g.triangles, half, in)) pinch_point[p] = 1;
    for (long q : g.triangles)
      if (pinch_point[s.F(q, 0)] || pinch_point[s.F(q, 1)] || pinch_point[s.F(q, 2)])
        in[q] = 0, out.push_back(single(s, q));
    for (std::vector<long>& piece : edge_pieces(s, g.triangles, half, in)) {
      PlanarFace h = g;
      h.triangles = std::move(piece);
      h.loops = {{s.F(h.triangles[0], 0), s.F(h.triangles[0], 1), s.F(h.triangles[0], 2)}};
      todo.push_back(std::move(h));
    }
  }
}

/// The groups of coplanar mergeable triangles, grown over shared edges from their first
/// triangle's plane; where a group's boundary pinches, the triangles at the pinch become faces of
/// their own (unpinched).
std::vector<PlanarFace> coplanar_groups(const TriSurface& s, const std::vector<char>& mergeable, const HalfEdges& half,
                                        const PlanarFacesParams& params) {
  std::vector<char> taken(s.F.rows(), 0), in(s.F.rows(), 0);
  std::vector<PlanarFace> out;
  for (long seed = 0; seed < s.F.rows(); ++seed) {
    if (!mergeable[seed] || taken[seed]) continue;
    PlanarFace f = single(s, seed);
    taken[seed] = 1;
    if (f.normal.norm() > 0)
      for (size_t i = 0; i < f.triangles.size(); ++i) {
        const long q = f.triangles[i];
        for (int k = 0; k < 3; ++k) {
          const long t = half.triangle(s.F(q, (k + 1) % 3), s.F(q, k));
          if (t < 0 || !mergeable[t] || taken[t] || !in_plane(s, t, f.origin, f.normal, params)) continue;
          taken[t] = 1;
          f.triangles.push_back(t);
        }
      }
    unpinched(s, std::move(f), half, in, out);
  }
  return out;
}

/// Per point: true when it may be dropped from the loops (see planar_faces).
std::vector<char> droppable_points(const TriSurface& s, const std::vector<char>& mergeable,
                                   const std::vector<PlanarFace>& faces, const HalfEdges& half,
                                   const PlanarFacesParams& params) {
  std::vector<int> face_of(s.F.rows(), -1);
  for (size_t f = 0; f < faces.size(); ++f)
    for (long q : faces[f].triangles) face_of[q] = static_cast<int>(f);
  const long n = s.V.rows();
  std::vector<char> locked(n, 0);
  std::vector<int> degree(n, 0);
  std::vector<std::array<int, 2>> ends(n, {-1, -1});
  for (long q = 0; q < s.F.rows(); ++q)
    for (int k = 0; k < 3; ++k) {
      const int a = s.F(q, k), b = s.F(q, (k + 1) % 3);
      if (!mergeable[q]) locked[a] = 1;
      const long t = half.triangle(b, a);
      if (a > b || (t >= 0 && face_of[t] == face_of[q])) continue;  // each edge once; inside a face
      for (const auto& [p, other] : {std::pair{a, b}, std::pair{b, a}}) {
        if (degree[p] < 2) ends[p][degree[p]] = other;
        ++degree[p];
      }
    }
  std::vector<char> out(n, 0);
  const double sine = std::sin(params.angular_tolerance);
  for (long p = 0; p < n; ++p) {
    if (locked[p] || degree[p] != 2) continue;
    const Vec3 x = point(s, static_cast<int>(p)), a = point(s, ends[p][0]), b = point(s, ends[p][1]);
    const Vec3 da = a - x, db = b - x;
    out[p] = da.dot(db) < 0 && da.cross(db).norm() <= sine * da.norm() * db.norm() &&
             distance_to_segment(x, a, b) <= params.linear_tolerance;
  }
  return out;
}

/// `loop` without its droppable points, a run between two kept points losing its inner points
/// only when each lies within the linear tolerance of the straight edge between them (measured
/// from the lower-numbered end, so the faces on both sides decide alike). A loop that would
/// keep fewer than three points is kept whole.
std::vector<int> corners(const TriSurface& s, const std::vector<int>& loop, const std::vector<char>& droppable,
                         double tolerance) {
  const size_t n = loop.size();
  size_t start = 0;
  while (start < n && droppable[loop[start]]) ++start;
  if (start == n) return loop;
  std::vector<int> out;
  for (size_t i = 0; i < n;) {
    const int a = loop[(start + i) % n];
    size_t j = i + 1;
    while (j < n && droppable[loop[(start + j) % n]]) ++j;
    const int c = loop[(start + j) % n];
    const Vec3 lo = point(s, std::min(a, c)), hi = point(s, std::max(a, c));
    bool straight = true;
    for (size_t k = i + 1; k < j && straight; ++k)
      straight = distance_to_segment(point(s, loop[(start + k) % n]), lo, hi) <= tolerance;
    out.push_back(a);
    if (!straight)
      for (size_t k = i + 1; k < j; ++k) out.push_back(loop[(start + k) % n]);
    i = j;
  }
  return out.size() < 3 ? loop : out;
}

}  // namespace

std::optional<std::vector<std::vector<int>>> boundary_loops(const TriSurface& s, const std::vector<long>& tris) {
  std::map<std::pair<int, int>, bool> half;
  for (long q : tris)
    for (int k = 0; k < 3; ++k) half[{s.F(q, k), s.F(q, (k + 1) % 3)}] = true;
  std::map<int, int> next;
  for (const auto& [e, unused] : half)
    if (!half.count({e.second, e.first}) && !next.emplace(e.first, e.second).second) return std::nullopt;
  std::vector<std::vector<int>> loops;
  while (!next.empty()) {
    std::vector<int> loop{next.begin()->first};
    for (int at = next.begin()->second; at != loop.front(); at = next.at(at)) {
      if (!next.count(at)) return std::nullopt;
      loop.push_back(at);
    }
    for (int p : loop) next.erase(p);
    loops.push_back(loop);
  }
  return loops;
}

std::vector<PlanarFace> planar_faces(const TriSurface& s, const std::vector<char>& mergeable,
                                     const PlanarFacesParams& params) {
  const HalfEdges half(s);
  std::vector<PlanarFace> faces = coplanar_groups(s, mergeable, half, params);
  const std::vector<char> droppable = droppable_points(s, mergeable, faces, half, params);
  for (PlanarFace& f : faces)
    if (f.triangles.size() > 1)
      for (auto& loop : f.loops) loop = corners(s, loop, droppable, params.linear_tolerance);
  return faces;
}

}  // namespace topopt::result
