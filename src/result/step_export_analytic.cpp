// The input's curved analytic faces in the result's STEP (see step_export_analytic.h).
#include "result/step_export_analytic.h"
#include "result/step_planar_faces.h"

#include <BRepBndLib.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <ElSLib.hxx>
#include <GProp_GProps.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom_ConicalSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_ElementarySurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_SphericalSurface.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array1OfPnt2d.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

namespace topopt::result {
namespace {

constexpr double kTwoPi = 2 * M_PI;

gp_Pnt point(const TriSurface& s, int i) { return gp_Pnt(s.V(i, 0), s.V(i, 1), s.V(i, 2)); }

/// The face's surface as an elementary curved surface (cylinder, cone, sphere, torus), in the
/// face's place; null for any other surface.
Handle(Geom_ElementarySurface) curved_elementary(const TopoDS_Face& face) {
  Handle(Geom_Surface) g = BRep_Tool::Surface(face);
  if (auto t = Handle(Geom_RectangularTrimmedSurface)::DownCast(g); !t.IsNull()) g = t->BasisSurface();
  if (g->IsKind(STANDARD_TYPE(Geom_CylindricalSurface)) || g->IsKind(STANDARD_TYPE(Geom_ConicalSurface)) ||
      g->IsKind(STANDARD_TYPE(Geom_SphericalSurface)) || g->IsKind(STANDARD_TYPE(Geom_ToroidalSurface)))
    return Handle(Geom_ElementarySurface)::DownCast(g);
  return nullptr;
}

/// (u, v) of the point of `g` nearest to p (ElSLib's closed forms; the cone's is the point
/// on the generatrix through p's angle, close enough for points near the surface).
gp_Pnt2d parameters(const Handle(Geom_ElementarySurface) & g, const gp_Pnt& p) {
  double u = 0, v = 0;
  if (auto c = Handle(Geom_CylindricalSurface)::DownCast(g); !c.IsNull()) ElSLib::Parameters(c->Cylinder(), p, u, v);
  if (auto c = Handle(Geom_ConicalSurface)::DownCast(g); !c.IsNull()) ElSLib::Parameters(c->Cone(), p, u, v);
  if (auto c = Handle(Geom_SphericalSurface)::DownCast(g); !c.IsNull()) ElSLib::Parameters(c->Sphere(), p, u, v);
  if (auto c = Handle(Geom_ToroidalSurface)::DownCast(g); !c.IsNull()) ElSLib::Parameters(c->Torus(), p, u, v);
  return {u, v};
}

/// Unit normal of `g` at (u, v) (the surface's own sense), or null vector at a singular point.
gp_Vec normal_at(const Handle(Geom_Surface) & g, const gp_Pnt2d& uv, gp_Pnt* at = nullptr) {
  gp_Pnt p;
  gp_Vec du, dv;
  g->D1(uv.X(), uv.Y(), p, du, dv);
  if (at) *at = p;
  const gp_Vec n = du.Crossed(dv);
  return n.Magnitude() > 1e-12 ? n.Normalized() : gp_Vec();
}

/// A triangle's area-weighted normal (its length: twice the area; outward for the surface's
/// triangles), centre and longest edge.
struct TriangleFrame {
  gp_Vec normal;
  gp_Pnt centre;
  double longest = 0;
};

TriangleFrame triangle_frame(const gp_Pnt& a, const gp_Pnt& b, const gp_Pnt& c) {
  return {gp_Vec(a, b).Crossed(gp_Vec(a, c)), gp_Pnt((a.XYZ() + b.XYZ() + c.XYZ()) / 3),
          std::max({a.Distance(b), b.Distance(c), c.Distance(a)})};
}

/// The frame of triangle q of `s`.
TriangleFrame triangle_frame(const TriSurface& s, long q) {
  return triangle_frame(point(s, s.F(q, 0)), point(s, s.F(q, 1)), point(s, s.F(q, 2)));
}

/// Distance from the middle of the gap-free arc of the angles `a` (radians, any range) to
/// the start of the circle: the centre of the smallest arc holding them all.
double arc_centre(std::vector<double> a) {
  for (double& x : a) x = x - kTwoPi * std::floor(x / kTwoPi);
  std::sort(a.begin(), a.end());
  double gap = a.front() + kTwoPi - a.back(), start = a.front();  // the gap across 0
  for (size_t i = 1; i < a.size(); ++i)
    if (a[i] - a[i - 1] > gap) gap = a[i] - a[i - 1], start = a[i];
  return start + (kTwoPi - gap) / 2;
}

/// `x` shifted by whole turns into (centre - pi, centre + pi].
double unwrap(double x, double centre) { return x - kTwoPi * std::round((x - centre) / kTwoPi); }

/// The triangles of `tris` in pieces connected through edges.
std::vector<std::vector<long>> connected_pieces(const TriSurface& s, const std::vector<long>& tris) {
  std::map<std::pair<int, int>, size_t> by_edge;  // half-edge -> position in tris
  for (size_t i = 0; i < tris.size(); ++i)
    for (int k = 0; k < 3; ++k) by_edge[{s.F(tris[i], k), s.F(tris[i], (k + 1) % 3)}] = i;
  std::vector<int> piece(tris.size(), -1);
  std::vector<std::vector<long>> out;
  for (size_t seed = 0; seed < tris.size(); ++seed) {
    if (piece[seed] >= 0) continue;
    std::vector<size_t> stack{seed};
    piece[seed] = static_cast<int>(out.size());
    out.emplace_back();
    while (!stack.empty()) {
      const size_t i = stack.back();
      stack.pop_back();
      out.back().push_back(tris[i]);
      for (int k = 0; k < 3; ++k) {
        const auto it = by_edge.find({s.F(tris[i], (k + 1) % 3), s.F(tris[i], k)});
        if (it != by_edge.end() && piece[it->second] < 0) piece[it->second] = piece[seed], stack.push_back(it->second);
      }
    }
  }
  return out;
}

/// True when a loop of the piece goes round the surface's axis (its angle turns by a full turn).
bool wraps(const std::vector<std::vector<int>>& loops, const std::vector<gp_Pnt2d>& uv) {
  for (const auto& loop : loops) {
    double turn = 0;
    for (size_t i = 0; i < loop.size(); ++i) {
      const double du = uv[loop[(i + 1) % loop.size()]].X() - uv[loop[i]].X();
      turn += unwrap(du, 0);
    }
    if (std::abs(turn) > M_PI) return true;
  }
  return false;
}

/// The 2D curve of the stored edge from point lo to point hi (lo < hi) on a surface where they
/// sit at uv_lo and uv_hi: a straight line in (u, v) over the edge's range [0, length].
Handle(Geom2d_BSplineCurve) segment_2d(const gp_Pnt2d& uv_lo, const gp_Pnt2d& uv_hi, double length) {
  TColgp_Array1OfPnt2d poles(1, 2);
  poles(1) = uv_lo, poles(2) = uv_hi;
  TColStd_Array1OfReal knots(1, 2);
  knots(1) = 0, knots(2) = length;
  TColStd_Array1OfInteger mults(1, 2);
  mults(1) = 2, mults(2) = 2;
  return new Geom2d_BSplineCurve(poles, knots, mults, 1);
}

/// One face on `g` for the piece `tris` (no loop wraps round the axis): the surface turned about
/// its axis so that the piece lies around u = pi, loops as wires of shared edges with their 2D
/// curves and tolerances, oriented outwards. Null when OCCT's check or the area refuses it (the
/// 2D curves it added are removed again).
class PieceFace {
 public:
  PieceFace(const TriSurface& s, const Handle(Geom_ElementarySurface) & g, const EdgeSource& edges)
      : s_(s), g_(g), edges_(edges) {}

