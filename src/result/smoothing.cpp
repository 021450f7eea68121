// Taubin λ|μ smoothing of the result surface, each pair followed by the local volume
// correction (see smoothing.h).
#include "result/smoothing.h"

#include <algorithm>
#include <vector>

#include "common/adjacency.h"

namespace topopt::result {

namespace {

/// What moves and how: the neighbours each point averages (compressed rows) and its kind.
struct SmoothingGraph {
  Adjacency neighbours;
  /// #P: 0 fixed, 1 free (all its neighbours), 2 on a planar Ω face's cut line (its two
  /// neighbours on that line; it stays in the face's plane).
  std::vector<char> movable;
};

/// Free points average all their neighbours; points on a planar Ω face's cut line average only
/// their neighbours on that same line, then return to the plane, so the face stays where it was
/// and only the cut curve is smoothed.
SmoothingGraph smoothing_graph(const TriSurface& s, bool slide_on_planar_faces) {
  const int np = static_cast<int>(s.V.rows());
  Adjacency all = group_pairs(np, [&](auto emit) {
    for (long t = 0; t < s.F.rows(); ++t)
      for (int k = 0; k < 3; ++k) emit(s.F(t, k), s.F(t, (k + 1) % 3)), emit(s.F(t, (k + 1) % 3), s.F(t, k));
  });
  sort_unique_rows(all);
  SmoothingGraph g;
  g.movable.assign(np, 0);
  std::vector<int> line;
  for (int i = 0; i < np; ++i) {
    line.clear();
    if (s.lock[i] == 0) {
      g.movable[i] = 1;
      line.assign(all.begin(i), all.end(i));
    } else if (s.lock[i] == 1 && slide_on_planar_faces) {
      const int f = s.point_face.size() ? s.point_face[i] : 0;
      const bool planar = f > 0 && f < static_cast<int>(s.face_plane.size()) && s.face_plane[f].head<3>().norm() > 0;
      for (int j : all.row(i))
        if (s.lock[j] == 1 && s.point_face[j] == f) line.push_back(j);
      if (planar && line.size() == 2)  // a cut-line point: exactly two neighbours on the same face's cut line
        g.movable[i] = 2;
      else
        line.clear();
    }
    if (line.empty()) g.movable[i] = 0;
    g.neighbours.push_row(line);
  }
  return g;
}

/// Point i moved to p, put back into its face's plane when it lies on a cut line.
Eigen::RowVector3d onto_plane(const TriSurface& s, const SmoothingGraph& g, long i, Eigen::RowVector3d p) {
  if (g.movable[i] != 2) return p;
  const Eigen::Vector4d& pl = s.face_plane[s.point_face[i]];
  const Eigen::RowVector3d n = pl.head<3>().transpose();
  return p - (p.dot(n) - pl[3]) * n;
}

/// One umbrella step with `factor` (λ or μ) at every movable point, all points at once.
void umbrella_step(TriSurface& s, const SmoothingGraph& g, double factor, MatX3d& next) {
  for (long i = 0; i < s.V.rows(); ++i) {
    if (!g.movable[i]) continue;
    Eigen::RowVector3d avg = Eigen::RowVector3d::Zero();
    for (int j : g.neighbours.row(static_cast<int>(i))) avg += s.V.row(j);
    avg /= g.neighbours.size(static_cast<int>(i));
    next.row(i) = onto_plane(s, g, i, s.V.row(i) + factor * (avg - s.V.row(i)));
  }
  s.V = next;
}

/// The direction along which each movable point's offset is measured (#P by 3, unit): the
/// gradient of the enclosed volume w.r.t. the point (a third of its triangles' area vectors:
/// outward), within the face's plane on a cut line. Zero where it vanishes.
MatX3d offset_directions(const TriSurface& s, const SmoothingGraph& g) {
  MatX3d d = MatX3d::Zero(s.V.rows(), 3);
  for (long t = 0; t < s.F.rows(); ++t) {
    const Eigen::RowVector3d a = s.V.row(s.F(t, 0)), b = s.V.row(s.F(t, 1)), c = s.V.row(s.F(t, 2));
    const Eigen::RowVector3d area = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) d.row(s.F(t, k)) += area;
  }
  for (long i = 0; i < d.rows(); ++i) {
    if (g.movable[i] == 2) {
      const Eigen::RowVector3d n = s.face_plane[s.point_face[i]].head<3>().transpose();
      d.row(i) -= d.row(i).dot(n) * n;
    }
    const double len = d.row(i).norm();
    d.row(i) = g.movable[i] && len > 0 ? Eigen::RowVector3d(d.row(i) / len) : Eigen::RowVector3d::Zero();
  }
  return d;
}

/// Moves the points back along their offset directions by the local mean of the offsets the
/// last pair gave them (from `before`): the mean over `rings` rings (damped Jacobi averaging of
/// the offsets, fixed points at 0) keeps the pair's zero-mean ripple removal and undoes its net
/// inward or outward move. A member a few edges thick is where that net move is large: its
/// cross-section is a short ring of points, which the umbrella operator sees as a high
/// frequency although the member's surface is smooth (a ring of 6 points loses about 2 % of its
/// radius a pair); as an offset along the normals it is a constant, which this restores.
void restore_local_volume(TriSurface& s, const SmoothingGraph& g, const MatX3d& before, int rings) {
  const MatX3d dir = offset_directions(s, g);
  const long np = s.V.rows();
  VecXd offset(np), mean(np);
  for (long i = 0; i < np; ++i) offset[i] = (s.V.row(i) - before.row(i)).dot(dir.row(i));
  for (int r = 0; r < rings; ++r) {
    for (long i = 0; i < np; ++i) {
      if (!g.movable[i]) {
        mean[i] = 0;
        continue;
      }
      double sum = 0;
      for (int j : g.neighbours.row(static_cast<int>(i))) sum += offset[j];
      // half a step: plain averaging would keep an alternating (checkerboard) ripple
      mean[i] = 0.5 * (offset[i] + sum / g.neighbours.size(static_cast<int>(i)));
    }
    offset.swap(mean);
  }
  for (long i = 0; i < np; ++i)
    if (g.movable[i]) s.V.row(i) = onto_plane(s, g, i, s.V.row(i) - offset[i] * dir.row(i));
}

}  // namespace

void smooth_surface(TriSurface& s, const SmoothParams& params) {
  const SmoothingGraph g = smoothing_graph(s, params.slide_on_planar_faces);
  MatX3d next = s.V, before;
  for (int it = 0; it < params.iterations; ++it) {
    before = s.V;
    umbrella_step(s, g, params.lambda, next);
    umbrella_step(s, g, params.mu, next);
    if (params.volume_rings > 0) restore_local_volume(s, g, before, params.volume_rings);
  }
}

}  // namespace topopt::result
