// Gross damage found before OCCT's checker: an edge off its face, an edge without a curve, a
// plane turned askew (OCCT's checker spins forever on it), and sound parts left alone.
#include "brep/damage_check.h"

#include <gtest/gtest.h>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Geom_Plane.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>

#include <chrono>

#include "brep/shape_io.h"
#include "brep/two_breps.h"
#include "common/error.h"

using namespace topopt;
using namespace topopt::brep;

namespace {

const char* kAdvice = "repair it";

std::string message_of(const std::function<void()>& work, ErrorCode expected = ErrorCode::InvalidShape) {
  try {
    work();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), expected) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return "";
}

}  // namespace

TEST(DamageCheck, SoundPartsPass) {
  for (const char* name : {"examples/rocker.step", "examples/bracket_nondesign.step", "nist/NIST_MBE_PMI_1.stp",
                           "nist/NIST_MBE_PMI_5.stp", "occt/CrankArm.brep", "occt/linkrods.step"})
    EXPECT_NO_THROW(check_gross_damage(read_shape_file(std::string(TOPOPT_SHARED_DATA) + "/" + name), name, kAdvice))
        << name;
}

TEST(DamageCheck, FaceMovedOffItsEdgesIsNamed) {
  // a 10 mm box whose top face (z = 10) is given the plane z = 15: its four edges lie 5 mm
  // off it, far above the allowance (1 % of the box's 17.3 mm diagonal)
  TopoDS_Shape box = BRepPrimAPI_MakeBox(10, 10, 10).Shape();
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(box, TopAbs_FACE, faces);
  int top = 0;
  for (int f = 1; f <= faces.Extent(); ++f) {
    Handle(Geom_Plane) p = Handle(Geom_Plane)::DownCast(BRep_Tool::Surface(TopoDS::Face(faces(f))));
    if (!p.IsNull() && p->Location().Z() > 9.9) top = f;
  }
  ASSERT_GT(top, 0);
  BRep_Builder().UpdateFace(TopoDS::Face(faces(top)), new Geom_Plane(gp_Pnt(0, 0, 15), gp_Dir(0, 0, 1)),
                            TopLoc_Location(), 1e-7);
  const std::string m = message_of([&] { check_gross_damage(box, "the part", kAdvice); });
  EXPECT_NE(m.find("the part is damaged: Edge"), std::string::npos) << m;
  EXPECT_NE(
      m.find(" lies 5 mm away from Face" + std::to_string(top) + ", which it bounds (allowed: 0.173 mm); repair it"),
      std::string::npos)
      << m;
}

TEST(DamageCheck, EdgeWithoutCurveIsNamedBeforeOcctsCheckerCrashesOnIt) {
  const TopoDS_Shape part = read_shape_file(std::string(TOPOPT_TEST_DATA) + "/hostile/edge_without_curve.brep");
  EXPECT_EQ(message_of([&] { load_two_breps(part, TopoDS_Shape()); }),
            "the part is damaged: Edge16 has no 3D curve; repair it (Part > Check geometry in FreeCAD) or re-export it "
            "from your CAD system");
}

TEST(DamageCheck, PlaneTurnedAskewIsNamedAtOnceWhereOcctsCheckerSpins) {
  const TopoDS_Shape part = read_shape_file(std::string(TOPOPT_TEST_DATA) + "/hostile/plane_normal_damaged.brep");
  const auto t0 = std::chrono::steady_clock::now();
  const std::string m = message_of([&] { load_two_breps(part, TopoDS_Shape()); });
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_EQ(m.rfind("the part is damaged: Edge9 is not on Face8, which it bounds", 0), 0u) << m;
}