  TopoDS_Face make(const std::vector<long>& tris, const std::vector<std::vector<int>>& loops) {
    turned_surface(tris);
    bool reversed = outward_sense(tris) < 0;
    TopoDS_Face face;
    builder_.MakeFace(face, turned_, Precision::Confusion());
    for (const auto& loop : loops) builder_.Add(face, wire(face, loop, reversed));
    if (reversed) face.Orientation(TopAbs_REVERSED);
    if (accepted(face, tris)) return face;
    undo();
    return {};
  }

 private:
  /// turned_: a copy of g_ turned about its axis so that the piece's angles centre on pi;
  /// uv_: each of the piece's points' parameters on it (v unwrapped too on a torus).
  void turned_surface(const std::vector<long>& tris) {
    std::vector<double> us, vs;
    for (long q : tris)
      for (int k = 0; k < 3; ++k) {
        const gp_Pnt2d uv = parameters(g_, point(s_, s_.F(q, k)));
        us.push_back(uv.X()), vs.push_back(uv.Y());
      }
    turned_ = Handle(Geom_ElementarySurface)::DownCast(g_->Copy());
    turned_->Rotate(g_->Position().Axis(), arc_centre(us) - M_PI);
    const bool torus = g_->IsKind(STANDARD_TYPE(Geom_ToroidalSurface));
    const double v_centre = torus ? arc_centre(vs) : 0;
    for (long q : tris)
      for (int k = 0; k < 3; ++k) {
        const int p = s_.F(q, k);
        const gp_Pnt2d uv = parameters(turned_, point(s_, p));
        uv_[p] = gp_Pnt2d(unwrap(uv.X(), M_PI), torus ? unwrap(uv.Y(), v_centre) : uv.Y());
      }
  }

