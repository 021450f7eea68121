// The input's curved faces back as analytic faces in the result's STEP: a fixture built in code
// (a plate with a through-bore, and a non-design tube — its own bore and boss — joined to it by
// a bar), triangulated as a result surface would be and tagged as iso_surface.h tags: the bores
// and the tube's boss come back as cylinders of the input's radius and axis, one valid solid of
// the surface's volume, and so does the STEP file OCCT reads back; a countersunk bore (a cone)
// and a rounded boss (a torus) come back as a cone and a torus.
#include "result/step_export_analytic.h"

#include <gtest/gtest.h>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepGProp.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCone.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <Geom_ConicalSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <Poly_Triangulation.hxx>
#include <STEPControl_Reader.hxx>
#include <ShapeUpgrade_UnifySameDomain.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <array>
#include <filesystem>
#include <gp_Lin.hxx>
#include <map>

#include "result/step_export.h"

namespace topopt::result {
namespace {

TopoDS_Shape cylinder(double x, double y, double r, double h) {
  return BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(x, y, 0), gp::DZ()), r, h).Shape();
}

/// The fixture: Ω a 60x30x10 plate with a bore of radius 5 at (12, 15) and one of radius 4 at
/// (45, 15); the non-design solid a tube around the second bore (radius 4 to 8); the result the
/// plate's left part (x < 35, with its bore), a bar from it into the tube, and the tube whole.
struct Fixture {
  TopoDS_Shape part, nondesign, result;
};

Fixture fixture() {
  Fixture f;
  const TopoDS_Shape plate = BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), gp_Pnt(60, 30, 10)).Shape();
  f.part = BRepAlgoAPI_Cut(BRepAlgoAPI_Cut(plate, cylinder(12, 15, 5, 10)).Shape(), cylinder(45, 15, 4, 10)).Shape();
  f.nondesign = BRepAlgoAPI_Cut(cylinder(45, 15, 8, 10), cylinder(45, 15, 4, 10)).Shape();
  const TopoDS_Shape left =
      BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), gp_Pnt(35, 30, 10)).Shape(), cylinder(12, 15, 5, 10))
          .Shape();
  const TopoDS_Shape bar = BRepPrimAPI_MakeBox(gp_Pnt(30, 12, 0), gp_Pnt(39, 18, 10)).Shape();
  ShapeUpgrade_UnifySameDomain unify(BRepAlgoAPI_Fuse(BRepAlgoAPI_Fuse(left, bar).Shape(), f.nondesign).Shape());
  unify.Build();
  f.result = unify.Shape();
  return f;
}

/// 1-based index of the face of `shape` within 1e-6 of point p, or 0.
int face_at(const TopoDS_Shape& shape, const gp_Pnt& p) {
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  for (int i = 1; i <= faces.Extent(); ++i) {
    BRepExtrema_DistShapeShape d(BRepBuilderAPI_MakeVertex(p).Vertex(), faces(i));
    if (d.IsDone() && d.Value() < 1e-6) return i;
  }
  return 0;
}

