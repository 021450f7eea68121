#include "mesh/core/conformity.h"

#include <gtest/gtest.h>

#include <sstream>

#include "brep/shape_io.h"
#include "common/face_key.h"
#include "mesh/core/structured_box.h"
#include "mesh/core/tet_quality.h"

using namespace topopt;

namespace {

// The cantilever example meshed structurally: 60 x 20 x 10 with the support slab x in [0,2]
// and the load pad x in [56,60], y in [7,13] as non-design boxes.
TetMesh cantilever_mesh() {
  mesh::StructuredBoxParams p;
  p.size = {60, 20, 10};
  p.cells = {30, 20, 5};
  p.nondesign = {{0, 0, 0, 2, 20, 10}, {56, 7, 0, 60, 13, 10}};
  return mesh::structured_box_mesh(p);
}

const brep::TwoBReps& cantilever_geometry() {
  static const brep::TwoBReps g =
      brep::load_two_breps(brep::read_shape_file(TOPOPT_SHARED_DATA "/examples/cantilever.step"),
                           brep::read_shape_file(TOPOPT_SHARED_DATA "/examples/cantilever_nondesign.step"));
  return g;
}

}  // namespace

TEST(Conformity, StructuredCantileverAgreesWithTheBReps) {
  TetMesh m = cantilever_mesh();
  mesh::ConformityReport r = mesh::check_conformity(m, &cantilever_geometry());
  EXPECT_TRUE(r.ok()) << r.to_json().dump(1);
  EXPECT_GT(r.interface_triangles, 0);
  EXPECT_EQ(r.interface_sampled, r.interface_triangles);
  ASSERT_EQ(r.domain_volume.size(), 3u);
  EXPECT_NEAR(r.domain_volume[1], 400.0, 1e-9);
  EXPECT_NEAR(r.domain_volume[2], 240.0, 1e-9);
  EXPECT_NEAR(r.domain_volume[0], 12000.0 - 640.0, 1e-12 * 12000);
  // Load pad's top face (z = 10) is the compound's face 6 + 6 = 12 and covers 4 x 6 mm².
  double pad_top = 0;
  for (int f = 0; f < m.F.rows(); ++f)
    if (m.nd_face[f] == 12) {
      Eigen::Vector3d a = m.V.row(m.F(f, 1)) - m.V.row(m.F(f, 0)), b = m.V.row(m.F(f, 2)) - m.V.row(m.F(f, 0));
      pad_top += a.cross(b).norm() / 2;
    }
  EXPECT_NEAR(pad_top, 24.0, 1e-9);
}

TEST(Conformity, FindsEachKindOfDefect) {
  const TetMesh good = cantilever_mesh();
  {
    TetMesh m = good;  // a missing tet opens the mesh
    m.T.conservativeResize(m.T.rows() - 1, 4);
    m.domain.conservativeResize(m.T.rows());
    auto r = mesh::check_conformity(m);
    EXPECT_FALSE(r.ok());
    EXPECT_GT(r.boundary_not_in_F + r.F_not_boundary, 0);
  }
  {
    TetMesh m = good;  // an inverted tet
    std::swap(m.T(10, 0), m.T(10, 1));
    EXPECT_EQ(mesh::check_conformity(m).inverted_tets, 1);
  }
  {
    TetMesh m = good;  // a node placed on top of another
    m.V.row(5) = m.V.row(6);
    EXPECT_GE(mesh::check_conformity(m).duplicate_nodes, 1);
  }
  {
    TetMesh m = good;  // a design tet tagged as non-design: volumes and interface are wrong
    for (int t = 0; t < m.T.rows(); ++t)
      if (m.domain[t] == 0) {
        m.domain[t] = 1;
        break;
      }
    auto r = mesh::check_conformity(m, &cantilever_geometry());
    EXPECT_FALSE(r.ok());
    EXPECT_GT(r.interface_off_nondesign, 0);
  }
  {
    TetMesh m = good;  // a boundary triangle flipped: the boundary is no longer oriented
    std::swap(m.F(0, 1), m.F(0, 2));
    EXPECT_GT(mesh::check_conformity(m).open_boundary_edges, 0);
  }
}