  /// > 0 when the surface's normal points out of the piece's triangles (summed over them).
  double outward_sense(const std::vector<long>& tris) const {
    double sense = 0;
    for (long q : tris) {
      const TriangleFrame t = triangle_frame(s_, q);
      sense += t.normal.Dot(normal_at(turned_, parameters(turned_, t.centre)));
    }
    return sense;
  }

  /// The loop as a wire of the shared edges, with the edges' 2D curves on `face`; run backwards
  /// when the face will be reversed (the wire is stored in the surface's own sense).
  TopoDS_Wire wire(const TopoDS_Face& face, const std::vector<int>& loop, bool reversed) {
    TopoDS_Wire w;
    builder_.MakeWire(w);
    const size_t n = loop.size();
    for (size_t i = 0; i < n; ++i) {
      int a = loop[i], b = loop[(i + 1) % n];
      if (reversed) a = loop[(2 * n - i) % n], b = loop[(2 * n - i - 1) % n];
      const TopoDS_Edge e = edges_(a, b);
      const int lo = std::min(a, b), hi = std::max(a, b);
      const double length = point(s_, lo).Distance(point(s_, hi));
      touched_.emplace_back(e, BRep_Tool::Tolerance(e));
      builder_.UpdateEdge(e, segment_2d(uv_.at(lo), uv_.at(hi), length), face, Precision::Confusion());
      widen(e, point(s_, lo), point(s_, hi), uv_.at(lo), uv_.at(hi));
      builder_.Add(w, e);
    }
    w.Closed(true);
    return w;
  }

  /// Raises the edge's (and its vertices') tolerance to its largest distance from the surface
  /// along its 2D curve (the straight edge is a chord of the curved surface).
  void widen(const TopoDS_Edge& e, const gp_Pnt& p0, const gp_Pnt& p1, const gp_Pnt2d& uv0, const gp_Pnt2d& uv1) {
    double worst = 0;
    for (int i = 0; i <= 16; ++i) {
      const double t = i / 16.0;
      const gp_Pnt on_edge(p0.XYZ() * (1 - t) + p1.XYZ() * t);
      const gp_Pnt on_surface = turned_->Value(uv0.X() * (1 - t) + uv1.X() * t, uv0.Y() * (1 - t) + uv1.Y() * t);
      worst = std::max(worst, on_edge.Distance(on_surface));
    }
    const double tol = std::max(BRep_Tool::Tolerance(e), 1.01 * worst + Precision::Confusion());
    builder_.UpdateEdge(e, tol);
    TopoDS_Vertex v0, v1;
    TopExp::Vertices(e, v0, v1);
    for (const TopoDS_Vertex& v : {v0, v1})
      if (BRep_Tool::Tolerance(v) < tol) builder_.UpdateVertex(v, tol);
  }

