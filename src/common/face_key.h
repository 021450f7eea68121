// An orientation-free key for a triangle (its three node indices sorted) and its hash, for
// matching faces between tets, boundary lists and files; and the outward faces of a tet.
#pragma once
#include <algorithm>
#include <array>
#include <cstddef>

namespace topopt {

/// The faces of a positively oriented tet (v0, v1, v2, v3), opposite vertex 0..3, each turning
/// so that its normal points out of the tet.
inline constexpr int kTetFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

using FaceKey = std::array<int, 3>;

/// The key of triangle (a, b, c): the same for every order of the three nodes.
inline FaceKey face_key(int a, int b, int c) {
  FaceKey k{a, b, c};
  std::sort(k.begin(), k.end());
  return k;
}

struct FaceKeyHash {
  std::size_t operator()(const FaceKey& k) const {
    return static_cast<std::size_t>(k[0]) * 73856093u ^ static_cast<std::size_t>(k[1]) * 19349663u ^
           static_cast<std::size_t>(k[2]) * 83492791u;
  }
};

}  // namespace topopt