/// The fixture's result triangulated (OCCT's mesher, points merged where faces share them) and
/// tagged as the iso-surface is: Ω's face number where the triangle lies on Ω's boundary, -1 on
/// the non-design tube, 0 elsewhere (the bar's sides: free-form). Every point locked.
TriSurface tagged_surface(const Fixture& f) {
  BRepMesh_IncrementalMesh(f.result, 0.2, false, 0.25);
  std::map<std::array<double, 3>, int> index;
  std::vector<std::array<double, 3>> points;
  std::vector<std::array<int, 4>> tris;  // a, b, c, tag
  for (TopExp_Explorer e(f.result, TopAbs_FACE); e.More(); e.Next()) {
    const TopoDS_Face face = TopoDS::Face(e.Current());
    TopLoc_Location loc;
    const Handle(Poly_Triangulation) t = BRep_Tool::Triangulation(face, loc);
    std::vector<int> id(t->NbNodes() + 1);
    for (int i = 1; i <= t->NbNodes(); ++i) {
      const gp_Pnt p = t->Node(i).Transformed(loc.Transformation());
      const auto it = index.emplace(std::array<double, 3>{p.X(), p.Y(), p.Z()}, static_cast<int>(points.size()));
      if (it.second) points.push_back(it.first->first);
      id[i] = it.first->second;
    }
    int tag = -2;  // found at the first triangle
    for (int k = 1; k <= t->NbTriangles(); ++k) {
      int a, b, c;
      t->Triangle(k).Get(a, b, c);
      if (face.Orientation() == TopAbs_REVERSED) std::swap(b, c);
      if (tag == -2) {  // the face's point at the triangle's centre in (u, v): on the face exactly
        const gp_XY uv = (t->UVNode(a).XY() + t->UVNode(b).XY() + t->UVNode(c).XY()) / 3;
        const gp_Pnt p = BRep_Tool::Surface(face)->Value(uv.X(), uv.Y());
        const int on_part = face_at(f.part, p);
        tag = on_part > 0 ? on_part : face_at(f.nondesign, p) > 0 ? -1 : 0;
      }
      tris.push_back({id[a], id[b], id[c], tag});
    }
  }
  TriSurface s;
  s.V.resize(static_cast<long>(points.size()), 3);
  for (size_t i = 0; i < points.size(); ++i) s.V.row(static_cast<long>(i)) << points[i][0], points[i][1], points[i][2];
  s.F.resize(static_cast<long>(tris.size()), 3);
  s.tag.resize(static_cast<long>(tris.size()));
  for (size_t q = 0; q < tris.size(); ++q) {
    s.F.row(static_cast<long>(q)) << tris[q][0], tris[q][1], tris[q][2];
    s.tag[static_cast<long>(q)] = tris[q][3];
  }
  s.lock = VecXi::Constant(s.V.rows(), 1);
  s.point_face = VecXi::Zero(s.V.rows());
  return s;
}

/// The cylindrical faces of `shape` of radius r (within 1e-6) whose axis is the line through
/// (x, y) along z (within 1e-6).
int cylinders(const TopoDS_Shape& shape, double x, double y, double r) {
  int n = 0;
  for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next()) {
    const auto c = Handle(Geom_CylindricalSurface)::DownCast(BRep_Tool::Surface(TopoDS::Face(e.Current())));
    if (c.IsNull()) continue;
    const gp_Ax1 axis = c->Axis();
    const gp_Lin line(axis);
    if (std::abs(c->Radius() - r) < 1e-6 && axis.Direction().IsParallel(gp::DZ(), 1e-9) &&
        line.Distance(gp_Pnt(x, y, 0)) < 1e-6)
      ++n;
  }
  return n;
}

double volume(const TopoDS_Shape& shape) {
  GProp_GProps props;
  BRepGProp::VolumeProperties(shape, props);
  return props.Mass();
}

const StepExportParams kNoCoarsening{.coarsen = {.tolerance = 0}};

/// Faces of `shape` whose surface is of kind T.
template <class T>
int faces_on(const TopoDS_Shape& shape) {
  int n = 0;
  for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next())
    n += !Handle(T)::DownCast(BRep_Tool::Surface(TopoDS::Face(e.Current()))).IsNull();
  return n;
}

