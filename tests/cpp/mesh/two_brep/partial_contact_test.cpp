// Partial contact through the 14 steps (issue 20): non-design solids whose faces lie partly on
// the part's boundary and partly inside it, across two faces of the part, cut by the part's
// outer face, or touching each other on unequal faces. Each fixture (built in code from OCCT
// primitives) and the shared mount example mesh natively into one conformal tagged mesh with
// every domain's volume within 0.5 % of its B-Rep's, and a non-design face on the part's
// boundary keeps the input's face number wherever the imprint split it.
#include <gtest/gtest.h>

#include <set>

#include "brep/partial_contact_fixtures.h"
#include "brep/shape_io.h"
#include "brep/two_breps.h"
#include "mesh/core/conformity.h"
#include "mesh/core/tet_quality.h"
#include "mesh/two_brep/native_mesher.h"
#include "pipeline/mesh_settings.h"

namespace topopt::mesh {
namespace {

/// The product's parameters (pipeline/mesh_settings.h) at `factor` times the default size.
TetMesh mesh_at(const brep::TwoBReps& model, double factor) {
  pipeline::MeshSettings s;
  s.size = factor * model.part.diagonal() / 50;
  return mesh_native(model, pipeline::native_mesh_params(s, pipeline::resolve_mesh_sizes(s, model.part.diagonal(), 0)));
}

/// Conformal, tagged, every domain's volume within 0.5 %, no flat tet.
void expect_conformal_with_volumes(const TetMesh& m, const brep::TwoBReps& model) {
  const ConformityReport c = check_conformity(m, &model);
  EXPECT_TRUE(c.ok()) << c.to_json().dump();
  EXPECT_EQ(c.duplicate_nodes, 0);
  EXPECT_EQ(c.interface_off_nondesign, 0);
  ASSERT_EQ(c.domain_volume.size(), static_cast<size_t>(model.nondesign.num_solids() + 1));
  ASSERT_EQ(c.expected_volume.size(), c.domain_volume.size());
  for (size_t d = 0; d < c.domain_volume.size(); ++d)
    EXPECT_NEAR(c.domain_volume[d], c.expected_volume[d], 0.005 * c.expected_volume[d]) << "domain " << d;
  EXPECT_GT(tet_quality(m).min_radius_ratio, 0.1);
  EXPECT_GE(m.face.minCoeff(), 1);
  EXPECT_LE(m.face.maxCoeff(), model.part.num_faces());
  EXPECT_GE(m.nd_face.minCoeff(), 0);
  EXPECT_LE(m.nd_face.maxCoeff(), model.nondesign.num_faces());  // the input's numbers, not the imprint's
}

TEST(PartialContact, EveryFixtureMeshesIntoOneConformalTaggedMesh) {
  for (const auto& fx : testing::partial_contact_fixtures()) {
    SCOPED_TRACE(fx.name);
    const brep::TwoBReps model = brep::load_two_breps(fx.part, fx.nondesign);
    EXPECT_TRUE(model.meshed.imprinted);
    expect_conformal_with_volumes(mesh_at(model, 1.0), model);
  }
}

TEST(PartialContact, MountMeshesAtTheDefaultSizeAndAtHalfOfIt) {
  const std::string dir = std::string(TOPOPT_SHARED_DATA) + "/examples/";
  const brep::TwoBReps model = brep::load_two_breps(brep::read_shape_file(dir + "mount.step"),
                                                    brep::read_shape_file(dir + "mount_nondesign.step"));
  ASSERT_TRUE(model.meshed.imprinted);
  for (double factor : {1.0, 0.5}) {
    SCOPED_TRACE(std::to_string(factor) + " x the default size");
    expect_conformal_with_volumes(mesh_at(model, factor), model);
  }
}

TEST(PartialContact, APadFaceAcrossTwoPartFacesIsTaggedOnBothWithItsInputNumber) {
  // the pad's top face (Face6 of Ω̄, 10 x 10 at z = 20) spans the part's two top faces at x = 20
  const auto fx = testing::pad_spanning_two_faces();
  const brep::TwoBReps model = brep::load_two_breps(fx.part, fx.nondesign);
  const TetMesh m = mesh_at(model, 1.0);
  double area = 0;
  std::set<int> part_faces;
  for (long t = 0; t < m.F.rows(); ++t) {
    if (m.nd_face[t] != 6) continue;
    part_faces.insert(m.face[t]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(m.V(m.F(t, k), 2), 20.0, 1e-9);
    area += 0.5 * (m.V.row(m.F(t, 1)) - m.V.row(m.F(t, 0))).cross(m.V.row(m.F(t, 2)) - m.V.row(m.F(t, 0))).norm();
  }
  EXPECT_EQ(part_faces.size(), 2u);
  EXPECT_NEAR(area, 100.0, 1e-9);
}

}  // namespace
}  // namespace topopt::mesh
