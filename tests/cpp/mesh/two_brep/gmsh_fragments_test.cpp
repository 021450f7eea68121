// The interim two-B-Rep mesher on the shared examples: one conformal mesh, domains in input
// order with the B-Reps' volumes, every boundary triangle tagged with a face of Ω.
#include "mesh/two_brep/gmsh_fragments.h"

#include <gtest/gtest.h>

#include "brep/shape_io.h"
#include "common/error.h"
#include "mesh/core/conformity.h"
#include "mesh/core/tet_quality.h"

namespace topopt::mesh {
namespace {

brep::TwoBReps example(const std::string& name) {
  std::string dir = std::string(TOPOPT_SHARED_DATA) + "/examples/";
  return brep::load_two_breps(brep::read_shape_file(dir + name + ".step"),
                              brep::read_shape_file(dir + name + "_nondesign.step"));
}

void check(const std::string& name, double size) {
  brep::TwoBReps model = example(name);
  FragmentMeshParams p;
  p.size = size;
  TetMesh m = mesh_with_gmsh_fragments(model, p);
  ConformityReport c = check_conformity(m, &model);
  EXPECT_TRUE(c.ok()) << name << ": " << c.to_json().dump();
  EXPECT_LT(c.max_volume_error, 0.005) << name;
  ASSERT_EQ(static_cast<int>(c.domain_volume.size()), model.nondesign.num_solids() + 1);
  for (long t = 0; t < m.F.rows(); ++t) {
    ASSERT_GE(m.face[t], 1) << name << ": an untagged boundary triangle";
    ASSERT_LE(m.face[t], model.part.num_faces());
  }
  QualityReport q = tet_quality(m);
  EXPECT_GT(q.min_radius_ratio, 0.05) << name;
}

TEST(GmshFragments, RockerDefaultAndFiner) {
  check("rocker", 0);
  check("rocker", 1.5);
}

TEST(GmshFragments, CantileverAndBracketWithPadsInContact) {
  check("cantilever", 0);
  check("bracket", 0);
}

TEST(GmshFragments, NativeAdvancingFrontFillsTheVolumesConformally) {
  // steps 12–14 on Gmsh's surface mesh: non-design solids first, then Ω around their tets
  brep::TwoBReps model = example("cantilever");
  FragmentMeshParams p;
  p.size = 2.5;
  p.native_volume = true;
  TetMesh m = mesh_with_gmsh_fragments(model, p);
  ConformityReport c = check_conformity(m, &model);
  EXPECT_TRUE(c.ok()) << c.to_json().dump();
  EXPECT_LT(c.max_volume_error, 1e-9);  // planar faces: exact
  EXPECT_EQ(c.domain_volume.size(), 3u);
}

TEST(GmshFragments, TooLargeIsRefusedWithASizeToUse) {
  brep::TwoBReps model = example("cantilever");
  FragmentMeshParams p;
  p.size = 0.01;
  try {
    mesh_with_gmsh_fragments(model, p);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::TooLarge);
    EXPECT_NE(std::string(e.what()).find("use a mesh size of at least"), std::string::npos);
  }
}

}  // namespace
}  // namespace topopt::mesh
