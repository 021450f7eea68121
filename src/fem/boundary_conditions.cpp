// Supports and loads on B-Rep faces, turned into fixed dofs and nodal loads (see the header).
#include "fem/boundary_conditions.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>

#include "common/error.h"

namespace topopt::fem {
namespace {

/// Appends to `out` the boundary triangles t with tag[t] == f (tag: #F face numbers); returns
/// how many.
size_t append_tagged(const VecXi& tag, int f, std::vector<int>& out) {
  const size_t before = out.size();
  for (long t = 0; t < tag.size(); ++t)
    if (tag[t] == f) out.push_back(static_cast<int>(t));
  return out.size() - before;
}

/// Triangles of the mesh boundary on the given Ω faces and Ω̄ faces. Throws FaceNotFound
/// naming the first face that has no triangle. `what` names the support or load.
std::vector<int> triangles_on(const TetMesh& mesh, const std::vector<int>& faces, const std::vector<int>& nd_faces,
                              const std::string& what) {
  std::vector<int> out;
  int max_face = mesh.face.size() ? mesh.face.maxCoeff() : 0;
  for (int f : faces)
    if (append_tagged(mesh.face, f, out) == 0) {
      std::ostringstream s;
      s << what << ": the part has no face Face" << f << " (its mesh has faces Face1 to Face" << max_face
        << "); pick a face of the part";
      throw Error(ErrorCode::FaceNotFound, s.str());
    }
  for (int f : nd_faces)
    if (append_tagged(mesh.nd_face, f, out) == 0) {
      std::ostringstream s;
      s << what << ": face NonDesign:Face" << f
        << " is not on the outside of the part (or does not exist); loads and supports act on "
           "the part's boundary";
      throw Error(ErrorCode::FaceNotFound, s.str());
    }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// Area-weighted normal (length = area) of boundary triangle t.
Eigen::Vector3d area_normal(const TetMesh& mesh, int t) {
  Eigen::Vector3d a = mesh.V.row(mesh.F(t, 0)), b = mesh.V.row(mesh.F(t, 1)), c = mesh.V.row(mesh.F(t, 2));
  return 0.5 * (b - a).cross(c - a);
}

std::string face_list(const std::vector<int>& faces, const std::vector<int>& nd) {
  std::string s;
  for (int f : faces) s += (s.empty() ? "" : ", ") + std::string("Face") + std::to_string(f);
  for (int f : nd) s += (s.empty() ? "" : ", ") + std::string("NonDesign:Face") + std::to_string(f);
  return s;
}

}  // namespace

Supports make_supports(const TetMesh& mesh, const std::vector<SupportSpec>& specs) {
  std::vector<double> value(3 * mesh.V.rows(), 0.0);
  std::vector<char> fixed(3 * mesh.V.rows(), 0);
  for (const SupportSpec& spec : specs) {
    const std::string what = "support on " + face_list(spec.faces, spec.nd_faces);
    std::vector<int> tris = triangles_on(mesh, spec.faces, spec.nd_faces, what);
    std::array<bool, 3> fix = spec.fix;
    if (spec.kind == SupportSpec::Kind::Fixed) fix = {true, true, true};
    if (spec.kind == SupportSpec::Kind::Symmetry) {
      Eigen::Vector3d n = Eigen::Vector3d::Zero();
      for (int t : tris) n += area_normal(mesh, t);
      if (n.norm() == 0) throw Error(ErrorCode::InvalidParameter, what + ": the faces have no area");
      n.normalize();
      for (int t : tris) {
        Eigen::Vector3d nt = area_normal(mesh, t);
        if (nt.norm() > 0 && nt.normalized().dot(n) < 1 - 1e-6)
          throw Error(ErrorCode::InvalidParameter, what + ": a symmetry plane must be planar; these faces are not");
      }
      int axis = 0;
      n.cwiseAbs().maxCoeff(&axis);
      if (std::abs(n[axis]) < 1 - 1e-6)
        throw Error(ErrorCode::InvalidParameter, what +
                                                     ": a symmetry plane must be perpendicular to x, y or z (model the "
                                                     "part so that its symmetry plane is a coordinate plane)");
      fix = {false, false, false};
      fix[axis] = true;
    }
    if (!fix[0] && !fix[1] && !fix[2]) throw Error(ErrorCode::InvalidParameter, what + ": no component is fixed");
    for (int t : tris)
      for (int k = 0; k < 3; ++k)
        for (int c = 0; c < 3; ++c)
          if (fix[c]) fixed[3 * mesh.F(t, k) + c] = 1;
  }
  Supports s;
  for (size_t d = 0; d < fixed.size(); ++d)
    if (fixed[d]) s.dofs.push_back(static_cast<int>(d)), s.values.push_back(value[d]);
  if (s.dofs.empty())
    throw Error(ErrorCode::NoSupport,
                "no support given: add at least one fixed face (or fixed components / symmetry "
                "planes that together hold the part)");
  return s;
}

Eigen::Matrix3Xd gravity_of(const std::vector<LoadCase>& cases) {
  Eigen::Matrix3Xd g = Eigen::Matrix3Xd::Zero(3, static_cast<long>(cases.size()));
  for (size_t k = 0; k < cases.size(); ++k)
    for (const LoadSpec& item : cases[k].items)
      if (item.kind == LoadSpec::Kind::Gravity)
        g.col(static_cast<long>(k)) += Eigen::Vector3d(item.vector[0], item.vector[1], item.vector[2]);
  return g;
}

Eigen::MatrixXd make_loads(const TetMesh& mesh, const Material& material, const std::vector<LoadCase>& cases) {
  Eigen::MatrixXd F = Eigen::MatrixXd::Zero(3 * mesh.V.rows(), static_cast<long>(cases.size()));
  for (size_t k = 0; k < cases.size(); ++k) {
    for (const LoadSpec& item : cases[k].items) {
      if (item.kind == LoadSpec::Kind::Gravity) {
        Eigen::Vector3d g(item.vector[0], item.vector[1], item.vector[2]);
        for (long t = 0; t < mesh.T.rows(); ++t) {
          Eigen::Vector3d p0 = mesh.V.row(mesh.T(t, 0));
          Eigen::Matrix3d J;
          for (int a = 0; a < 3; ++a) J.col(a) = mesh.V.row(mesh.T(t, a + 1)).transpose() - p0;
          double vol = J.determinant() / 6.0;
          Eigen::Vector3d f = material.density * vol / 4.0 * g;
          for (int a = 0; a < 4; ++a)
            for (int c = 0; c < 3; ++c) F(3 * mesh.T(t, a) + c, k) += f[c];
        }
        continue;
      }
      const std::string what = std::string(item.kind == LoadSpec::Kind::Force ? "force" : "pressure") + " on " +
                               face_list(item.faces, item.nd_faces);
      std::vector<int> tris = triangles_on(mesh, item.faces, item.nd_faces, what);
      double area = 0;
      for (int t : tris) area += area_normal(mesh, t).norm();
      if (!(area > 0)) throw Error(ErrorCode::InvalidParameter, what + ": the faces have no area");
      Eigen::Vector3d total(item.vector[0], item.vector[1], item.vector[2]);
      for (int t : tris) {
        Eigen::Vector3d an = area_normal(mesh, t);
        Eigen::Vector3d f = item.kind == LoadSpec::Kind::Force ? Eigen::Vector3d(total * (an.norm() / area))
                                                               : Eigen::Vector3d(-item.value * an);
        for (int a = 0; a < 3; ++a)
          for (int c = 0; c < 3; ++c) F(3 * mesh.F(t, a) + c, k) += f[c] / 3.0;
      }
    }
  }
  return F;
}

}  // namespace topopt::fem
