// Taubin λ|μ smoothing of the result surface (see smoothing.h).
#include "result/smoothing.h"

#include <algorithm>
#include <vector>

namespace topopt::result {

void smooth_surface(TriSurface& s, const SmoothParams& params) {
  const long np = s.V.rows();
  // Neighbours (CSR). Free points average all neighbours; points on a planar Ω face's cut
  // line average only their neighbours on that same line, then return to the plane, so the
  // face stays where it was and only the cut curve is smoothed.
  std::vector<std::vector<int>> nb(np);
  for (long t = 0; t < s.F.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      int a = s.F(t, k), b = s.F(t, (k + 1) % 3);
      nb[a].push_back(b), nb[b].push_back(a);
    }
  std::vector<int> start(np + 1, 0), list;
  std::vector<char> movable(np, 0);
  for (long i = 0; i < np; ++i) {
    auto& v = nb[i];
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    if (s.lock[i] == 0) {
      movable[i] = 1;
      list.insert(list.end(), v.begin(), v.end());
    } else if (s.lock[i] == 1 && params.slide_on_planar_faces) {
      int f = s.point_face.size() ? s.point_face[i] : 0;
      bool planar = f > 0 && f < static_cast<int>(s.face_plane.size()) && s.face_plane[f].head<3>().norm() > 0;
      // a cut-line point: exactly two neighbours on the same face's cut line
      std::vector<int> line;
      for (int j : v)
        if (s.lock[j] == 1 && s.point_face[j] == f) line.push_back(j);
      if (planar && line.size() == 2) {
        movable[i] = 2;
        list.insert(list.end(), line.begin(), line.end());
      }
    }
    start[i + 1] = static_cast<int>(list.size());
  }
  MatX3d next = s.V;
  auto step = [&](double factor) {
    for (long i = 0; i < np; ++i) {
      if (!movable[i] || start[i + 1] == start[i]) continue;
      Eigen::RowVector3d avg = Eigen::RowVector3d::Zero();
      for (int k = start[i]; k < start[i + 1]; ++k) avg += s.V.row(list[k]);
      avg /= (start[i + 1] - start[i]);
      Eigen::RowVector3d p = s.V.row(i) + factor * (avg - s.V.row(i));
      if (movable[i] == 2) {
        const Eigen::Vector4d& pl = s.face_plane[s.point_face[i]];
        Eigen::RowVector3d n = pl.head<3>().transpose();
        p -= (p.dot(n) - pl[3]) * n;
      }
      next.row(i) = p;
    }
    s.V = next;
  };
  for (int it = 0; it < params.iterations; ++it) {
    step(params.lambda);
    step(params.mu);
  }
}

}  // namespace topopt::result
