#include "brep/classify.h"
#include "brep/point_locator.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAlgoAPI_Common.hxx>
#include <BRepBndLib.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <BRepGProp.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Geom_Surface.hxx>
#include <Poly_Triangulation.hxx>
#include <ShapeAnalysis_Curve.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS.hxx>
#include <algorithm>
#include <cmath>

#include "common/error.h"
#include "common/number_text.h"

namespace topopt::brep {

const char* on_name(On on) {
  switch (on) {
    case On::Interior:
      return "interior";
    case On::Vertex:
      return "vertex";
    case On::Edge:
      return "edge";
    case On::Face:
      return "face";
  }
  return "interior";
}

namespace {

std::vector<gp_Pnt> edge_samples(const TopoDS_Edge& edge, int n) {
  std::vector<gp_Pnt> out;
  if (BRep_Tool::Degenerated(edge)) return out;
  BRepAdaptor_Curve c(edge);
  for (int k = 1; k <= n; ++k)
    out.push_back(c.Value(c.FirstParameter() + (c.LastParameter() - c.FirstParameter()) * k / (n + 1)));
  return out;
}

/// Points inside a face: centroids (in the parameter plane) of the triangles of a coarse
/// triangulation, spread over the face. Triangles lie inside the trimmed domain, so their
/// centroids do too.
std::vector<gp_Pnt> face_samples(const TopoDS_Face& face, int n) {
  std::vector<gp_Pnt> out;
  TopLoc_Location loc;
  Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, loc);
  if (tri.IsNull() || tri->NbTriangles() == 0) return out;
  Handle(Geom_Surface) surface = BRep_Tool::Surface(face);
  const int nt = tri->NbTriangles();
  const int step = std::max(1, nt / std::max(1, n));
  for (int t = 1; t <= nt && static_cast<int>(out.size()) < n; t += step) {
    int a, b, c;
    tri->Triangle(t).Get(a, b, c);
    if (tri->HasUVNodes()) {
      gp_Pnt2d uv((tri->UVNode(a).XY() + tri->UVNode(b).XY() + tri->UVNode(c).XY()) / 3.0);
      out.push_back(surface->Value(uv.X(), uv.Y()));
    } else {
      gp_XYZ xyz = (tri->Node(a).XYZ() + tri->Node(b).XYZ() + tri->Node(c).XYZ()) / 3.0;
      out.push_back(gp_Pnt(xyz).Transformed(loc.Transformation()));
    }
  }
  return out;
}

/// Makes sure every face of the shape carries a triangulation to sample from.
void ensure_triangulated(const TopoDS_Shape& shape) {
  BRepMesh_IncrementalMesh mesher(shape, 0.05, true, 0.5, false);
  (void)mesher;
}

/// Intersection of hit sets: entities present in every sample's hits.
std::vector<int> common_indices(const std::vector<std::vector<Hit>>& per_sample) {
  if (per_sample.empty()) return {};
  std::vector<int> common;
  for (const Hit& h : per_sample[0]) common.push_back(h.index);
  for (size_t s = 1; s < per_sample.size(); ++s) {
    std::vector<int> keep;
    for (int c : common)
      for (const Hit& h : per_sample[s])
        if (h.index == c) {
          keep.push_back(c);
          break;
        }
    common.swap(keep);
  }
  return common;
}

double max_distance(const std::vector<std::vector<Hit>>& per_sample, int index) {
  double d = 0;
  for (const auto& hits : per_sample)
    for (const Hit& h : hits)
      if (h.index == index) d = std::max(d, h.distance);
  return d;
}

double volume_of(const TopoDS_Shape& s) {
  GProp_GProps props;
  BRepGProp::VolumeProperties(s, props);
  return props.Mass();
}

/// Volume of the intersection of a and b, or a negative number if the boolean failed.
double common_volume(const TopoDS_Shape& a, const TopoDS_Shape& b) {
  try {
    BRepAlgoAPI_Common common(a, b);
    if (!common.IsDone() || common.HasErrors()) return -1;
    return std::abs(volume_of(common.Shape()));
  } catch (const Standard_Failure&) {
    return -1;
  }
}

std::string fmt(double x) { return number_text(x, 4); }

}  // namespace

double coincidence_tolerance(const TopologyIndex& base, const ClassifyParams& params) {
  return params.tolerance > 0 ? params.tolerance : 1e-6 * std::max(base.diagonal(), 1.0);
}

