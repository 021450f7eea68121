// The triangles around each node (see triangle_stars.h).
#include "mesh/surface/triangle_stars.h"

namespace topopt::mesh {

TriangleStars triangle_stars(const MatX3i& T, long nt, long nodes, const std::vector<char>& dead) {
  TriangleStars star;
  star.offset.assign(nodes + 1, 0);
  auto alive = [&](long t) { return dead.empty() || !dead[t]; };
  for (long t = 0; t < nt; ++t)
    if (alive(t))
      for (int k = 0; k < 3; ++k) ++star.offset[T(t, k) + 1];
  for (long i = 0; i < nodes; ++i) star.offset[i + 1] += star.offset[i];
  star.index.resize(star.offset[nodes]);
  std::vector<int> fill(star.offset.begin(), star.offset.end() - 1);
  for (long t = 0; t < nt; ++t)
    if (alive(t))
      for (int k = 0; k < 3; ++k) star.index[fill[T(t, k)]++] = static_cast<int>(t);
  return star;
}

}  // namespace topopt::mesh
