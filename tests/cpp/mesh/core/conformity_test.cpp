#include "mesh/core/conformity.h"

#include <gtest/gtest.h>

#include "brep/shape_io.h"
#include "mesh/core/structured_box.h"

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
