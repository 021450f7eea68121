// The Gmsh fallback on the shared examples: one conformal mesh, domains in input order with
// the B-Reps' volumes, every boundary triangle tagged with a face of Ω. Run as the product
// runs it, in a child process (pipeline::mesh_with_gmsh_isolated), with the product's sizes.
#include "mesh/two_brep/gmsh_fragments.h"

#include <gtest/gtest.h>

#include "brep/shape_io.h"
#include "common/error.h"
#include "mesh/core/conformity.h"
#include "mesh/core/tet_quality.h"
#include "pipeline/mesh_model.h"
#include "pipeline/mesh_settings.h"

namespace topopt::mesh {
namespace {

brep::TwoBReps example(const std::string& name) {
  std::string dir = std::string(TOPOPT_SHARED_DATA) + "/examples/";
  return brep::load_two_breps(brep::read_shape_file(dir + name + ".step"),
                              brep::read_shape_file(dir + name + "_nondesign.step"));
}

/// The product's Gmsh parameters for `settings` on `model`.
FragmentMeshParams params_for(const brep::TwoBReps& model, const pipeline::MeshSettings& settings) {
  return pipeline::gmsh_mesh_params(
      settings, pipeline::resolve_mesh_sizes(settings, model.part.diagonal(), std::abs(model.part.solid_volume.sum())));
}

TetMesh gmsh_mesh(const brep::TwoBReps& model, const pipeline::MeshSettings& settings) {
  return pipeline::mesh_with_gmsh_isolated(model, params_for(model, settings), 600);
}

void check(const std::string& name, double size) {
  brep::TwoBReps model = example(name);
  pipeline::MeshSettings s;
  s.size = size;
  TetMesh m = gmsh_mesh(model, s);
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
  pipeline::MeshSettings s;
  s.size = 2.5;
  s.mesher = pipeline::Mesher::Gmsh;
  s.gmsh_volume_by_front = true;
  TetMesh m = gmsh_mesh(model, s);
  ConformityReport c = check_conformity(m, &model);
  EXPECT_TRUE(c.ok()) << c.to_json().dump();
  EXPECT_LT(c.max_volume_error, 1e-9);  // planar faces: exact
  EXPECT_EQ(c.domain_volume.size(), 3u);
}

TEST(GmshFragments, RefusesParamsWithoutSizes) {
  // the sizes are decided by pipeline::MeshSettings; the check comes before Gmsh starts
  brep::TwoBReps model = example("cantilever");
  try {
    mesh_with_gmsh_fragments(model, FragmentMeshParams{});
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Internal);
  }
}

}  // namespace
}  // namespace topopt::mesh
