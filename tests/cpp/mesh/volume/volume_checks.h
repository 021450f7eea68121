// What the volume tests share: surfaces made from tets, the checks of a filled mesh, the
// conversions to the fill's internal formats, and our surface mesh of a shared part.
#pragma once
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "brep/shape_io.h"
#include "io/msh.h"
#include "mesh/core/conformity.h"
#include "mesh/core/tet_quality.h"
#include "mesh/surface/surface_mesher.h"
#include "mesh/volume/volume_front.h"
#include "simp/density_filter.h"

namespace topopt::mesh {

/// The closed surface of the given tets (outward), on compacted nodes.
inline void surface_of(const TetMesh& m, const std::vector<int>& keep, MatX3d& V, MatX3i& F) {
  MatX4i T(keep.size(), 4);
  for (size_t i = 0; i < keep.size(); ++i) T.row(i) = m.T.row(keep[i]);
  MatX3i B = io::boundary_triangles(T);
  std::vector<int> map(m.V.rows(), -1);
  std::vector<Eigen::RowVector3d> pts;
  F.resize(B.rows(), 3);
  for (long t = 0; t < B.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      int v = B(t, k);
      if (map[v] < 0) map[v] = static_cast<int>(pts.size()), pts.push_back(m.V.row(v));
      F(t, k) = map[v];
    }
  V.resize(pts.size(), 3);
  for (size_t i = 0; i < pts.size(); ++i) V.row(i) = pts[i];
}

/// Checks the filled mesh (T0 ∪ new tets) against the surface and returns its volume.
inline double check_fill(const MatX3d& V, const MatX3i& F, const MatX4i& T0, const VolumeFillResult& r,
                         double expected_volume) {
  TetMesh m;
  m.V = r.V;
  m.T.resize(T0.rows() + r.T.rows(), 4);
  if (T0.rows()) m.T.topRows(T0.rows()) = T0;
  m.T.bottomRows(r.T.rows()) = r.T;
  m.domain = VecXi::Zero(m.T.rows());
  m.F = F;
  m.face = VecXi::Ones(F.rows());
  EXPECT_EQ(r.V.topRows(V.rows()), V) << "input nodes moved";
  ConformityReport c = check_conformity(m);
  EXPECT_EQ(c.inverted_tets, 0);
  EXPECT_EQ(c.overshared_faces, 0);
  EXPECT_EQ(c.boundary_not_in_F, 0) << "the mesh's boundary is not the input surface";
  EXPECT_EQ(c.F_not_boundary, 0);
  EXPECT_EQ(c.duplicate_nodes, 0);
  double vol = simp::tet_volumes(m).sum();
  EXPECT_NEAR(vol, expected_volume, 1e-9 * expected_volume);
  return vol;
}

inline std::vector<Eigen::Vector3d> points_of(const MatX3d& V) {
  std::vector<Eigen::Vector3d> P(V.rows());
  for (long i = 0; i < V.rows(); ++i) P[i] = V.row(i).transpose();
  return P;
}

inline std::vector<std::array<int, 3>> triangles_of(const MatX3i& F) {
  std::vector<std::array<int, 3>> B(F.rows());
  for (long t = 0; t < F.rows(); ++t) B[t] = {F(t, 0), F(t, 1), F(t, 2)};
  return B;
}

inline double tet_volume(const std::vector<Eigen::Vector3d>& P, const std::array<int, 4>& t) {
  return (P[t[1]] - P[t[0]]).dot((P[t[2]] - P[t[0]]).cross(P[t[3]] - P[t[0]])) / 6;
}

/// Winding number of the closed surface (V, F) around x (1 inside, 0 outside): the solid
/// angles of its triangles seen from x, over 4π.
inline double winding_number(const MatX3d& V, const MatX3i& F, const Eigen::Vector3d& x) {
  double sum = 0;
  for (long t = 0; t < F.rows(); ++t) {
    const Eigen::Vector3d a = V.row(F(t, 0)).transpose() - x, b = V.row(F(t, 1)).transpose() - x,
                          c = V.row(F(t, 2)).transpose() - x;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    sum += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return sum / (4 * M_PI);
}

/// The volume a closed surface (triangles F on nodes V, normals out) bounds, by the
/// divergence theorem.
inline double surface_volume(const MatX3d& V, const MatX3i& F) {
  double volume = 0;
  for (long t = 0; t < F.rows(); ++t) volume += V.row(F(t, 0)).dot(V.row(F(t, 1)).cross(V.row(F(t, 2)))) / 6;
  return volume;
}

/// Our surface mesh of a part of ../shared/data at its default size (diagonal / 50, also
/// returned in `size`).
inline SurfaceMesh default_surface(const std::string& file, double* size = nullptr) {
  const brep::TopologyIndex topo =
      brep::index_topology(brep::read_shape_file(std::string(TOPOPT_SHARED_DATA) + "/" + file));
  SurfaceMeshParams sp;
  sp.size = topo.diagonal() / 50;
  if (size) *size = sp.size;
  return mesh_surface(topo, sp);
}

/// Fills the closed surface (V: #V by 3, F: #F by 3, outward) with no existing tets at the
/// uniform edge length `size`, checks the fill (check_fill: against the surface's volume) and
/// returns the quality of its tets; `tets`, when given, gets their number.
inline QualityReport fill_at_size(const MatX3d& V, const MatX3i& F, double size, long* tets = nullptr) {
  VolumeFillParams p;
  p.size = [size](const double*) { return size; };
  const VolumeFillResult r = fill_volume(V, F, MatX4i(), p);
  check_fill(V, F, MatX4i(), r, surface_volume(V, F));
  if (tets) *tets = r.T.rows();
  TetMesh m;
  m.V = r.V, m.T = r.T;
  return tet_quality(m);
}

}  // namespace topopt::mesh
