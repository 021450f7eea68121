#include "partial_contact_fixtures.h"

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRep_Builder.hxx>
#include <GeomAPI_Interpolate.hxx>
#include <Geom_BSplineCurve.hxx>
#include <ShapeUpgrade_UnifySameDomain.hxx>
#include <TColgp_HArray1OfPnt.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <cmath>
#include <gp_Ax2.hxx>
#include <stdexcept>

namespace topopt::testing {
namespace {

TopoDS_Shape cylinder(double x, double y, double z, double r, double h, gp_Dir axis = gp::DZ()) {
  return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, y, z), axis), r, h).Shape();
}

TopoDS_Shape box(double x0, double y0, double z0, double x1, double y1, double z1) {
  return BRepPrimAPI_MakeBox(gp_Pnt(x0, y0, z0), gp_Pnt(x1, y1, z1)).Shape();
}

/// The first solid of a boolean's result (the fixtures' booleans make exactly one).
TopoDS_Shape solid_of(const TopoDS_Shape& shape) {
  TopExp_Explorer it(shape, TopAbs_SOLID);
  if (!it.More()) throw std::runtime_error("fixture boolean made no solid");
  return it.Current();
}

TopoDS_Shape fuse(const TopoDS_Shape& a, const TopoDS_Shape& b, bool unify = true) {
  BRepAlgoAPI_Fuse f(a, b);
  if (!unify) return solid_of(f.Shape());
  ShapeUpgrade_UnifySameDomain u(f.Shape());
  u.Build();
  return solid_of(u.Shape());
}

TopoDS_Shape cut(const TopoDS_Shape& a, const TopoDS_Shape& b) { return solid_of(BRepAlgoAPI_Cut(a, b).Shape()); }

TopoDS_Shape compound(const std::vector<TopoDS_Shape>& solids) {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  for (const auto& s : solids) b.Add(c, s);
  return c;
}

}  // namespace

PartialContactFixture plate_with_bosses_on_one_side() {
  TopoDS_Shape part = box(0, 0, 0, 60, 40, 8);
  std::vector<TopoDS_Shape> bosses;
  for (double x : {15.0, 45.0}) {
    part = fuse(part, cylinder(x, 20, 0, 6, 14));
    bosses.push_back(cut(cylinder(x, 20, 0, 6, 14), cylinder(x, 20, 0, 3, 14)));
  }
  for (double x : {15.0, 45.0}) part = cut(part, cylinder(x, 20, 0, 3, 14));
  return {"plate with bosses on one side", part, compound(bosses)};
}

PartialContactFixture bracket_with_lug_cut_by_outer_face() {
  TopoDS_Shape part = cut(fuse(box(0, 0, 0, 60, 40, 8), cylinder(60, 20, 0, 10, 8)), cylinder(60, 20, 0, 5, 8));
  TopoDS_Shape lug = cut(cylinder(60, 20, 0, 10, 8), cylinder(60, 20, 0, 5, 8));
  return {"bracket with a lug cut by its outer face", part, compound({lug})};
}

PartialContactFixture boss_on_cylinder_wall() {
  TopoDS_Shape part = fuse(cylinder(0, 0, 0, 20, 30), cylinder(0, 0, 15, 5, 30, gp::DX()));
  return {"boss half outside a cylinder face", part, compound({cylinder(12, 0, 15, 5, 18, gp::DX())})};
}

PartialContactFixture boss_on_bspline_wall() {
  Handle(TColgp_HArray1OfPnt) points = new TColgp_HArray1OfPnt(1, 13);
  for (int i = 0; i < 13; ++i) points->SetValue(i + 1, gp_Pnt(5.0 * i, 0, 10 + 4 * std::sin(M_PI * i / 12)));
  GeomAPI_Interpolate fit(points, false, 1e-9);
  fit.Perform();
  const Handle(Geom_BSplineCurve) arch = fit.Curve();
  const gp_Pnt a = arch->StartPoint(), b = arch->EndPoint();
  BRepBuilderAPI_MakeWire wire;
  wire.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(0, 0, 0), gp_Pnt(60, 0, 0)).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(gp_Pnt(60, 0, 0), b).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(arch).Edge());
  wire.Add(BRepBuilderAPI_MakeEdge(a, gp_Pnt(0, 0, 0)).Edge());
  const TopoDS_Face profile = BRepBuilderAPI_MakeFace(wire.Wire(), true).Face();
  const TopoDS_Shape block =
      BRepBuilderAPI_NurbsConvert(BRepPrimAPI_MakePrism(profile, gp_Vec(0, 40, 0)).Shape()).Shape();
  const TopoDS_Shape part = fuse(block, cylinder(30, 20, 0, 5, 20), false);
  return {"boss on a B-spline wall", part, compound({cylinder(30, 20, 0, 5, 20)})};
}

PartialContactFixture pad_spanning_two_faces() {
  TopoDS_Shape part = fuse(box(0, 0, 0, 20, 30, 20), box(20, 0, 0, 40, 30, 20), false);
  return {"pad spanning two faces", part, compound({box(15, 10, 15, 25, 20, 20)})};
}

PartialContactFixture pads_touching_on_unequal_faces() {
  return {"pads touching on unequal faces", box(0, 0, 0, 40, 30, 20),
          compound({box(10, 10, 0, 20, 15, 5), box(20, 5, 0, 30, 25, 8)})};
}

std::vector<PartialContactFixture> partial_contact_fixtures() {
  return {plate_with_bosses_on_one_side(), bracket_with_lug_cut_by_outer_face(), boss_on_cylinder_wall(),
          pad_spanning_two_faces(),        pads_touching_on_unequal_faces(),     boss_on_bspline_wall()};
}

}  // namespace topopt::testing
