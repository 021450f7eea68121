#include "brep/point_locator.h"

#include <BRepBndLib.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Geom_Surface.hxx>
#include <ShapeAnalysis_Curve.hxx>
#include <TopoDS.hxx>
#include <gp_Pnt2d.hxx>

namespace topopt::brep {

PointLocator::PointLocator(const TopologyIndex& model, double tol) : m_(model), tol_(tol) {
  edge_box_.resize(m_.num_edges());
  for (int i = 0; i < m_.num_edges(); ++i) {
    BRepBndLib::Add(m_.edges(i + 1), edge_box_[i], false);
    edge_box_[i].Enlarge(tol_ + m_.edge_tolerance[i]);
  }
  face_box_.resize(m_.num_faces());
  for (int i = 0; i < m_.num_faces(); ++i) {
    BRepBndLib::Add(m_.faces(i + 1), face_box_[i], false);
    face_box_[i].Enlarge(tol_ + m_.face_tolerance[i]);
  }
}

std::vector<Hit> PointLocator::vertices_at(const gp_Pnt& p, double extra_tol) const {
  std::vector<Hit> hits;
  for (int i = 0; i < m_.num_vertices(); ++i) {
    gp_Pnt q(m_.vertex_point(i, 0), m_.vertex_point(i, 1), m_.vertex_point(i, 2));
    double d = p.Distance(q);
    if (d <= tol_ + extra_tol + m_.vertex_tolerance[i]) hits.push_back({i, 0, 0, d});
  }
  return hits;
}

std::vector<Hit> PointLocator::edges_at(const gp_Pnt& p, double extra_tol) const {
  std::vector<Hit> hits;
  for (int i = 0; i < m_.num_edges(); ++i) {
    if (m_.edge_degenerate[i] || edge_box_[i].IsOut(p)) continue;
    const TopoDS_Edge& e = TopoDS::Edge(m_.edges(i + 1));
    double first, last;
    Handle(Geom_Curve) curve = BRep_Tool::Curve(e, first, last);
    if (curve.IsNull()) continue;
    gp_Pnt proj;
    double param;
    ShapeAnalysis_Curve sac;
    double d = sac.Project(curve, p, tol_, proj, param, first, last, false);
    if (d <= tol_ + extra_tol + m_.edge_tolerance[i]) hits.push_back({i, param, 0, d});
  }
  return hits;
}

std::vector<Hit> PointLocator::faces_at(const gp_Pnt& p, double extra_tol) const {
  std::vector<Hit> hits;
  for (int i = 0; i < m_.num_faces(); ++i) {
    if (face_box_[i].IsOut(p)) continue;
    const TopoDS_Face& f = TopoDS::Face(m_.faces(i + 1));
    Handle(Geom_Surface) surface = BRep_Tool::Surface(f);
    if (surface.IsNull()) continue;
    double u0, u1, v0, v1;
    BRepTools::UVBounds(f, u0, u1, v0, v1);
    GeomAPI_ProjectPointOnSurf proj(p, surface, u0, u1, v0, v1);
    if (proj.NbPoints() == 0) continue;
    const double allowed = tol_ + extra_tol + m_.face_tolerance[i];
    double d = proj.LowerDistance();
    if (d > allowed) continue;
    double u, v;
    proj.LowerDistanceParameters(u, v);
    BRepClass_FaceClassifier inside(f, gp_Pnt2d(u, v), allowed);
    TopAbs_State state = inside.State();
    if (state == TopAbs_IN || state == TopAbs_ON) hits.push_back({i, u, v, d});
  }
  return hits;
}

}  // namespace topopt::brep
