// The result shape as an OCCT solid and a STEP file (see step_export.h).
#include "result/step_export.h"

#include <fcntl.h>
#include <unistd.h>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepCheck.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepCheck_Result.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <Geom_ElementarySurface.hxx>
#include <Geom_Line.hxx>
#include <Geom_Plane.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Writer.hxx>
#include <ShapeUpgrade_UnifySameDomain.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <gp_Pln.hxx>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include "brep/occt_guard.h"
#include "common/cpu_time.h"
#include "common/error.h"
#include "common/isolate.h"
#include "result/step_export_analytic.h"
#include "result/step_planar_faces.h"

namespace topopt::result {
namespace {

gp_Pnt point(const TriSurface& s, int i) { return gp_Pnt(s.V(i, 0), s.V(i, 1), s.V(i, 2)); }

/// The B-Rep vertices and edges of the surface, each made once and shared by every face
/// that uses it (so the shell is closed by construction).
class SharedTopology {
 public:
  explicit SharedTopology(const TriSurface& s) : s_(s), vertex_(s.V.rows()) {}

  /// The edge from point a to point b, oriented a -> b (the stored edge runs low -> high).
  TopoDS_Edge edge(int a, int b) {
    const auto key = std::minmax(a, b);
    auto it = edges_.find(key);
    if (it == edges_.end()) it = edges_.emplace(key, straight_edge(key.first, key.second)).first;
    return a < b ? it->second : TopoDS::Edge(it->second.Reversed());
  }

 private:
  TopoDS_Vertex vertex(int i) {
    if (vertex_[i].IsNull()) vertex_[i] = BRepBuilderAPI_MakeVertex(point(s_, i)).Vertex();
    return vertex_[i];
  }
  TopoDS_Edge straight_edge(int a, int b) {
    TopoDS_Edge e;
    const gp_Pnt pa = point(s_, a), pb = point(s_, b);
    const double length = pa.Distance(pb);
    Handle(Geom_Line) line = new Geom_Line(pa, gp_Dir(gp_Vec(pa, pb)));
    builder_.MakeEdge(e, line, Precision::Confusion());
    builder_.Add(e, vertex(a).Oriented(TopAbs_FORWARD));
    builder_.Add(e, vertex(b).Oriented(TopAbs_REVERSED));
    builder_.Range(e, 0, length);
    return e;
  }

