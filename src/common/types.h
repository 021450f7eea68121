// Flat array types shared by all stages (geogram/libigl style): one row per entity.
#pragma once
#include <Eigen/Dense>
#include <vector>

namespace topopt {

/// #V by 3 coordinates, row-major so that one node's x,y,z are contiguous.
using MatX3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #T by 4 tetrahedra (node indices, 0-based, positive orientation).
using MatX4i = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;
/// #P by 2 points of a parameter plane (u, v).
using MatX2d = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;
/// #F by 3 triangles (node indices, 0-based).
using MatX3i = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #E by 2 segments (node indices, 0-based).
using MatX2i = Eigen::Matrix<int, Eigen::Dynamic, 2, Eigen::RowMajor>;
using VecXi = Eigen::VectorXi;
using VecXd = Eigen::VectorXd;

/// A tagged tetrahedral mesh: what the mesher produces and FEM, SIMP and surface consume.
struct TetMesh {
  MatX3d V;      ///< #V by 3 node coordinates (mm)
  MatX4i T;      ///< #T by 4 tets, positively oriented (det[v1-v0, v2-v0, v3-v0] > 0)
  VecXi domain;  ///< #T: 0 = design domain Ω0, i >= 1 = non-design solid Ωi (input order)
  MatX3i F;      ///< #F by 3 boundary triangles of Ω, oriented outwards
  VecXi face;    ///< #F: Ω's B-Rep face number, 1-based as FreeCAD's FaceN (0 if unknown)
  /// #F (or empty): the face of the non-design compound Ω̄ that the triangle also lies on,
  /// 1-based in FreeCAD's numbering of that compound; 0 if none. Lets loads and supports
  /// act on a load pad's face where it forms part of Ω's boundary.
  VecXi nd_face;
};

}  // namespace topopt
