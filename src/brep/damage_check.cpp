// Gross damage to a solid's geometry (see damage_check.h).
#include "brep/damage_check.h"

#include <BRep_CurveRepresentation.hxx>
#include <BRep_GCurve.hxx>
#include <BRep_ListIteratorOfListOfCurveRepresentation.hxx>
#include <BRep_TEdge.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_Curve.hxx>
#include <Geom_Plane.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_Surface.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <algorithm>
#include <cmath>
#include <gp_Pln.hxx>

#include "common/error.h"
#include "common/number_text.h"

namespace topopt::brep {
namespace {

constexpr int kSamples = 5;

bool finite(const gp_Pnt& p) { return std::isfinite(p.X()) && std::isfinite(p.Y()) && std::isfinite(p.Z()); }

/// What a check found wrong, with the label and the advice around it.
struct Damage {
  const std::string& label;
  const std::string& advice;
  [[noreturn]] void operator()(const std::string& what) const {
    throw Error(ErrorCode::InvalidShape, label + " is damaged: " + what + "; " + advice);
  }
};

/// The diagonal of the vertices' box (the size gross deviations are measured against).
double vertex_box_size(const TopoDS_Shape& solid, const Damage& damaged) {
  TopTools_IndexedMapOfShape vertices;
  TopExp::MapShapes(solid, TopAbs_VERTEX, vertices);
  Bnd_Box box;
  for (int v = 1; v <= vertices.Extent(); ++v) {
    const gp_Pnt p = BRep_Tool::Pnt(TopoDS::Vertex(vertices(v)));
    if (!finite(p)) damaged("Vertex" + std::to_string(v) + " has coordinates that are not finite numbers");
    box.Add(p);
  }
  return box.IsVoid() ? 0.0 : std::sqrt(box.SquareExtent());
}

/// The stored curve of `edge` on the face's surface `s` at location `loc`, with its range;
/// null when none is stored (planes may have none).
Handle(Geom2d_Curve) stored_pcurve(const TopoDS_Edge& edge, const Handle(Geom_Surface) & s, const TopLoc_Location& loc,
                                   double& first, double& last) {
  const Handle(BRep_TEdge) te = Handle(BRep_TEdge)::DownCast(edge.TShape());
  const TopLoc_Location relative = loc.Predivided(edge.Location());
  for (BRep_ListIteratorOfListOfCurveRepresentation it(te->Curves()); it.More(); it.Next()) {
    const Handle(BRep_CurveRepresentation)& cr = it.Value();
    const Handle(BRep_GCurve) gc = Handle(BRep_GCurve)::DownCast(cr);
    if (gc.IsNull() || !cr->IsCurveOnSurface(s, relative) || cr->PCurve().IsNull()) continue;
    gc->Range(first, last);
    return cr->PCurve();
  }
  return Handle(Geom2d_Curve)();
}

/// The plane of a planar surface (through trims), else null.
Handle(Geom_Plane) plane_of(const Handle(Geom_Surface) & s) {
  Handle(Geom_Surface) basis = s;
  while (basis->IsKind(STANDARD_TYPE(Geom_RectangularTrimmedSurface)))
    basis = Handle(Geom_RectangularTrimmedSurface)::DownCast(basis)->BasisSurface();
  return Handle(Geom_Plane)::DownCast(basis);
}

/// The largest distance between the edge's 3D curve and the face at the samples: through the
/// stored curve on the face (same-parameter edges), or, on a plane that has none (OCCT
/// stores none there and would project), the distance to the plane. Negative: not checked.
double edge_face_distance(const TopoDS_Edge& edge, const Handle(Geom_Curve) & c, const TopLoc_Location& cloc, double c0,
                          double c1, const Handle(Geom_Surface) & s, const TopLoc_Location& sloc) {
  double p0 = 0, p1 = 0, worst = -1;
  const Handle(Geom2d_Curve) pc = stored_pcurve(edge, s, sloc, p0, p1);
  const Handle(Geom_Plane) plane = pc.IsNull() ? plane_of(s) : Handle(Geom_Plane)();
  if (pc.IsNull() ? plane.IsNull() : !BRep_Tool::SameParameter(edge)) return worst;
  if (!pc.IsNull() && (!std::isfinite(p0) || !std::isfinite(p1))) return HUGE_VAL;
  const gp_Pln pln = plane.IsNull() ? gp_Pln() : plane->Pln().Transformed(sloc.Transformation());
  for (int k = 0; k < kSamples; ++k) {
    const double a = static_cast<double>(k) / (kSamples - 1);
    const gp_Pnt on_curve = c->Value(c0 + a * (c1 - c0)).Transformed(cloc.Transformation());
    double d = 0;
    if (!pc.IsNull()) {
      const gp_Pnt2d uv = pc->Value(p0 + a * (p1 - p0));
      d = on_curve.Distance(s->Value(uv.X(), uv.Y()).Transformed(sloc.Transformation()));
    } else {
      d = pln.Distance(on_curve);
    }
    worst = std::isfinite(d) ? std::max(worst, d) : HUGE_VAL;
  }
  return worst;
}

/// Checks one edge of face `f` (FreeCAD numbers `e`, `f`) against the face's surface.
void check_edge_on_face(const TopoDS_Edge& edge, int e, const Handle(Geom_Surface) & s, const TopLoc_Location& sloc,
                        int f, double size, const Damage& damaged) {
  const std::string name = "Edge" + std::to_string(e);
  TopLoc_Location cloc;
  double c0 = 0, c1 = 0;
  const Handle(Geom_Curve) c = BRep_Tool::Curve(edge, cloc, c0, c1);
  if (c.IsNull()) damaged(name + " has no 3D curve");
  if (!std::isfinite(c0) || !std::isfinite(c1)) damaged(name + " has a parameter range that is not finite");
  const double allowed = std::max(1000 * BRep_Tool::Tolerance(edge), 0.01 * size);
  const double d = edge_face_distance(edge, c, cloc, c0, c1, s, sloc);
  if (!std::isfinite(d))
    damaged(name + " is not on Face" + std::to_string(f) + ", which it bounds (its distance is not a finite number)");
  if (d > allowed)
    damaged(name + " lies " + mm_text(d) + " away from Face" + std::to_string(f) +
            ", which it bounds (allowed: " + mm_text(allowed) + ")");
}

}  // namespace

void check_gross_damage(const TopoDS_Shape& solid, const std::string& label, const std::string& advice) {
  const Damage damaged{label, advice};
  const double size = vertex_box_size(solid, damaged);
  TopTools_IndexedMapOfShape faces, edges;
  TopExp::MapShapes(solid, TopAbs_FACE, faces);
  TopExp::MapShapes(solid, TopAbs_EDGE, edges);
  for (int f = 1; f <= faces.Extent(); ++f) {
    const TopoDS_Face& face = TopoDS::Face(faces(f));
    TopLoc_Location sloc;
    const Handle(Geom_Surface) s = BRep_Tool::Surface(face, sloc);
    if (s.IsNull()) damaged("Face" + std::to_string(f) + " has no surface");
    for (TopExp_Explorer ex(face, TopAbs_EDGE); ex.More(); ex.Next()) {
      const TopoDS_Edge& edge = TopoDS::Edge(ex.Current());
      if (!BRep_Tool::Degenerated(edge)) check_edge_on_face(edge, edges.FindIndex(edge), s, sloc, f, size, damaged);
    }
  }
}

}  // namespace topopt::brep