  const TriSurface& s_;
  BRep_Builder builder_;
  std::vector<TopoDS_Vertex> vertex_;
  std::map<std::pair<int, int>, TopoDS_Edge> edges_;
};

/// Triangle q's planar face, bounded by its three shared edges. Throws Error(InvalidShape)
/// for a triangle without area (no plane to put it on) or with an edge of no length.
TopoDS_Face triangle_face(const TriSurface& s, SharedTopology& topo, long q) {
  const int a = s.F(q, 0), b = s.F(q, 1), c = s.F(q, 2);
  const gp_Pnt pa = point(s, a), pb = point(s, b), pc = point(s, c);
  const gp_Vec n = gp_Vec(pa, pb).Crossed(gp_Vec(pa, pc));
  const double shortest = std::min({pa.Distance(pb), pb.Distance(pc), pc.Distance(pa)});
  if (n.Magnitude() <= 1e-12 * std::max(1.0, pa.SquareDistance(pb)) || shortest <= Precision::Confusion())
    throw Error(ErrorCode::InvalidShape, "the result surface has a triangle without area near (" +
                                             std::to_string(pa.X()) + ", " + std::to_string(pa.Y()) + ", " +
                                             std::to_string(pa.Z()) +
                                             "): it cannot become a CAD face; try other smoothing settings "
                                             "(\"optimization.smooth\") or a finer mesh");
  TopoDS_Wire w;
  BRep_Builder builder;
  builder.MakeWire(w);
  builder.Add(w, topo.edge(a, b));
  builder.Add(w, topo.edge(b, c));
  builder.Add(w, topo.edge(c, a));
  w.Closed(true);
  BRepBuilderAPI_MakeFace mf(gp_Pln(pa, gp_Dir(n)), w, true);
  if (!mf.IsDone()) throw Error(ErrorCode::InvalidShape, "OCCT could not make a face of a result triangle");
  return mf.Face();
}

std::string report_text(const StepExportReport& r) {
  std::ostringstream o;
  o.precision(17);
  o << r.valid << " " << r.solids << " " << r.faces << " " << r.planar_faces << " " << r.volume << " " << r.triangles
    << " " << r.unmerged_bodies << " " << r.analytic_faces << " " << r.analytic_refused << " " << r.facet_bodies;
  return o.str();
}

StepExportReport report_of(const std::string& text) {
  StepExportReport r;
  std::istringstream in(text);
  in >> r.valid >> r.solids >> r.faces >> r.planar_faces >> r.volume >> r.triangles >> r.unmerged_bodies >>
      r.analytic_faces >> r.analytic_refused >> r.facet_bodies;
  if (!in) throw Error(ErrorCode::Internal, "the STEP export's child answered '" + text + "'");
  return r;
}

void write_step_file(const TopoDS_Shape& shape, const std::string& path, bool pcurves) {
  STEPControl_Writer writer;
  Interface_Static::SetCVal("write.step.schema", "AP214IS");
  Interface_Static::SetCVal("write.step.unit", "MM");
  Interface_Static::SetIVal("write.surfacecurve.mode", pcurves ? 1 : 0);
  if (writer.Transfer(shape, STEPControl_ManifoldSolidBrep) != IFSelect_RetDone)
    throw Error(ErrorCode::InvalidShape, "OCCT could not translate the result solid to STEP");
  if (writer.Write(path.c_str()) != IFSelect_RetDone)
    throw Error(ErrorCode::Io, "cannot write '" + path + "' (folder missing, not writable, or disk full)");
}

/// The surface's triangles by piece (triangles sharing a point belong together), each piece
/// with its signed volume (> 0: a body, its triangles outward; < 0: a closed void inside one).
struct SurfacePieces {
  std::vector<std::vector<long>> triangles;
  std::vector<double> volume;
};

SurfacePieces surface_pieces(const TriSurface& s) {
  std::vector<int> parent(s.V.rows());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto root = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (long q = 0; q < s.F.rows(); ++q)
    for (int k = 1; k < 3; ++k) parent[root(s.F(q, k))] = root(s.F(q, 0));
  SurfacePieces out;
  std::map<int, size_t> index;
  for (long q = 0; q < s.F.rows(); ++q) {
    const auto it = index.emplace(root(s.F(q, 0)), out.triangles.size()).first;
    if (it->second == out.triangles.size()) out.triangles.emplace_back(), out.volume.push_back(0);
    out.triangles[it->second].push_back(q);
    const Eigen::Vector3d a = s.V.row(s.F(q, 0)), b = s.V.row(s.F(q, 1)), c = s.V.row(s.F(q, 2));
    out.volume[it->second] += a.dot(b.cross(c)) / 6;
  }
  return out;
}

/// The planar face `f` (step_planar_faces.h) on its plane, its loops as wires of the shared
/// edges between their kept points.
TopoDS_Face planar_face(const PlanarFace& f, SharedTopology& topo) {
  BRep_Builder builder;
  TopoDS_Face face;
  builder.MakeFace(face, new Geom_Plane(gp_Pnt(f.origin.x(), f.origin.y(), f.origin.z()),
                                        gp_Dir(f.normal.x(), f.normal.y(), f.normal.z())),
                   Precision::Confusion());
  for (const std::vector<int>& loop : f.loops) {
    TopoDS_Wire w;
    builder.MakeWire(w);
    for (size_t i = 0; i < loop.size(); ++i) builder.Add(w, topo.edge(loop[i], loop[(i + 1) % loop.size()]));
    w.Closed(true);
    builder.Add(face, w);
  }
  return face;
}

/// The faces of one piece of the surface (`tris`) into `shell`: the triangles on a curved
/// analytic input face (`on_source`: per triangle its SourceFaces id, or -1; empty: none) as
/// faces on that surface (analytic_faces; `refused` counts the pieces left as facets), the
/// piece's planar faces `planar` (one triangle: its own face) and the triangles of refused
/// analytic pieces as planar faces of their own. Returns true when an input face's region came
/// back as several faces (a full bore's two halves).
bool add_piece_faces(TopoDS_Shell& shell, const TriSurface& s, SharedTopology& topo, const std::vector<long>& tris,
                     const SourceFaces* source, const std::vector<int>& on_source,
                     const std::vector<const PlanarFace*>& planar, int& refused) {
  BRep_Builder builder;
  std::map<int, std::vector<long>> regions;
  std::vector<long> facets;
  for (long q : tris)
    if (!on_source.empty() && on_source[q] >= 0) regions[on_source[q]].push_back(q);
  const EdgeSource edges = [&topo](int a, int b) { return topo.edge(a, b); };
  bool split = false;
  for (const auto& [id, region] : regions) {
    const std::vector<TopoDS_Face> faces = analytic_faces(s, region, source->surface(id), edges, facets, refused);
    split = split || faces.size() > 1;
    for (const TopoDS_Face& f : faces) builder.Add(shell, f);
  }
  for (long q : facets) builder.Add(shell, triangle_face(s, topo, q));
  for (const PlanarFace* f : planar)
    builder.Add(shell, f->triangles.size() == 1 ? triangle_face(s, topo, f->triangles[0]) : planar_face(*f, topo));
  return split;
}

/// One solid per body of the surface, each void's shell added to the body that holds it (by
/// OCCT's classifier, at one of the void's points); curved input faces as analytic faces where
/// `source` is given (add_piece_faces), coplanar triangles merged into one planar face with
/// `merge` (step_planar_faces.h), else a face per triangle. `split` (optional): per body, whether
/// an input face's region came back as several faces.
std::vector<TopoDS_Solid> solids_of(const TriSurface& s, const SurfacePieces& pieces, const SourceFaces* source,
                                    const std::optional<PlanarFacesParams>& merge, int& refused,
                                    std::vector<char>* split = nullptr) {
  SharedTopology topo(s);
  BRep_Builder builder;
  const std::vector<int> on_source = source && !source->empty() ? source->classify(s) : std::vector<int>{};
  std::vector<char> mergeable(s.F.rows(), 1);
  for (size_t q = 0; q < on_source.size(); ++q) mergeable[q] = on_source[q] < 0;
  // without merging, the angle no two normals are within: every triangle its own face
  const std::vector<PlanarFace> planar = planar_faces(s, mergeable, merge.value_or(PlanarFacesParams{-1, -1}));
  std::vector<int> piece_of(s.F.rows(), -1);
  for (size_t k = 0; k < pieces.triangles.size(); ++k)
    for (long q : pieces.triangles[k]) piece_of[q] = static_cast<int>(k);
  std::vector<std::vector<const PlanarFace*>> planar_of(pieces.triangles.size());
  for (const PlanarFace& f : planar) planar_of[piece_of[f.triangles[0]]].push_back(&f);
  std::vector<TopoDS_Solid> bodies;
  std::vector<std::pair<TopoDS_Shell, long>> voids;  // (shell, one of its triangles)
  for (size_t k = 0; k < pieces.triangles.size(); ++k) {
    TopoDS_Shell shell;
    builder.MakeShell(shell);
    const bool halves = add_piece_faces(shell, s, topo, pieces.triangles[k], source, on_source, planar_of[k], refused);
    shell.Closed(true);
    if (pieces.volume[k] < 0) {
      voids.emplace_back(shell, pieces.triangles[k][0]);
      continue;
    }
    if (split) split->push_back(halves);
    TopoDS_Solid solid;
    builder.MakeSolid(solid);
    builder.Add(solid, shell);
    bodies.push_back(solid);
  }
  for (const auto& [shell, q] : voids) {
    const gp_Pnt p = point(s, s.F(q, 0));
    auto holder = std::find_if(bodies.begin(), bodies.end(), [&](const TopoDS_Solid& b) {
      return BRepClass3d_SolidClassifier(b, p, 1e-7).State() == TopAbs_IN;
    });
    if (holder == bodies.end())
      throw Error(ErrorCode::InvalidShape, "the result surface has a closed void near (" + std::to_string(p.X()) +
                                               ", " + std::to_string(p.Y()) + ", " + std::to_string(p.Z()) +
                                               ") that lies in no body; try other smoothing settings "
                                               "(\"optimization.smooth\")");
    builder.Add(*holder, shell);
  }
  return bodies;
}

/// `body` with the faces on one input surface that touch each other joined into one face (a
/// full bore's two halves become one face with a seam: ShapeUpgrade_UnifySameDomain, faces only,
/// whose edge merge re-orients the whole shell at a cost growing as its square); not checked
/// (the caller keeps it only when it passes OCCT's check). Null when OCCT throws on the way
/// (on a body that is not valid to begin with: the mount's, a vertex without a point).
TopoDS_Shape halves_joined(const TopoDS_Shape& body, double angular_tolerance) {
  try {
    ShapeUpgrade_UnifySameDomain unify(body, false, true, false);
    unify.SetAngularTolerance(angular_tolerance);
    unify.Build();
    return unify.Shape();
  } catch (const Standard_Failure&) {
    return {};
  }
}

/// The forms a body of the result can be built in, richest first: the input's curved faces as
/// analytic faces and coplanar triangles merged; the same unmerged; merged planar faces only;
/// a planar face per triangle, which a closed, outward surface without self-intersection always
/// makes valid. Each form is built for all bodies at once, when first needed, on its own
/// vertices and edges.
class BodyForms {
 public:
  BodyForms(const TriSurface& s, const SurfacePieces& pieces, const SourceFaces* source,
            const std::optional<PlanarFacesParams>& merge)
      : s_(s), pieces_(pieces), source_(source), merge_(merge) {}

