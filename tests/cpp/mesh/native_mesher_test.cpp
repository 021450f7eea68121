// The native path end to end on the shared examples (a part without non-design solids): our
// surface mesh filled by our advancing front is conformal, has no inverted tet, its boundary
// is the surface mesh and its volume is the B-Rep's within 0.5 %; non-design input is refused
// with a message until the 14-step driver lands.
#include "mesh/native_mesher.h"

#include <gtest/gtest.h>

#include "brep/shape_io.h"
#include "common/error.h"
#include "mesh/conformity.h"
#include "mesh/tet_quality.h"

namespace topopt::mesh {
namespace {

brep::TwoBReps load(const std::string& name, bool with_nd = false) {
  const std::string dir = std::string(TOPOPT_SHARED_DATA) + "/examples/";
  return brep::load_two_breps(brep::read_shape_file(dir + name + ".step"),
                              with_nd ? brep::read_shape_file(dir + name + "_nondesign.step") : TopoDS_Shape());
}

TEST(NativeMesher, ExamplesAreConformalWithTheBRepVolume) {
  for (auto [name, factor] : {std::pair<const char*, double>{"rocker", 1.0}, {"rocker", 0.5}, {"cantilever", 1.0}, {"bracket", 1.0}}) {
    SCOPED_TRACE(std::string(name) + " at " + std::to_string(factor) + " x the default size");
    const brep::TwoBReps model = load(name);
    NativeMeshParams p;
    p.surface.size = factor * model.part.diagonal() / 50;
    const TetMesh m = mesh_native(model, p);
    const ConformityReport c = check_conformity(m, &model);
    EXPECT_TRUE(c.ok()) << c.to_json().dump();
    EXPECT_LT(c.max_volume_error, 0.005);
    const QualityReport q = tet_quality(m);
    EXPECT_GT(q.min_radius_ratio, 0);  // no flat or inverted tet
    EXPECT_GT(q.mean_radius_ratio, 0.7);
  }
}

TEST(NativeMesher, NonDesignSolidsAreRefusedWithAMessage) {
  try {
    mesh_native(load("rocker", true));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidParameter);
    EXPECT_NE(std::string(e.what()).find("non-design"), std::string::npos);
  }
}

}  // namespace
}  // namespace topopt::mesh
