// A fixture shared by the result tests: an axis-aligned cube added to a result surface as a
// piece of its own — a detached body (outward) or a closed void (inward).
#pragma once
#include "result/iso_surface.h"

namespace topopt::testing {

/// `s` with the cube [lo, lo + edge] (three coordinates) added as twelve triangles tagged 0,
/// outward (a body) or, with `void_inside`, inward (a void in the body around it).
inline result::TriSurface with_cube(const result::TriSurface& s, const Eigen::Vector3d& lo, double edge,
                                    bool void_inside = false) {
  result::TriSurface t = s;
  const long n = s.V.rows(), m = s.F.rows();
  t.V.conservativeResize(n + 8, 3);
  for (int i = 0; i < 8; ++i)
    t.V.row(n + i) << lo.x() + edge * (i & 1), lo.y() + edge * ((i >> 1) & 1), lo.z() + edge * ((i >> 2) & 1);
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  t.F.conservativeResize(m + 12, 3);
  t.tag.conservativeResize(m + 12);
  for (int q = 0; q < 6; ++q) {
    const int* c = quads[q];
    const int b = void_inside ? 2 : 1, d = void_inside ? 1 : 2;
    t.F.row(m + 2 * q) << n + c[0], n + c[b], n + c[d];
    t.F.row(m + 2 * q + 1) << n + c[0], n + c[b + 1], n + c[d + 1];
    t.tag[m + 2 * q] = t.tag[m + 2 * q + 1] = 0;
  }
  return t;
}

}  // namespace topopt::testing