namespace {

// One tet on nodes V (4 by 3) with its four faces as the boundary, turned outwards when the
// tet is positive.
TetMesh one_tet(const MatX3d& V) {
  TetMesh m;
  m.V = V;
  m.T.resize(1, 4);
  m.T << 0, 1, 2, 3;
  m.F.resize(4, 3);
  for (int k = 0; k < 4; ++k) m.F.row(k) << kTetFace[k][0], kTetFace[k][1], kTetFace[k][2];
  m.domain = Eigen::VectorXi::Zero(1);
  return m;
}

}  // namespace

TEST(Conformity, AcceptsTheUnitTetAsItsOwnMesh) {
  MatX3d V(4, 3);
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  const mesh::ConformityReport r = mesh::check_conformity(one_tet(V));
  EXPECT_TRUE(r.ok()) << r.describe();
  EXPECT_EQ(r.describe(), "");
  ASSERT_EQ(r.worst_tets.size(), 1u);
  EXPECT_EQ(r.worst_tets[0].orientation, 1);
  EXPECT_NEAR(r.worst_tets[0].radius_ratio, mesh::radius_ratio(V.row(0), V.row(1), V.row(2), V.row(3)), 1e-15);
}

TEST(Conformity, RejectsAFlatTetNamingWhereItIs) {
  MatX3d V(4, 3);  // four coplanar points: the square z = 3 around (10.5, 20.5, 3)
  V << 10, 20, 3, 11, 20, 3, 10, 21, 3, 11, 21, 3;
  const mesh::ConformityReport r = mesh::check_conformity(one_tet(V));
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.flat_tets, 1);
  EXPECT_EQ(r.inverted_tets, 0);
  ASSERT_FALSE(r.worst_tets.empty());
  EXPECT_EQ(r.worst_tets[0].orientation, 0);
  const std::string text = r.describe();
  EXPECT_NE(text.find("1 flat tets"), std::string::npos) << text;
  EXPECT_NE(text.find("near (10.5, 20.5, 3)"), std::string::npos) << text;
  try {
    mesh::require_valid_mesh(r, "the test mesh");
    ADD_FAILURE() << "a flat tet passed";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::MeshingFailed);
    EXPECT_NE(std::string(e.what()).find("the test mesh is not a valid mesh: 1 flat tets"), std::string::npos)
        << e.what();
  }
}

TEST(Conformity, RejectsANearlyFlatTetThatFloatingPointCallsPositive) {
  MatX3d V(4, 3);  // the fourth node 1e-9 above the plane of the others, well inside their triangle
  V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, 1e-9;
  const mesh::ConformityReport r = mesh::check_conformity(one_tet(V));
  ASSERT_GT(r.domain_volume[0], 0);  // positive, exactly and in floating point
  EXPECT_EQ(r.flat_tets, 1);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.describe().find("near (0.325, 0.325, 2.5e-10)"), std::string::npos) << r.describe();
}

TEST(Conformity, NamesTheInvertedTetOfALargerMesh) {
  TetMesh m = cantilever_mesh();
  std::swap(m.T(10, 0), m.T(10, 1));
  const Eigen::RowVector3d c =
      (m.V.row(m.T(10, 0)) + m.V.row(m.T(10, 1)) + m.V.row(m.T(10, 2)) + m.V.row(m.T(10, 3))) / 4;
  const mesh::ConformityReport r = mesh::check_conformity(m);
  EXPECT_EQ(r.inverted_tets, 1);
  EXPECT_EQ(r.flat_tets, 0);
  ASSERT_EQ(r.worst_tets.size(), 5u);
  EXPECT_EQ(r.worst_tets[0].tet, 10);
  EXPECT_EQ(r.worst_tets[0].orientation, -1);
  for (size_t k = 1; k < r.worst_tets.size(); ++k) {
    EXPECT_EQ(r.worst_tets[k].orientation, 1);
    EXPECT_LE(r.worst_tets[k - 1].orientation == 1 ? r.worst_tets[k - 1].radius_ratio : 0.0,
              r.worst_tets[k].radius_ratio);
  }
  std::ostringstream near;
  near << "tet 10 near (" << c.x() << ", " << c.y() << ", " << c.z() << ")";
  EXPECT_NE(r.describe().find("1 inverted tets (negative volume), the worst " + near.str()), std::string::npos)
      << r.describe();
}
