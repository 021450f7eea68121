// The imprint of the part's boundary on the non-design solids (brep/imprint.h): a face partly
// on Ω's boundary and partly inside becomes faces each wholly on one face of Ω or wholly
// inside; every piece remembers the input face it came from; Ω̄ without partial contact is
// kept as it is (its meshes must not change).
#include "brep/imprint.h"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "brep/report.h"
#include "brep/shape_io.h"
#include "brep/two_breps.h"
#include "partial_contact_fixtures.h"

namespace topopt::brep {
namespace {

TEST(Imprint, BossOuterCylinderSplitsIntoAPieceOnThePartAndAPieceInside) {
  const auto fx = testing::plate_with_bosses_on_one_side();
  const TwoBReps m = load_two_breps(fx.part, fx.nondesign);
  ASSERT_TRUE(m.meshed.imprinted);
  ASSERT_EQ(m.meshed.topo.num_solids(), 2);
  ASSERT_EQ(static_cast<int>(m.meshed.face_origin.size()), m.meshed.topo.num_faces());
  // The input's outer cylinders are interior as a whole (they lie on no one face of Ω).
  for (int f = 0; f < m.nondesign.num_faces(); ++f)
    if (m.nondesign.face_surface[f] == "Cylinder" && m.nondesign.face_area[f] > 2 * 3.1416 * 6 * 14 - 1) {
      EXPECT_EQ(m.nd_on_part.face[f].on, On::Interior) << "input Face" << f + 1;
    }
  // After the imprint each outer cylinder is two faces: z in [0, 8] inside (area 2 pi 6 8),
  // z in [8, 14] on the part's boss face (2 pi 6 6); both come from the input's cylinder.
  const double inside = 2 * M_PI * 6 * 8, outside = 2 * M_PI * 6 * 6;
  int n_inside = 0, n_outside = 0;
  for (int f = 0; f < m.meshed.topo.num_faces(); ++f) {
    if (m.meshed.topo.face_surface[f] != "Cylinder") continue;
    const int origin = m.meshed.face_origin[f];
    ASSERT_GE(origin, 0);
    EXPECT_EQ(m.nondesign.face_surface[origin], "Cylinder");
    const double a = m.meshed.topo.face_area[f];
    if (std::abs(a - inside) < 1e-3 * inside) {
      ++n_inside;
      EXPECT_EQ(m.meshed.on_part.face[f].on, On::Interior);
    } else if (std::abs(a - outside) < 1e-3 * outside) {
      ++n_outside;
      EXPECT_EQ(m.meshed.on_part.face[f].on, On::Face);
    }
  }
  EXPECT_EQ(n_inside, 2);
  EXPECT_EQ(n_outside, 2);
  // the split conserves each input face's area
  std::map<int, double> area;
  for (int f = 0; f < m.meshed.topo.num_faces(); ++f) area[m.meshed.face_origin[f]] += m.meshed.topo.face_area[f];
  for (auto [f, a] : area) EXPECT_NEAR(a, m.nondesign.face_area[f], 1e-6 * a) << "input Face" << f + 1;
}

TEST(Imprint, TheReportNamesEachSplitFaceAndWhereItsPiecesLie) {
  const auto fx = testing::plate_with_bosses_on_one_side();
  const TwoBReps m = load_two_breps(fx.part, fx.nondesign);
  const nlohmann::json r = two_breps_report(m)["imprint"];
  ASSERT_EQ(r.size(), 2u);  // each boss's outer cylinder
  for (const auto& face : r) {
    ASSERT_EQ(face["pieces"].size(), 2u);
    std::multiset<std::string> on;
    for (const auto& p : face["pieces"]) on.insert(p["on"].get<std::string>());
    EXPECT_EQ(on, (std::multiset<std::string>{"face", "interior"})) << face.dump();
  }
  const std::string summary = two_breps_summary(m);
  EXPECT_NE(summary.find("reaches the part's boundary in part: split into"), std::string::npos) << summary;
  EXPECT_NE(summary.find("[inside]"), std::string::npos) << summary;
}

TEST(Imprint, TouchingPadsShareIdenticalFacesAfterTheImprint) {
  const auto fx = testing::pads_touching_on_unequal_faces();
  const TwoBReps m = load_two_breps(fx.part, fx.nondesign);
  ASSERT_TRUE(m.meshed.imprinted);
  ASSERT_EQ(m.meshed.relations.contacts.size(), 1u);
  const Contact& c = m.meshed.relations.contacts[0];
  ASSERT_EQ(c.faces.size(), 1u);  // pad A's 5 x 5 face and the same piece of pad B's face
  EXPECT_NEAR(m.meshed.topo.face_area[c.faces[0].first], 25.0, 1e-6);
  EXPECT_NEAR(m.meshed.topo.face_area[c.faces[0].second], 25.0, 1e-6);
}

TEST(Imprint, ModelsWithoutPartialContactAreKeptAsTheyAre) {
  for (const char* name : {"rocker", "cantilever", "bracket"}) {
    SCOPED_TRACE(name);
    const std::string dir = std::string(TOPOPT_SHARED_DATA) + "/examples/";
    const TwoBReps m =
        load_two_breps(read_shape_file(dir + name + ".step"), read_shape_file(dir + name + "_nondesign.step"));
    EXPECT_FALSE(m.meshed.imprinted);
    EXPECT_TRUE(m.meshed.topo.shape.IsSame(m.nondesign.shape));
    EXPECT_EQ(m.meshed.relations.contacts.size(), m.relations.contacts.size());
  }
}

TEST(Imprint, PastItsBudgetTheImprintStopsWithATimeoutNamingTheStage) {
  const auto fx = testing::plate_with_bosses_on_one_side();
  ClassifyParams params;
  params.imprint_seconds = 1e-6;  // spent before OCCT's first check
  try {
    load_two_breps(fx.part, fx.nondesign, params);
    FAIL() << "the imprint ran past its budget without stopping";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Timeout) << e.what();
    EXPECT_NE(std::string(e.what()).find("imprinting the part's boundary"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--mesher gmsh"), std::string::npos) << e.what();
  }
  params.imprint_seconds = 120;  // the default: the same fixture imprints
  EXPECT_TRUE(load_two_breps(fx.part, fx.nondesign, params).meshed.imprinted);
}

TEST(Imprint, ACancelStopsTheImprint) {
  const auto fx = testing::plate_with_bosses_on_one_side();
  const TwoBReps m = load_two_breps(fx.part, fx.nondesign);
  Progress cancel;
  cancel.cancelled = [] { return true; };
  try {
    meshed_nondesign(m.part, m.nondesign, m.nd_on_part, m.relations, {}, cancel);
    FAIL() << "a cancel did not stop the imprint";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Cancelled) << e.what();
  }
}

}  // namespace
}  // namespace topopt::brep