/// A 30x30x10 plate with a boss of radius 6 on top, up to z = 16, whose top edge is rounded
/// (radius 2: a torus) and a countersunk bore through both (a cone from radius 4 down to 2,
/// then a cylinder of radius 2): the whole part is the result, its faces Ω's.
Fixture countersunk_boss() {
  Fixture f;
  // the rounded boss: a cylinder of radius 6 to z = 14, one of radius 4 to z = 16 and the torus
  // (radii 4 and 2, centred at z = 14) between them
  const TopoDS_Shape torus = BRepPrimAPI_MakeTorus(gp_Ax2(gp_Pnt(15, 15, 14), gp::DZ()), 4, 2).Shape();
  const TopoDS_Shape boss =
      BRepAlgoAPI_Fuse(BRepAlgoAPI_Fuse(cylinder(15, 15, 6, 14), cylinder(15, 15, 4, 16)).Shape(), torus).Shape();
  const TopoDS_Shape body =
      BRepAlgoAPI_Fuse(BRepPrimAPI_MakeBox(gp_Pnt(0, 0, 0), gp_Pnt(30, 30, 10)).Shape(), boss).Shape();
  const TopoDS_Shape sink = BRepPrimAPI_MakeCone(gp_Ax2(gp_Pnt(15, 15, 14), gp::DZ()), 2, 4, 2).Shape();
  ShapeUpgrade_UnifySameDomain unify(
      BRepAlgoAPI_Cut(BRepAlgoAPI_Cut(body, sink).Shape(), cylinder(15, 15, 2, 16)).Shape());
  unify.Build();
  f.part = f.result = unify.Shape();
  return f;
}

/// The solid of `s` with the curved faces of `part` and `nondesign` as analytic faces, checked
/// on the way: valid, one solid, no curved piece refused. `r`: what describe_solid says of it.
TopoDS_Shape analytic_solid(const TriSurface& s, const TopoDS_Shape& part, const TopoDS_Shape& nondesign,
                            StepExportReport& r) {
  const SourceFaces source(part, nondesign);
  int refused = -1;
  const TopoDS_Shape solid = result_solid(s, kNoCoarsening, nullptr, &source, &refused);
  r = describe_solid(solid);
  EXPECT_TRUE(r.valid) << solid_faults(solid);
  EXPECT_EQ(r.solids, 1);
  EXPECT_EQ(refused, 0);
  return solid;
}

TEST(StepExportAnalytic, TrianglesOnCurvedInputFacesAreFoundByTagAndPlace) {
  const Fixture f = fixture();
  const TriSurface s = tagged_surface(f);
  const SourceFaces source(f.part, f.nondesign);
  // Ω: its two bores; the tube: its outer and inner cylinders
  ASSERT_EQ(source.size(), 4);
  const std::vector<int> on = source.classify(s);
  long on_bore = 0, on_boss = 0, planar_on_curved = 0;
  for (long q = 0; q < s.F.rows(); ++q) {
    const Eigen::Vector3d c = (s.V.row(s.F(q, 0)) + s.V.row(s.F(q, 1)) + s.V.row(s.F(q, 2))) / 3;
    const double r5 = std::hypot(c.x() - 12, c.y() - 15), r8 = std::hypot(c.x() - 45, c.y() - 15);
    const Eigen::Vector3d n =
        (s.V.row(s.F(q, 1)) - s.V.row(s.F(q, 0))).cross(s.V.row(s.F(q, 2)) - s.V.row(s.F(q, 0))).normalized();
    if (std::abs(n.z()) > 0.9) planar_on_curved += on[q] >= 0;  // the plate's top and bottom
    if (std::abs(n.z()) < 0.1 && r5 < 5.01) on_bore += on[q] >= 0 && s.tag[q] > 0;
    if (std::abs(n.z()) < 0.1 && r8 > 7.9 && r8 < 8.01) on_boss += on[q] >= 0 && s.tag[q] == -1;
  }
  EXPECT_EQ(planar_on_curved, 0);
  EXPECT_GT(on_bore, 20);
  EXPECT_GT(on_boss, 20);
}