Classification classify(const TopologyIndex& base, const TopologyIndex& other, const ClassifyParams& params) {
  const double tol = coincidence_tolerance(base, params);
  PointLocator probe(base, tol);
  ensure_triangulated(other.shape);
  Classification out;

  out.vertex.resize(other.num_vertices());
  for (int i = 0; i < other.num_vertices(); ++i) {
    gp_Pnt p(other.vertex_point(i, 0), other.vertex_point(i, 1), other.vertex_point(i, 2));
    const double extra = other.vertex_tolerance[i];
    Location& loc = out.vertex[i];
    if (auto v = probe.vertices_at(p, extra); !v.empty()) {
      loc = {On::Vertex, v[0].index, {0, 0}, v[0].distance};
    } else if (auto e = probe.edges_at(p, extra); !e.empty()) {
      loc = {On::Edge, e[0].index, {e[0].t0, 0}, e[0].distance};
    } else if (auto f = probe.faces_at(p, extra); !f.empty()) {
      loc = {On::Face, f[0].index, {f[0].t0, f[0].t1}, f[0].distance};
    }
  }

  out.edge.resize(other.num_edges());
  for (int i = 0; i < other.num_edges(); ++i) {
    const TopoDS_Edge& e = TopoDS::Edge(other.edges(i + 1));
    std::vector<gp_Pnt> samples = edge_samples(e, params.edge_samples);
    if (samples.empty()) continue;  // degenerate: its vertex says where it is
    const double extra = other.edge_tolerance[i];
    std::vector<std::vector<Hit>> on_edges, on_faces;
    for (const gp_Pnt& p : samples) on_edges.push_back(probe.edges_at(p, extra));
    Location& loc = out.edge[i];
    if (auto common = common_indices(on_edges); !common.empty()) {
      int be = common[0];
      loc = {On::Edge, be, {0, 0}, max_distance(on_edges, be)};
      // Range on the base edge covered by this edge: its end points projected on it.
      double lo = 1e300, hi = -1e300;
      for (const auto& hits : on_edges)
        for (const Hit& h : hits)
          if (h.index == be) lo = std::min(lo, h.t0), hi = std::max(hi, h.t0);
      for (int end = 0; end < 2; ++end) {
        int vi = other.edge_vertices(i, end);
        if (vi < 0) continue;
        gp_Pnt p(other.vertex_point(vi, 0), other.vertex_point(vi, 1), other.vertex_point(vi, 2));
        for (const Hit& h : probe.edges_at(p, extra))
          if (h.index == be) lo = std::min(lo, h.t0), hi = std::max(hi, h.t0);
      }
      loc.t[0] = lo;
      loc.t[1] = hi;
      continue;
    }
    for (const gp_Pnt& p : samples) on_faces.push_back(probe.faces_at(p, extra));
    if (auto common = common_indices(on_faces); !common.empty())
      loc = {On::Face, common[0], {0, 0}, max_distance(on_faces, common[0])};
  }

  out.face.resize(other.num_faces());
  for (int i = 0; i < other.num_faces(); ++i) {
    const TopoDS_Face& f = TopoDS::Face(other.faces(i + 1));
    std::vector<gp_Pnt> samples = face_samples(f, params.face_samples);
    if (samples.empty()) continue;
    const double extra = other.face_tolerance[i];
    std::vector<std::vector<Hit>> on_faces;
    for (const gp_Pnt& p : samples) {
      on_faces.push_back(probe.faces_at(p, extra));
      if (on_faces.back().empty()) break;  // one sample off every face: interior
    }
    if (auto common = common_indices(on_faces); !common.empty())
      out.face[i] = {On::Face, common[0], {0, 0}, max_distance(on_faces, common[0])};
  }
  return out;
}

bool touching(const TopologyIndex& nondesign, int i, int j, double tol, Contact& contact) {
  const TopoDS_Shape& a = nondesign.solids(i + 1);
  const TopoDS_Shape& b = nondesign.solids(j + 1);
  BRepExtrema_DistShapeShape dist(a, b);
  if (!dist.IsDone() || dist.Value() > tol) return false;
  contact = Contact{i, j, {}};
  // Faces of a lying on faces of b: sample a's faces, probe b's.
  TopologyIndex bi = index_topology(b);
  PointLocator probe_b(bi, tol);
  for (const int* fa = nondesign.solid_faces.begin(i); fa != nondesign.solid_faces.end(i); ++fa) {
    for (const gp_Pnt& p : face_samples(TopoDS::Face(nondesign.faces(*fa + 1)), 12)) {
      auto hits = probe_b.faces_at(p, nondesign.face_tolerance[*fa]);
      if (hits.empty()) continue;
      int fb = nondesign.faces.FindIndex(bi.faces(hits[0].index + 1)) - 1;
      if (std::find(contact.faces.begin(), contact.faces.end(), std::make_pair(*fa, fb)) == contact.faces.end())
        contact.faces.emplace_back(*fa, fb);
    }
  }
  return true;
}

