// The draw direction's cast on the tets (see tet_cast.h).
#include "simp/controls/tet_cast.h"

#include <algorithm>
#include <array>

#include "common/adjacency.h"
#include "mesh/core/predicates.h"
#include "simp/controls/draw_filter.h"

namespace topopt::simp {

namespace {

/// One face of a design tet: its corners sorted (the key two tets share), the tet (#D index)
/// and the corner opposite the face.
struct TetFace {
  std::array<int, 3> key;
  int tet;
  int opposite;
};

/// The pairs of design tets (#D indices) sharing a face, the lower one first: a ray along d
/// leaves the first into the second. Faces parallel to d give no pair.
std::vector<std::array<int, 2>> pairs_along(const TetMesh& mesh, const std::vector<int>& design,
                                            const Eigen::Vector3d& d) {
  std::vector<TetFace> faces;
  faces.reserve(4 * design.size());
  for (size_t i = 0; i < design.size(); ++i)
    for (int k = 0; k < 4; ++k) {
      std::array<int, 3> key;
      for (int m = 0, n = 0; m < 4; ++m)
        if (m != k) key[n++] = mesh.T(design[i], m);
      std::sort(key.begin(), key.end());
      faces.push_back({key, static_cast<int>(i), mesh.T(design[i], k)});
    }
  std::sort(faces.begin(), faces.end(), [](const TetFace& a, const TetFace& b) { return a.key < b.key; });
  std::vector<std::array<int, 2>> pairs;
  for (size_t f = 0; f + 1 < faces.size(); ++f) {
    if (faces[f].key != faces[f + 1].key) continue;
    const TetFace& one = faces[f];
    Eigen::Vector3d corner[3];
    for (int m = 0; m < 3; ++m) corner[m] = mesh.V.row(one.key[m]).transpose();
    const Eigen::Vector3d opposite = mesh.V.row(one.opposite).transpose(), ahead = corner[0] + d;
    const int side = mesh::predicates::orient3d(corner[0].data(), corner[1].data(), corner[2].data(), opposite.data());
    const int up = mesh::predicates::orient3d(corner[0].data(), corner[1].data(), corner[2].data(), ahead.data());
    if (up != 0 && side != 0)  // d points into `one`'s side: the other tet lies below it
      pairs.push_back(up == side ? std::array<int, 2>{faces[f + 1].tet, one.tet}
                                 : std::array<int, 2>{one.tet, faces[f + 1].tet});
    ++f;
  }
  return pairs;
}

}  // namespace

TetCast::TetCast(const TetMesh& mesh, const std::vector<int>& design, const TetCastParams& params)
    : eps_(params.smoothness) {
  const Eigen::Vector3d d = params.direction.normalized();
  const int n = static_cast<int>(design.size());
  std::vector<double> height(n);  // along the way each tet takes: up above the plane, down below it
  std::vector<char> below(n, 0);
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int a = 0; a < 4; ++a) c += mesh.V.row(mesh.T(design[i], a)).transpose() / 4;
    below[i] = params.split && c.dot(d) < params.parting_point.dot(d);
    height[i] = below[i] ? -c.dot(d) : c.dot(d);
  }
  // edge (taker, source): above the plane the lower tet takes from the upper, below it the reverse
  std::vector<std::array<int, 2>> edges;
  for (const auto& [lower, upper] : pairs_along(mesh, design, d))
    if (below[lower] == below[upper])
      edges.push_back(below[lower] ? std::array<int, 2>{upper, lower} : std::array<int, 2>{lower, upper});
  // the edges by their source tet, in edge order
  const Adjacency dependents = group_pairs(n, [&](auto emit) {
    for (size_t e = 0; e < edges.size(); ++e) emit(edges[e][1], static_cast<int>(e));
  });
  std::vector<int> pending(n, 0);
  for (const auto& e : edges) ++pending[e[0]];
  // Kahn's order; a cycle is broken at its highest remaining tet (its sources not yet placed dropped)
  std::vector<char> alive(edges.size(), 1), queued(n, 0);
  std::vector<int> ready;
  for (int i = 0; i < n; ++i)
    if (pending[i] == 0) ready.push_back(i), queued[i] = 1;
  order_.reserve(n);
  std::vector<char> placed(n, 0);
  while (static_cast<int>(order_.size()) < n) {
    if (ready.empty()) {
      int top = -1;
      for (int i = 0; i < n; ++i)
        if (!queued[i] && (top < 0 || height[i] > height[top])) top = i;
      for (size_t e = 0; e < edges.size(); ++e)
        if (edges[e][0] == top && alive[e] && !placed[edges[e][1]]) alive[e] = 0, ++dropped_;
      ready.push_back(top), queued[top] = 1;
    }
    const int t = ready.back();
    ready.pop_back();
    order_.push_back(t), placed[t] = 1;
    for (const int e : dependents.row(t)) {
      if (alive[e] && --pending[edges[e][0]] == 0 && !queued[edges[e][0]])
        ready.push_back(edges[e][0]), queued[edges[e][0]] = 1;
    }
  }
  takes_from_ = group_pairs(n, [&](auto emit) {
    for (size_t e = 0; e < edges.size(); ++e)
      if (alive[e]) emit(edges[e][0], edges[e][1]);
  });
}

VecXd TetCast::sweep(const VecXd& z, std::vector<double>* da, std::vector<double>* db) const {
  VecXd out = z;
  double ignore_a, ignore_b;
  for (const int t : order_) {
    double m = z[t];
    for (int e = takes_from_.offset[t]; e < takes_from_.offset[t + 1]; ++e)
      m = smooth_max(m, out[takes_from_.index[e]], eps_, da ? &(*da)[e] : &ignore_a, db ? &(*db)[e] : &ignore_b);
    out[t] = m;
  }
  return out;
}

VecXd TetCast::apply(const VecXd& z) const { return sweep(z, nullptr, nullptr); }

VecXd TetCast::apply_transpose(const VecXd& z, const VecXd& g) const {
  std::vector<double> da(takes_from_.index.size()), db(takes_from_.index.size());
  sweep(z, &da, &db);
  VecXd a = g, dz = VecXd::Zero(z.size());
  for (auto t = order_.rbegin(); t != order_.rend(); ++t) {
    double carried = a[*t];  // d/d out[t]: complete, every tet taking from t came later
    for (int e = takes_from_.offset[*t + 1] - 1; e >= takes_from_.offset[*t]; --e) {
      a[takes_from_.index[e]] += carried * db[e];
      carried *= da[e];
    }
    dz[*t] += carried;
  }
  return dz;
}

}  // namespace topopt::simp
