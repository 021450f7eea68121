// The kept tets of a crisp design and their boundary triangles (see kept_part.h).
#include "fem/kept_part.h"

#include <unordered_set>

#include "common/face_key.h"

namespace topopt::fem {
namespace {

/// Renumbers the nodes of `part` (whose T, F index `all` nodes of the source mesh) to those its
/// tets use, in the order they first use them, and copies their coordinates from V.
void compact_nodes(TetMesh& part, const MatX3d& V) {
  std::vector<int> renum(V.rows(), -1);
  int used = 0;
  for (long t = 0; t < part.T.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      if (renum[part.T(t, k)] < 0) renum[part.T(t, k)] = used++;
  part.V.resize(used, 3);
  for (long i = 0; i < V.rows(); ++i)
    if (renum[i] >= 0) part.V.row(renum[i]) = V.row(i);
  for (long t = 0; t < part.T.rows(); ++t)
    for (int k = 0; k < 4; ++k) part.T(t, k) = renum[part.T(t, k)];
  for (long q = 0; q < part.F.rows(); ++q)
    for (int k = 0; k < 3; ++k) part.F(q, k) = renum[part.F(q, k)];
}

}  // namespace

TetMesh kept_part(const TetMesh& mesh, const std::vector<char>& kept, KeptNodes nodes) {
  TetMesh part;
  part.V = mesh.V;
  const bool tagged = mesh.domain.size() == mesh.T.rows();
  std::unordered_set<FaceKey, FaceKeyHash> kept_faces;
  long n = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) n += kept[t] != 0;
  part.T.resize(n, 4), part.domain = VecXi::Zero(n);
  n = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (!kept[t]) continue;
    for (int k = 0; k < 4; ++k)
      kept_faces.insert(face_key(mesh.T(t, kTetFace[k][0]), mesh.T(t, kTetFace[k][1]), mesh.T(t, kTetFace[k][2])));
    part.T.row(n) = mesh.T.row(t);
    if (tagged) part.domain[n] = mesh.domain[t];
    ++n;
  }
  const bool faced = mesh.face.size() == mesh.F.rows(), nd = mesh.nd_face.size() == mesh.F.rows();
  part.F.resize(mesh.F.rows(), 3);
  if (faced) part.face.resize(mesh.F.rows());
  if (nd) part.nd_face.resize(mesh.F.rows());
  long nf = 0;
  for (long q = 0; q < mesh.F.rows(); ++q) {
    if (!kept_faces.count(face_key(mesh.F(q, 0), mesh.F(q, 1), mesh.F(q, 2)))) continue;
    part.F.row(nf) = mesh.F.row(q);
    if (faced) part.face[nf] = mesh.face[q];
    if (nd) part.nd_face[nf] = mesh.nd_face[q];
    ++nf;
  }
  part.F.conservativeResize(nf, 3);
  if (faced) part.face.conservativeResize(nf);
  if (nd) part.nd_face.conservativeResize(nf);
  if (nodes == KeptNodes::Compact) compact_nodes(part, mesh.V);
  return part;
}

}  // namespace topopt::fem