TEST(StepExportAnalytic, BoresAndBossAreCylindersOfTheInputInOneValidSolid) {
  const Fixture f = fixture();
  const TriSurface s = tagged_surface(f);
  StepExportReport r;
  const TopoDS_Shape solid = analytic_solid(s, f.part, f.nondesign, r);
  // the plate's bore and the tube's bore (full turns, built as two halves each) and the tube's boss
  // (what the bar leaves of it): cylinders of the input's radius and axis
  EXPECT_GE(cylinders(solid, 12, 15, 5), 1);
  EXPECT_GE(cylinders(solid, 45, 15, 4), 1);
  EXPECT_GE(cylinders(solid, 45, 15, 8), 1);
  EXPECT_EQ(r.analytic_faces, cylinders(solid, 12, 15, 5) + cylinders(solid, 45, 15, 4) + cylinders(solid, 45, 15, 8));
  // the halves of each full bore are merged back into one face by the export's
  // UnifySameDomain (a face with a seam): one face per cylinder
  EXPECT_EQ(r.analytic_faces, 3);
  RecordProperty("faces", r.faces);
  RecordProperty("analytic_faces", r.analytic_faces);
  RecordProperty("triangles", static_cast<int>(s.F.rows()));
  // everything else planar; the surface's volume (its chords cut the cylinders: within 0.5 %)
  EXPECT_EQ(r.faces, r.planar_faces + r.analytic_faces);
  EXPECT_LT(r.faces, 40);
  const double stl = check_surface(s.V, s.F).volume, exact = volume(f.result);
  EXPECT_NEAR(r.volume, stl, 0.005 * stl);
  EXPECT_NEAR(r.volume, exact, 0.005 * exact);
  // without the input's faces the cylinders are facets
  const StepExportReport facets = describe_solid(result_solid(s, kNoCoarsening));
  EXPECT_EQ(facets.analytic_faces, 0);
  EXPECT_GT(facets.faces, 5 * r.faces);
}

TEST(StepExportAnalytic, StepReadBackHasTheCylindersValidWithTheVolume) {
  const Fixture f = fixture();
  const TriSurface s = tagged_surface(f);
  const SourceFaces source(f.part, f.nondesign);
  const std::string path = (std::filesystem::temp_directory_path() / "topopt_step_analytic.step").string();
  const StepExportReport written = write_result_step(path, s, kNoCoarsening, {}, &source);
  EXPECT_TRUE(written.valid);
  EXPECT_EQ(written.analytic_refused, 0);
  STEPControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  const TopoDS_Shape back = reader.OneShape();
  const StepExportReport r = describe_solid(back);
  RecordProperty("bytes", static_cast<int>(written.bytes));
  EXPECT_TRUE(r.valid) << solid_faults(back);
  EXPECT_EQ(r.solids, 1);
  EXPECT_EQ(r.faces, written.faces);
  EXPECT_EQ(r.analytic_faces, written.analytic_faces);
  EXPECT_GE(cylinders(back, 12, 15, 5), 1);
  EXPECT_GE(cylinders(back, 45, 15, 4), 1);
  EXPECT_GE(cylinders(back, 45, 15, 8), 1);
  const double stl = check_surface(s.V, s.F).volume;
  EXPECT_NEAR(r.volume, stl, 0.005 * stl);
  std::filesystem::remove(path);
}

TEST(StepExportAnalytic, ConesAndToriToo) {
  const Fixture f = countersunk_boss();
  ASSERT_EQ(faces_on<Geom_ToroidalSurface>(f.part), 1);
  ASSERT_EQ(faces_on<Geom_ConicalSurface>(f.part), 1);
  const TriSurface s = tagged_surface(f);
  StepExportReport r;
  const TopoDS_Shape solid = analytic_solid(s, f.part, {}, r);
  EXPECT_EQ(faces_on<Geom_ToroidalSurface>(solid), 1);
  EXPECT_EQ(faces_on<Geom_ConicalSurface>(solid), 1);
  EXPECT_EQ(cylinders(solid, 15, 15, 2), 1);
  EXPECT_EQ(cylinders(solid, 15, 15, 6), 1);
  EXPECT_EQ(r.faces, r.planar_faces + r.analytic_faces);
  const double stl = check_surface(s.V, s.F).volume, exact = volume(f.result);
  EXPECT_NEAR(r.volume, stl, 0.005 * stl);
  EXPECT_NEAR(r.volume, exact, 0.005 * exact);
}

}  // namespace
}  // namespace topopt::result