ContainmentReport check_containment(const TopologyIndex& part, const TopologyIndex& nondesign,
                                    const ClassifyParams& params) {
  const double tol = coincidence_tolerance(part, params);
  ContainmentReport report;
  if (part.num_solids() != 1)
    throw Error(ErrorCode::InvalidShape, "the part must be exactly one solid; it has " +
                                             std::to_string(part.num_solids()) + " (fuse them into one, or pick one)");
  const TopoDS_Shape& whole = part.solids(1);
  const int n = nondesign.num_solids();
  ensure_triangulated(nondesign.shape);

  std::vector<Bnd_Box> boxes(n);
  for (int i = 0; i < n; ++i) {
    BRepBndLib::Add(nondesign.solids(i + 1), boxes[i], false);
    boxes[i].Enlarge(tol);
  }
  Bnd_Box part_box;
  BRepBndLib::Add(whole, part_box, false);
  part_box.Enlarge(10 * tol);

  for (int i = 0; i < n; ++i) {
    const TopoDS_Shape& s = nondesign.solids(i + 1);
    const double vi = std::abs(nondesign.solid_volume[i]);
    double xmin, ymin, zmin, xmax, ymax, zmax;
    boxes[i].Get(xmin, ymin, zmin, xmax, ymax, zmax);
    bool outside = part_box.IsOut(gp_Pnt(xmin, ymin, zmin)) || part_box.IsOut(gp_Pnt(xmax, ymax, zmax));
    double outside_volume = -1;
    if (!outside) {
      double vc = common_volume(whole, s);
      if (vc >= 0) {
        outside_volume = vi - vc;
        outside = outside_volume > 1e-5 * vi;
      } else {
        // The boolean failed: fall back to classifying surface samples.
        report.warnings.push_back("could not intersect non-design solid " + std::to_string(i + 1) +
                                  " with the part; checked containment by sampling instead");
        BRepClass3d_SolidClassifier inside(whole);
        for (int fi : std::vector<int>(nondesign.solid_faces.begin(i), nondesign.solid_faces.end(i))) {
          for (const gp_Pnt& p : face_samples(TopoDS::Face(nondesign.faces(fi + 1)), 8)) {
            inside.Perform(p, tol);
            if (inside.State() == TopAbs_OUT) outside = true;
          }
        }
      }
    }
    if (outside) {
      std::string amount = outside_volume > 0
                               ? " (" + fmt(outside_volume) + " mm³, " + fmt(100 * outside_volume / vi) + " % of it)"
                               : "";
      throw Error(ErrorCode::NonDesignOutside, "non-design solid " + std::to_string(i + 1) + " is not inside the part" +
                                                   amount + ": move or trim it so that it lies within the part");
    }
  }

  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if (boxes[i].IsOut(boxes[j])) continue;
      const TopoDS_Shape& a = nondesign.solids(i + 1);
      const TopoDS_Shape& b = nondesign.solids(j + 1);
      double vc = common_volume(a, b);
      double vmin = std::min(std::abs(nondesign.solid_volume[i]), std::abs(nondesign.solid_volume[j]));
      if (vc > 1e-5 * vmin)
        throw Error(ErrorCode::NonDesignOverlap, "non-design solids " + std::to_string(i + 1) + " and " +
                                                     std::to_string(j + 1) + " overlap (" + fmt(vc) +
                                                     " mm³ in common): make them disjoint; they may touch");
      Contact contact;
      if (!touching(nondesign, i, j, tol, contact)) continue;
      if (contact.faces.empty())
        report.warnings.push_back("non-design solids " + std::to_string(i + 1) + " and " + std::to_string(j + 1) +
                                  " touch along an edge or at a point only");
      report.contacts.push_back(std::move(contact));
    }
  }
  return report;
}

}  // namespace topopt::brep
