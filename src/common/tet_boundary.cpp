// Boundary faces of a tet mesh by sorting face keys (see tet_boundary.h).
#include "common/tet_boundary.h"

#include <algorithm>
#include <array>
#include <vector>

#include "common/face_key.h"

namespace topopt {

MatX3i boundary_triangles(const MatX4i& T) {
  // Faces of tet (a,b,c,d) oriented outwards for a positive tet. All 4 #T faces sorted by
  // their key: a face met once is on the boundary (sorting beats hashing here by ~3x).
  struct Entry {
    FaceKey key;
    int tet, face;
  };
  std::vector<Entry> all;
  all.reserve(4 * T.rows());
  for (long t = 0; t < T.rows(); ++t)
    for (int f = 0; f < 4; ++f)
      all.push_back(
          {face_key(T(t, kTetFace[f][0]), T(t, kTetFace[f][1]), T(t, kTetFace[f][2])), static_cast<int>(t), f});
  std::sort(all.begin(), all.end(), [](const Entry& a, const Entry& b) { return a.key < b.key; });
  std::vector<std::array<int, 3>> out;
  for (size_t i = 0; i < all.size();) {
    size_t j = i + 1;
    while (j < all.size() && all[j].key == all[i].key) ++j;
    if (j == i + 1) {
      const Entry& e = all[i];
      out.push_back({T(e.tet, kTetFace[e.face][0]), T(e.tet, kTetFace[e.face][1]), T(e.tet, kTetFace[e.face][2])});
    }
    i = j;
  }
  std::sort(out.begin(), out.end());
  MatX3i F(out.size(), 3);
  for (size_t i = 0; i < out.size(); ++i) F.row(i) << out[i][0], out[i][1], out[i][2];
  return F;
}

}  // namespace topopt