  /// OCCT's check passes and the face's area is the triangles' within 5 % (a face bounded the
  /// wrong way round would be the rest of the surface).
  bool accepted(const TopoDS_Face& face, const std::vector<long>& tris) const {
    if (!BRepCheck_Analyzer(face).IsValid()) return false;
    double area = 0;
    for (long q : tris) area += triangle_frame(s_, q).normal.Magnitude() / 2;
    GProp_GProps props;
    BRepGProp::SurfaceProperties(face, props);
    return std::abs(props.Mass() - area) <= 0.05 * area;
  }

  /// Removes the 2D curves added on the turned surface and restores the edges' tolerances.
  void undo() {
    for (const auto& [e, tol] : touched_) {
      builder_.UpdateEdge(e, Handle(Geom2d_Curve)(), turned_, TopLoc_Location(), tol);
      builder_.UpdateEdge(e, tol);
    }
  }

  const TriSurface& s_;
  Handle(Geom_ElementarySurface) g_, turned_;
  const EdgeSource& edges_;
  BRep_Builder builder_;
  std::map<int, gp_Pnt2d> uv_;
  std::vector<std::pair<TopoDS_Edge, double>> touched_;
};

/// The triangles of `piece` whose centre's angle on g lies in [0, pi) (first) and [pi, 2 pi).
std::pair<std::vector<long>, std::vector<long>> halves(const TriSurface& s, const std::vector<long>& piece,
                                                       const Handle(Geom_ElementarySurface) & g) {
  std::pair<std::vector<long>, std::vector<long>> out;
  for (long q : piece) {
    double u = parameters(g, triangle_frame(s, q).centre).X();
    u -= kTwoPi * std::floor(u / kTwoPi);
    (u < M_PI ? out.first : out.second).push_back(q);
  }
  return out;
}

}  // namespace

SourceFaces::SourceFaces(const TopoDS_Shape& part, const TopoDS_Shape& nondesign) {
  TopTools_IndexedMapOfShape faces;
  if (!part.IsNull()) TopExp::MapShapes(part, TopAbs_FACE, faces);
  part_face_.resize(faces.Extent() + 1);
  for (int f = 1; f <= faces.Extent(); ++f) add(TopoDS::Face(faces(f)), part_face_[f]);
  TopTools_IndexedMapOfShape solids;
  if (!nondesign.IsNull()) TopExp::MapShapes(nondesign, TopAbs_SOLID, solids);
  solid_faces_.resize(solids.Extent() + 1);
  for (int k = 1; k <= solids.Extent(); ++k) {
    TopTools_IndexedMapOfShape own;
    TopExp::MapShapes(solids(k), TopAbs_FACE, own);
    for (int f = 1; f <= own.Extent(); ++f) add(TopoDS::Face(own(f)), solid_faces_[k]);
  }
}

void SourceFaces::add(const TopoDS_Face& face, std::vector<int>& ids) {
  Handle(Geom_ElementarySurface) g = curved_elementary(face);
  if (g.IsNull()) return;
  ids.push_back(size());
  faces_.push_back(face);
  surfaces_.push_back(g);
}

int SourceFaces::nearest(const std::vector<int>& ids, const gp_Pnt& c, const gp_Vec& n, double edge) const {
  int out = -1;
  double best = 0.2 * edge;
  for (int id : ids) {
    gp_Pnt on;
    const gp_Vec normal = normal_at(surfaces_[id], parameters(surfaces_[id], c), &on);
    const double d = on.Distance(c);
    if (d < best && std::abs(normal.Dot(n.Normalized())) > std::cos(M_PI / 4)) best = d, out = id;
  }
  return out;
}

std::vector<int> SourceFaces::classify(const TriSurface& s) const {
  const std::vector<int> none;
  std::vector<int> out(s.F.rows(), -1);
  for (long q = 0; q < s.F.rows(); ++q) {
    const int t = s.tag[q];
    const std::vector<int>& candidates = t > 0 && t < static_cast<int>(part_face_.size())      ? part_face_[t]
                                         : t < 0 && -t < static_cast<int>(solid_faces_.size()) ? solid_faces_[-t]
                                                                                               : none;
    if (candidates.empty()) continue;
    const TriangleFrame f = triangle_frame(s, q);
    if (f.normal.Magnitude() > 0) out[q] = nearest(candidates, f.centre, f.normal, f.longest);
  }
  return out;
}

VecXi SourceFaces::part_face_numbers(const MatX3d& V, const MatX3i& F) const {
  std::vector<std::pair<int, Bnd_Box>> curved;  // Ω's curved faces: id and bounding box
  std::vector<int> number(size(), 0);           // id -> Ω's face number (0: a non-design face)
  for (int f = 1; f < static_cast<int>(part_face_.size()); ++f)
    for (int id : part_face_[f]) {
      Bnd_Box box;
      BRepBndLib::Add(faces_[id], box);
      curved.emplace_back(id, box);
      number[id] = f;
    }
  VecXi out = VecXi::Zero(F.rows());
  const auto at = [&V](int i) { return gp_Pnt(V(i, 0), V(i, 1), V(i, 2)); };
  std::vector<int> ids;
  for (long q = 0; q < F.rows() && !curved.empty(); ++q) {
    const TriangleFrame f = triangle_frame(at(F(q, 0)), at(F(q, 1)), at(F(q, 2)));
    if (f.normal.Magnitude() <= 0) continue;
    ids.clear();
    for (const auto& [id, box] : curved) {
      Bnd_Box near = box;
      near.Enlarge(f.longest);
      if (!near.IsOut(f.centre)) ids.push_back(id);
    }
    const int id = nearest(ids, f.centre, f.normal, f.longest);
    if (id >= 0) out[q] = number[id];
  }
  return out;
}

std::vector<TopoDS_Face> analytic_faces(const TriSurface& s, const std::vector<long>& region,
                                        const Handle(Geom_ElementarySurface) & g, const EdgeSource& edges,
                                        std::vector<long>& facets, int& refused) {
  std::vector<TopoDS_Face> out;
  const auto give_up = [&](const std::vector<long>& tris) {
    facets.insert(facets.end(), tris.begin(), tris.end());
    ++refused;
  };
  std::vector<gp_Pnt2d> uv(s.V.rows());
  for (long q : region)
    for (int k = 0; k < 3; ++k) uv[s.F(q, k)] = parameters(g, point(s, s.F(q, k)));
  // one face per piece; a piece going round the axis is cut in two halves first, and so is a
  // piece whose face OCCT refuses (on the rocker: a piece whose points' angles cover the whole
  // turn at different heights without going round, so no single seam position clears it)
  const auto face_of = [&](const std::vector<long>& piece, bool may_split, auto& self) -> void {
    const auto split = [&]() {
      const auto [lower, upper] = halves(s, piece, g);
      for (const auto& half : {lower, upper})
        for (const auto& part : connected_pieces(s, half)) self(part, false, self);
    };
    const auto loops = boundary_loops(s, piece);
    if (!loops) return may_split ? split() : give_up(piece);
    if (wraps(*loops, uv)) return may_split ? split() : give_up(piece);
    const TopoDS_Face face = PieceFace(s, g, edges).make(piece, *loops);
    if (!face.IsNull()) return out.push_back(face);
    may_split ? split() : give_up(piece);
  };
  if (g.IsNull()) {
    give_up(region);
    return out;
  }
  for (const auto& piece : connected_pieces(s, region)) face_of(piece, true, face_of);
  return out;
}

}  // namespace topopt::result
