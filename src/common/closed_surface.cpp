// Edge pairing and enclosed volume of a triangle surface (see closed_surface.h).
#include "common/closed_surface.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace topopt {
namespace {

uint64_t directed_key(int a, int b) {
  return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
}

}  // namespace

SurfaceCheck check_surface(const MatX3i& F) {
  std::vector<uint64_t> edges;
  edges.reserve(3 * F.rows());
  for (long t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) edges.push_back(directed_key(F(t, k), F(t, (k + 1) % 3)));
  std::sort(edges.begin(), edges.end());
  auto uses = [&](uint64_t key) {  // how many triangles use the directed edge `key`
    const auto range = std::equal_range(edges.begin(), edges.end(), key);
    return static_cast<long>(range.second - range.first);
  };
  SurfaceCheck c;
  for (size_t i = 0; i < edges.size();) {
    const uint64_t key = edges[i];
    const long n = uses(key);
    const long m = uses(directed_key(static_cast<int>(key & 0xffffffffu), static_cast<int>(key >> 32)));
    c.overshared_edges += n > 1;
    c.open_edges += m == 0;
    c.misoriented_edges += m > 0 && n != m;
    c.unpaired_edges += n != 1 || m != 1;
    i += static_cast<size_t>(n);
  }
  return c;
}

SurfaceCheck check_surface(const MatX3d& V, const MatX3i& F) {
  SurfaceCheck c = check_surface(F);
  for (long t = 0; t < F.rows(); ++t) {
    const Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), d = V.row(F(t, 2));
    c.volume += a.dot(b.cross(d)) / 6.0;
  }
  return c;
}

}  // namespace topopt
