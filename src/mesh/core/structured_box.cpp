#include "mesh/core/structured_box.h"

#include <cassert>
#include <cmath>

#include "common/error.h"

namespace topopt::mesh {

TetMesh structured_box_mesh(const StructuredBoxParams& p) {
  const int nx = p.cells[0], ny = p.cells[1], nz = p.cells[2];
  if (nx < 1 || ny < 1 || nz < 1 || p.size[0] <= 0 || p.size[1] <= 0 || p.size[2] <= 0)
    throw Error(ErrorCode::InvalidParameter, "structured box: sizes and cell counts must be positive");
  auto node = [&](int i, int j, int k) { return i + (nx + 1) * (j + (ny + 1) * k); };
  TetMesh m;
  m.V.resize((nx + 1) * (ny + 1) * (nz + 1), 3);
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        m.V.row(node(i, j, k)) << p.origin[0] + p.size[0] * i / nx, p.origin[1] + p.size[1] * j / ny,
            p.origin[2] + p.size[2] * k / nz;

  // Kuhn split of the unit cube: one tet per permutation of the axes, each walking from
  // corner 0 to corner 7 along the edges in that order. Corner c has bits (x, y, z).
  static const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  m.T.resize(6 * nx * ny * nz, 4);
  m.domain = VecXi::Zero(m.T.rows());
  int t = 0;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        for (const auto& perm : perms) {
          int c[3] = {0, 0, 0};
          int tet[4];
          tet[0] = node(i, j, k);
          for (int s = 0; s < 3; ++s) {
            c[perm[s]] = 1;
            tet[s + 1] = node(i + c[0], j + c[1], k + c[2]);
          }
          // Odd permutations give negative orientation: swap two nodes.
          Eigen::Vector3d a = m.V.row(tet[1]) - m.V.row(tet[0]), b = m.V.row(tet[2]) - m.V.row(tet[0]),
                          d = m.V.row(tet[3]) - m.V.row(tet[0]);
          if (a.cross(b).dot(d) < 0) std::swap(tet[2], tet[3]);
          m.T.row(t) << tet[0], tet[1], tet[2], tet[3];
          Eigen::RowVector3d centroid = (m.V.row(tet[0]) + m.V.row(tet[1]) + m.V.row(tet[2]) + m.V.row(tet[3])) / 4;
          for (size_t b2 = 0; b2 < p.nondesign.size(); ++b2) {
            const auto& box = p.nondesign[b2];
            if (centroid[0] > box[0] && centroid[1] > box[1] && centroid[2] > box[2] && centroid[0] < box[3] &&
                centroid[1] < box[4] && centroid[2] < box[5]) {
              m.domain[t] = static_cast<int>(b2) + 1;
              break;
            }
          }
          ++t;
        }

  // Boundary: two triangles per boundary quad, split along the same diagonal the Kuhn
  // tets use (from the cell corner with the lower index sum), oriented outwards.
  std::vector<std::array<int, 3>> tris;
  std::vector<int> faces;
  auto quad = [&](int a, int b, int c, int d, int face) {  // a-b-c-d counter-clockwise seen from outside, a lowest
    tris.push_back({a, b, c});
    tris.push_back({a, c, d});
    faces.push_back(face);
    faces.push_back(face);
  };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      quad(node(0, j, k), node(0, j, k + 1), node(0, j + 1, k + 1), node(0, j + 1, k), 1);
      quad(node(nx, j, k), node(nx, j + 1, k), node(nx, j + 1, k + 1), node(nx, j, k + 1), 2);
    }
  for (int k = 0; k < nz; ++k)
    for (int i = 0; i < nx; ++i) {
      quad(node(i, 0, k), node(i + 1, 0, k), node(i + 1, 0, k + 1), node(i, 0, k + 1), 3);
      quad(node(i, ny, k), node(i, ny, k + 1), node(i + 1, ny, k + 1), node(i + 1, ny, k), 4);
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      quad(node(i, j, 0), node(i, j + 1, 0), node(i + 1, j + 1, 0), node(i + 1, j, 0), 5);
      quad(node(i, j, nz), node(i + 1, j, nz), node(i + 1, j + 1, nz), node(i, j + 1, nz), 6);
    }
  m.F.resize(tris.size(), 3);
  m.face.resize(tris.size());
  m.nd_face = VecXi::Zero(tris.size());
  for (size_t f = 0; f < tris.size(); ++f) {
    m.F.row(f) << tris[f][0], tris[f][1], tris[f][2];
    m.face[f] = faces[f];
    // The non-design box face this triangle lies on, numbered as in a compound of OCCT boxes
    // (6 faces each, in the same order as the part's).
    Eigen::RowVector3d c = (m.V.row(tris[f][0]) + m.V.row(tris[f][1]) + m.V.row(tris[f][2])) / 3.0;
    const int axis = (faces[f] - 1) / 2;
    const bool at_max = (faces[f] - 1) % 2 == 1;
    for (size_t b = 0; b < p.nondesign.size() && !m.nd_face[f]; ++b) {
      const auto& box = p.nondesign[b];
      const double plane = at_max ? box[3 + axis] : box[axis];
      const double eps = 1e-9 * (p.size[0] + p.size[1] + p.size[2]);
      bool inside = std::abs(c[axis] - plane) <= eps;
      for (int k = 0; k < 3 && inside; ++k)
        if (k != axis) inside = c[k] > box[k] && c[k] < box[3 + k];
      if (inside) m.nd_face[f] = static_cast<int>(6 * b) + faces[f];
    }
  }
  return m;
}

}  // namespace topopt::mesh
