#include "brep/topology_index.h"

#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <cmath>

namespace topopt::brep {

std::string surface_type_name(const TopoDS_Shape& face) {
  BRepAdaptor_Surface surface(TopoDS::Face(face), false);
  switch (surface.GetType()) {
    case GeomAbs_Plane:
      return "Plane";
    case GeomAbs_Cylinder:
      return "Cylinder";
    case GeomAbs_Cone:
      return "Cone";
    case GeomAbs_Sphere:
      return "Sphere";
    case GeomAbs_Torus:
      return "Torus";
    case GeomAbs_BezierSurface:
      return "Bezier";
    case GeomAbs_BSplineSurface:
      return "BSpline";
    case GeomAbs_SurfaceOfRevolution:
      return "Revolution";
    case GeomAbs_SurfaceOfExtrusion:
      return "Extrusion";
    case GeomAbs_OffsetSurface:
      return "Offset";
    default:
      return "Other";
  }
}

double TopologyIndex::diagonal() const {
  double s = 0;
  for (int k = 0; k < 3; ++k) s += (bbox_max[k] - bbox_min[k]) * (bbox_max[k] - bbox_min[k]);
  return std::sqrt(s);
}

namespace {

/// Indices (0-based) in `map` of the sub-shapes of `shape` of type `type`, in explorer order.
std::vector<int> sub_indices(const TopoDS_Shape& shape, TopAbs_ShapeEnum type, const TopTools_IndexedMapOfShape& map) {
  std::vector<int> out;
  for (TopExp_Explorer ex(shape, type); ex.More(); ex.Next()) out.push_back(map.FindIndex(ex.Current()) - 1);
  return out;
}

}  // namespace

TopologyIndex index_topology(const TopoDS_Shape& shape) {
  TopologyIndex t;
  t.shape = shape;
  TopExp::MapShapes(shape, TopAbs_VERTEX, t.vertices);
  TopExp::MapShapes(shape, TopAbs_EDGE, t.edges);
  TopExp::MapShapes(shape, TopAbs_FACE, t.faces);
  TopExp::MapShapes(shape, TopAbs_SHELL, t.shells);
  TopExp::MapShapes(shape, TopAbs_SOLID, t.solids);

  const int nv = t.num_vertices(), ne = t.num_edges(), nf = t.num_faces(), ns = t.num_solids();
  t.vertex_point.resize(nv, 3);
  t.vertex_tolerance.resize(nv);
  for (int i = 0; i < nv; ++i) {
    const TopoDS_Vertex& v = TopoDS::Vertex(t.vertices(i + 1));
    gp_Pnt p = BRep_Tool::Pnt(v);
    t.vertex_point.row(i) << p.X(), p.Y(), p.Z();
    t.vertex_tolerance[i] = BRep_Tool::Tolerance(v);
  }

  t.edge_vertices.resize(ne, 2);
  t.edge_degenerate.resize(ne);
  t.edge_length.resize(ne);
  t.edge_tolerance.resize(ne);
  for (int i = 0; i < ne; ++i) {
    const TopoDS_Edge& e = TopoDS::Edge(t.edges(i + 1));
    TopoDS_Vertex a, b;
    TopExp::Vertices(e, a, b);
    t.edge_vertices(i, 0) = a.IsNull() ? -1 : t.vertices.FindIndex(a) - 1;
    t.edge_vertices(i, 1) = b.IsNull() ? -1 : t.vertices.FindIndex(b) - 1;
    t.edge_degenerate[i] = BRep_Tool::Degenerated(e);
    GProp_GProps props;
    BRepGProp::LinearProperties(e, props);
    t.edge_length[i] = props.Mass();
    t.edge_tolerance[i] = BRep_Tool::Tolerance(e);
  }

  t.face_area.resize(nf);
  t.face_centre.resize(nf, 3);
  t.face_surface.resize(nf);
  t.face_tolerance.resize(nf);
  for (int i = 0; i < nf; ++i) {
    const TopoDS_Face& f = TopoDS::Face(t.faces(i + 1));
    std::vector<int> edges, wire_sizes;
    for (TopExp_Explorer wex(f, TopAbs_WIRE); wex.More(); wex.Next()) {
      int count = 0;
      for (TopExp_Explorer eex(wex.Current(), TopAbs_EDGE); eex.More(); eex.Next(), ++count)
        edges.push_back(t.edges.FindIndex(eex.Current()) - 1);
      wire_sizes.push_back(count);
    }
    t.face_edges.push_row(edges);
    t.face_wires.push_row(wire_sizes);
    GProp_GProps props;
    BRepGProp::SurfaceProperties(f, props);
    t.face_area[i] = props.Mass();
    gp_Pnt c = props.CentreOfMass();
    t.face_centre.row(i) << c.X(), c.Y(), c.Z();
    t.face_surface[i] = surface_type_name(f);
    t.face_tolerance[i] = BRep_Tool::Tolerance(f);
  }

  for (int i = 0; i < t.num_shells(); ++i) t.shell_faces.push_row(sub_indices(t.shells(i + 1), TopAbs_FACE, t.faces));

  t.face_solid = VecXi::Constant(nf, -1);
  t.solid_volume.resize(ns);
  for (int i = 0; i < ns; ++i) {
    const TopoDS_Shape& s = t.solids(i + 1);
    t.solid_shells.push_row(sub_indices(s, TopAbs_SHELL, t.shells));
    std::vector<int> faces = sub_indices(s, TopAbs_FACE, t.faces);
    for (int f : faces)
      if (t.face_solid[f] < 0) t.face_solid[f] = i;
    t.solid_faces.push_row(faces);
    GProp_GProps props;
    BRepGProp::VolumeProperties(s, props);
    t.solid_volume[i] = props.Mass();
  }

  Bnd_Box box;
  BRepBndLib::Add(shape, box, false);
  if (!box.IsVoid()) box.Get(t.bbox_min[0], t.bbox_min[1], t.bbox_min[2], t.bbox_max[0], t.bbox_max[1], t.bbox_max[2]);
  return t;
}

}  // namespace topopt::brep