  /// Body b in form `form`: 0 the first form built again (on fresh vertices and edges, for a
  /// body the halves' join damaged), 1, 2 or 3 the fallbacks after it.
  const TopoDS_Solid& body(int form, size_t b) {
    std::vector<TopoDS_Solid>& built = forms_[form];
    int ignored = 0;
    if (built.empty())
      built = solids_of(s_, pieces_, form < 2 ? source_ : nullptr, form % 2 == 0 ? merge_ : std::nullopt, ignored);
    return built[b];
  }

 private:
  const TriSurface& s_;
  const SurfacePieces& pieces_;
  const SourceFaces* source_;
  std::optional<PlanarFacesParams> merge_;
  std::vector<TopoDS_Solid> forms_[4];
};

/// The refusal of a surface that coarsen_to_budget could not bring within `budget` triangles,
/// naming the job key that raises the budget.
Error over_budget(const TriSurface& given, const CoarsenReport& r, long budget) {
  std::ostringstream o;
  o.precision(3);
  o << "result.step is not written: the result surface has " << given.F.rows() << " triangles and, coarsened as far "
    << "as its volume (within " << 100 * CoarsenBudget{}.max_volume_change
    << " %) and the check against self-intersection allow (chordal tolerance " << r.tolerance << " mm), still "
    << r.triangles_after << ", more than the STEP export's budget of " << budget
    << "; result.stl holds the shape. To write it anyway set \"" << max_triangles_key
    << "\" in the job's \"output\" to " << r.triangles_after << " or more (0: no budget), or optimise on a coarser mesh";
  return Error(ErrorCode::TooLarge, o.str());
}

/// What a piece of the surface is made of, from its triangles' tags (iso_surface.h): the
/// design region (free-form or Ω's faces) and the non-design solids it holds, e.g. "the design
/// with non-design solids 1, 2" or "non-design solid 3 alone".
std::string piece_makeup(const TriSurface& s, const std::vector<long>& triangles) {
  bool design = false;
  std::set<int> nondesign;
  for (long q : triangles) {
    if (s.tag[q] >= 0) design = true;
    if (s.tag[q] < 0) nondesign.insert(-s.tag[q]);
  }
  std::ostringstream o;
  o << (design ? "the design" : "");
  if (!nondesign.empty()) o << (design ? " with " : "") << "non-design solid" << (nondesign.size() > 1 ? "s " : " ");
  for (auto it = nondesign.begin(); it != nondesign.end(); ++it) o << (it == nondesign.begin() ? "" : ", ") << *it;
  if (!design && nondesign.size() == 1) o << " alone";
  return o.str();
}

}  // namespace

std::vector<std::string> body_descriptions(const TriSurface& s) {
  const SurfacePieces pieces = surface_pieces(s);
  std::vector<std::string> out;
  for (size_t k = 0; k < pieces.triangles.size(); ++k) {
    if (pieces.volume[k] <= 0) continue;  // a closed void inside a body
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (long q : pieces.triangles[k])
      for (int c = 0; c < 3; ++c) {
        lo = lo.cwiseMin(s.V.row(s.F(q, c)).transpose());
        hi = hi.cwiseMax(s.V.row(s.F(q, c)).transpose());
      }
    const Eigen::Vector3d centre = (lo + hi) / 2;
    std::ostringstream o;
    o.precision(4);
    o << "body " << out.size() + 1 << ": " << pieces.volume[k] << " mm³ around (" << centre.x() << ", " << centre.y()
      << ", " << centre.z() << "), " << piece_makeup(s, pieces.triangles[k]);
    out.push_back(o.str());
  }
  return out;
}

int result_bodies(const TriSurface& s) {
  const SurfacePieces pieces = surface_pieces(s);
  return static_cast<int>(std::count_if(pieces.volume.begin(), pieces.volume.end(), [](double v) { return v > 0; }));
}

TopoDS_Shape result_solid(const TriSurface& given, const StepExportParams& params, CoarsenReport* coarsened,
                          const SourceFaces* source, int* analytic_refused, bool* checked_valid) {
  const SurfaceCheck check = check_surface(given.V, given.F);
  if (!check.closed_manifold() || check.volume <= 0)
    throw Error(
        ErrorCode::InvalidShape,
        "the result surface is not closed and outward (" + std::to_string(check.unpaired_edges) +
            " unpaired edges): it cannot become a solid; try other smoothing settings (\"optimization.smooth\")");
  CoarsenReport report;
  const TriSurface s = coarsen_to_budget(given, params.coarsen, {params.max_triangles}, &report);
  if (coarsened) *coarsened = report;
  if (!report.fits) throw over_budget(given, report, params.max_triangles);
  // the bodies of the result (a detached non-design solid is one more) with their voids
  // inside, not a single shell of several pieces (BRepCheck: not connected)
  int refused = 0, analytic = 0;
  const SurfacePieces pieces = surface_pieces(s);
  const auto merge = params.unify ? std::optional<PlanarFacesParams>({params.angular_tolerance}) : std::nullopt;
  std::vector<char> split;
  std::vector<TopoDS_Shape> bodies;
  for (const TopoDS_Solid& body : solids_of(s, pieces, source, merge, analytic, &split)) bodies.push_back(body);
  if (analytic_refused) *analytic_refused = analytic;
  // a body OCCT's check refuses is built again in the next form (BodyForms) until one passes:
  // unmerged (counted in refused), then without the input's curved faces (in facet_bodies too),
  // then a face per triangle; each body is checked once in each form tried (BRepCheck is a
  // fifth of the export's time)
  BodyForms forms(s, pieces, source, merge);
  int facet_bodies = 0;
  bool all_valid = merge.has_value();
  for (size_t b = 0; merge && b < bodies.size(); ++b) {
    // UnifySameDomain works on the body's own sub-shapes: when it throws or its result fails the
    // check, the body may be left damaged (the mount at 5 mm: it threw "vertex without a
    // point" and left wires open), so the first form is built again, its halves unjoined
    int form = 0;
    if (split[b]) {
      const TopoDS_Shape joined = halves_joined(bodies[b], params.angular_tolerance);
      if (!joined.IsNull() && BRepCheck_Analyzer(joined).IsValid()) {
        bodies[b] = joined;
        continue;
      }
    } else if (BRepCheck_Analyzer(bodies[b]).IsValid()) {
      continue;
    } else {
      form = 1;
    }
    while (form <= 3 && !BRepCheck_Analyzer(forms.body(form, b)).IsValid()) ++form;
    if (form > 3) {
      all_valid = false;
      continue;
    }
    bodies[b] = forms.body(form, b);
    refused += form > 0;
    facet_bodies += form > 1;
  }
  if (coarsened) coarsened->unmerged_bodies = refused, coarsened->facet_bodies = facet_bodies;
  if (checked_valid) *checked_valid = all_valid;
  if (bodies.size() == 1) return bodies[0];
  BRep_Builder builder;
  TopoDS_Compound all;
  builder.MakeCompound(all);
  for (const TopoDS_Shape& body : bodies) builder.Add(all, body);
  return all;
}

std::string solid_faults(const TopoDS_Shape& shape, int limit) {
  const BRepCheck_Analyzer analyzer(shape);
  std::ostringstream out;
  int found = 0;
  const auto note = [&](const char* kind, int index, const TopoDS_Shape& sub, BRepCheck_Status status) {
    if (status == BRepCheck_NoError || found++ >= limit) return;
    if (found > 1) out << "; ";
    out << kind << " " << index;
    if (sub.ShapeType() == TopAbs_FACE || sub.ShapeType() == TopAbs_EDGE || sub.ShapeType() == TopAbs_VERTEX) {
      Bnd_Box box;
      BRepBndLib::Add(sub, box);
      const gp_Pnt c = box.IsVoid() ? gp_Pnt() : gp_Pnt((box.CornerMin().XYZ() + box.CornerMax().XYZ()) / 2);
      out << " near (" << c.X() << ", " << c.Y() << ", " << c.Z() << ")";
    }
    out << ": ";
    BRepCheck::Print(status, out);
  };
  const std::pair<TopAbs_ShapeEnum, const char*> kinds[] = {{TopAbs_VERTEX, "vertex"}, {TopAbs_EDGE, "edge"},
                                                            {TopAbs_WIRE, "wire"},     {TopAbs_FACE, "face"},
                                                            {TopAbs_SHELL, "shell"},   {TopAbs_SOLID, "solid"}};
  for (const auto& [type, kind] : kinds) {
    TopTools_IndexedMapOfShape subs;
    TopExp::MapShapes(shape, type, subs);
    for (int i = 1; i <= subs.Extent(); ++i) {
      const Handle(BRepCheck_Result)& result = analyzer.Result(subs(i));
      if (result.IsNull()) continue;
      for (BRepCheck_Status status : result->Status()) note(kind, i, subs(i), status);
      for (result->InitContextIterator(); result->MoreShapeInContext(); result->NextShapeInContext())
        for (BRepCheck_Status status : result->StatusOnShape()) note(kind, i, subs(i), status);
    }
  }
  if (found > limit) out << " (" << found - limit << " more)";
  std::string text = out.str();
  std::replace(text.begin(), text.end(), '\n', ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

StepExportReport describe_solid(const TopoDS_Shape& shape, bool known_valid) {
  StepExportReport r;
  for (TopExp_Explorer e(shape, TopAbs_SOLID); e.More(); e.Next()) ++r.solids;
  for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next()) {
    ++r.faces;
    Handle(Geom_Surface) surface = BRep_Tool::Surface(TopoDS::Face(e.Current()));
    if (surface.IsNull()) continue;
    if (surface->IsKind(STANDARD_TYPE(Geom_Plane))) ++r.planar_faces;
    if (surface->IsKind(STANDARD_TYPE(Geom_ElementarySurface)) && !surface->IsKind(STANDARD_TYPE(Geom_Plane)))
      ++r.analytic_faces;
  }
  r.valid = known_valid || BRepCheck_Analyzer(shape).IsValid();
  GProp_GProps props;
  BRepGProp::VolumeProperties(shape, props);
  r.volume = props.Mass();
  return r;
}

StepExportReport write_result_step(const std::string& path, const TriSurface& s, const StepExportParams& params,
                                   const Progress& progress, const SourceFaces* source) {
  const std::vector<std::string> parts = body_descriptions(s);
  if (parts.size() > 1) {
    std::string named;
    for (const std::string& b : parts) named += (named.empty() ? "" : "; ") + b;
    progress.warn("result.step holds " + std::to_string(parts.size()) +
                  " separate solids in one compound, because the design does not join them (as made they are "
                  "separate parts): " +
                  named +
                  ". For one part the design must carry load between them: a load on one body and a support on "
                  "another makes it join them, and a larger \"optimization.volume_fraction\" may");
  }
  const auto t0 = std::chrono::steady_clock::now();
  const double children_cpu0 = children_cpu_seconds();
  const pid_t caller = getpid();
  const std::string answer = run_isolated(
      "writing the result as STEP", params.seconds,
      [&]() {
        // OCCT's STEP writer prints its statistics on stdout: silenced in the child only
        // (stdout is the CLI's answer and the worker's protocol)
        if (getpid() != caller) {
          const int null = open("/dev/null", O_WRONLY);
          if (null >= 0) dup2(null, 1), close(null);
        }
        return brep::guard_occt("building result.step from the result surface", [&]() {
          CoarsenReport coarsened;
          int analytic_refused = 0;
          bool checked_valid = false;  // every body passed OCCT's check in result_solid: not run again
          const TopoDS_Shape solid = result_solid(s, params, &coarsened, source, &analytic_refused, &checked_valid);
          StepExportReport r = describe_solid(solid, checked_valid);
          r.triangles = coarsened.triangles_after;
          r.unmerged_bodies = coarsened.unmerged_bodies;
          r.facet_bodies = coarsened.facet_bodies;
          r.analytic_refused = analytic_refused;
          const int bodies = result_bodies(s);
          if (!r.valid || r.solids != bodies)
            throw Error(ErrorCode::InvalidShape,
                        "the result solid is not " + std::to_string(bodies) + " valid solid(s) (" +
                            std::to_string(r.solids) + " solids, OCCT's check " +
                            (r.valid ? std::string("passed") : "failed: " + solid_faults(solid, 3)) +
                            "); the STL is written: try other smoothing settings (\"optimization.smooth\")");
          write_step_file(solid, path, params.pcurves);
          return report_text(r);
        }, brep::OcctBlame::own_shape);
      },
      progress);
  StepExportReport r = report_of(answer);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.cpu_seconds = children_cpu_seconds() - children_cpu0;  // the child, waited for by run_isolated
  std::error_code ec;
  r.bytes = static_cast<long>(std::filesystem::file_size(path, ec));
  return r;
}

}  // namespace topopt::result
