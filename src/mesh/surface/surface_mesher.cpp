// Surface meshing by the B-Rep hierarchy (see surface_mesher.h).
#include "mesh/surface/surface_mesher.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepLProp_CLProps.hxx>
#include <BRepLProp_SLProps.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_Curve.hxx>
#include <Geom_Surface.hxx>
#include <Poly_Triangulation.hxx>
#include <ShapeAnalysis_Curve.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Vertex.hxx>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <sstream>
#include <thread>
#include <unordered_map>
#include <unordered_set>

#include "common/closed_surface.h"
#include "common/cpu_time.h"
#include "common/error.h"
#include "common/parallel.h"
#include "mesh/core/predicates.h"
#include "mesh/core/ray_cast.h"
#include "mesh/surface/graded_size.h"
#include "mesh/surface/surface_optimize.h"

namespace topopt::mesh {

// A per-direction scale making lengths in (su·u, sv·v) approximate lengths on the surface (the
// mean of |Xu| and |Xv| over 5 x 5 samples), and the largest curvature there.
ModelSurface::FaceGeometry ModelSurface::face_geometry(const TopoDS_Face& f) {
  FaceGeometry g;
  double u0, u1, v0, v1;
  BRepTools::UVBounds(f, u0, u1, v0, v1);
  BRepAdaptor_Surface s(f, Standard_True);
  BRepLProp_SLProps props(s, 2, 1e-9);
  double su = 0, sv = 0;
  int n = 0;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      const double u = u0 + (u1 - u0) * (i + 0.5) / 5, v = v0 + (v1 - v0) * (j + 0.5) / 5;
      gp_Pnt p;
      gp_Vec du, dv;
      s.D1(u, v, p, du, dv);
      su += du.Magnitude();
      sv += dv.Magnitude();
      ++n;
      props.SetParameters(u, v);
      if (props.IsCurvatureDefined())
        g.kmax = std::max({g.kmax, std::abs(props.MaxCurvature()), std::abs(props.MinCurvature())});
    }
  g.su = su / n > 1e-12 ? su / n : 1;
  g.sv = sv / n > 1e-12 ? sv / n : 1;
  return g;
}

namespace {

/// At most this many pieces on a collapsed edge: the fan around a cone apex or a sphere pole
/// has about as many triangles, so their angles there stay near 360° / 12 or more.
constexpr int kMaxApexPieces = 12;
/// A face corner sharper than this (radians) is closed by one needle triangle (see
/// sharp_corners).
constexpr double kNeedleAngle = 30 * M_PI / 180;
/// The two pieces at a corner sharper than kNeedleAngle are made the same length when the
/// triangle closing the corner would have an angle above this (radians; match_corner_pieces).
constexpr double kCapAngle = 100 * M_PI / 180;

/// The angle (rad) the surface of `face` sweeps around a collapsed edge (cone apex, sphere
/// pole) whose parameter curve is pc on [t0, t1]: the turning of the surface's derivative
/// across that curve, summed over samples.
double apex_angle(const TopoDS_Face& face, const Handle(Geom2d_Curve) & pc, double t0, double t1) {
  BRepAdaptor_Surface s(face, Standard_False);
  double u0, u1, v0, v1;
  BRepTools::UVBounds(face, u0, u1, v0, v1);
  const double eps = 1e-4 * std::max(u1 - u0, v1 - v0);
  // the face's side of the collapsed edge, chosen once at its middle (chosen per sample, a
  // side that flips reverses the direction and adds half-turns to the sum)
  double side = 1;
  {
    gp_Pnt2d q;
    gp_Vec2d d;
    pc->D1(0.5 * (t0 + t1), q, d);
    const double m = d.Magnitude();
    if (m > 1e-300) {
      const double x = q.X() - eps * d.Y() / m, y = q.Y() + eps * d.X() / m;
      if (x < u0 || x > u1 || y < v0 || y > v1) side = -1;
    }
  }
  const int m = 24;
  gp_Vec prev;
  double total = 0;
  for (int i = 0; i <= m; ++i) {
    const double t = t0 + (t1 - t0) * i / m;
    gp_Pnt2d q;
    gp_Vec2d d;
    pc->D1(t, q, d);
    if (d.Magnitude() < 1e-300) continue;
    // a point just off the collapsed edge, on the face's side, where the derivatives live
    gp_Vec2d across(-side * d.Y(), side * d.X());
    across.Normalize();
    const gp_Pnt2d inside(q.X() + eps * across.X(), q.Y() + eps * across.Y());
    gp_Pnt p;
    gp_Vec xu, xv;
    s.D1(inside.X(), inside.Y(), p, xu, xv);
    gp_Vec dir = xu * across.X() + xv * across.Y();
    if (dir.Magnitude() < 1e-300) continue;
    dir.Normalize();
    if (prev.Magnitude() > 0) total += prev.Angle(dir);
    prev = dir;
  }
  return total > 0 ? total : 2 * M_PI;
}

/// The faces of solid s (0-based) in the solid's order: (face number, 1-based; whether the
/// solid uses it reversed with respect to the index's own orientation of that face).
std::vector<std::pair<int, bool>> solid_faces(const brep::TopologyIndex& topo, int s) {
  std::vector<std::pair<int, bool>> out;
  for (TopExp_Explorer ex(topo.solids(s + 1), TopAbs_FACE); ex.More(); ex.Next()) {
    const int f = topo.faces.FindIndex(ex.Current());
    if (f > 0) out.push_back({f, ex.Current().Orientation() != topo.faces(f).Orientation()});
  }
  return out;
}

double sqdist(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

/// Distance from P to the segment AB in the plane.
double point_segment_distance(const std::array<double, 2>& P, const std::array<double, 2>& A,
                              const std::array<double, 2>& B) {
  const double dx = B[0] - A[0], dy = B[1] - A[1], l2 = dx * dx + dy * dy;
  const double t = l2 > 0 ? std::clamp(((P[0] - A[0]) * dx + (P[1] - A[1]) * dy) / l2, 0.0, 1.0) : 0.0;
  return std::hypot(P[0] - A[0] - t * dx, P[1] - A[1] - t * dy);
}

/// Whether the segments A-B and C-D meet (cross, touch or overlap; collinear pieces of one
/// straight edge that are apart do not), by exact orientation tests.
bool segments_meet(const std::array<double, 2>& A, const std::array<double, 2>& B, const std::array<double, 2>& C,
                   const std::array<double, 2>& D) {
  return predicates::segments_meet(A.data(), B.data(), C.data(), D.data());
}

}  // namespace

int wall_layers_option(double value) {
  if (!(value >= 0 && value <= 4 && value == std::floor(value)))
    throw Error(ErrorCode::InvalidParameter,
                "wall layers must be a whole number from 0 (no refinement by wall thickness) to 4; 2 gives thin walls "
                "two element layers across");
  return static_cast<int>(value);
}

// ============================================================================ ModelSurface

ModelSurface::ModelSurface(const brep::TopologyIndex& topo, std::vector<std::array<double, 3>>& nodes,
                           const SurfaceMeshParams& params)
    : topo_(topo), nodes_(nodes), params_(params) {
  h_ = params.size > 0 ? params.size : topo.diagonal() / 50;
  hmin_ = params.min_size > 0 ? params.min_size : h_ / 10;
  grade_ = params.gradation - 1;
  const int nv = topo.num_vertices(), ne = topo.num_edges(), nf = topo.num_faces();
  vertex_node_.assign(nv, -1);
  edge_kind_.assign(ne, EdgeKind::Free);
  alias_of_.assign(ne, {-1, 0});
  fixed_.resize(ne);
  edge_param_.resize(ne);
  edge_node_.resize(ne);
  split_close_.assign(ne, 0);
  constraint_.resize(nf);
  face_extra_nodes_.resize(nf);
  face_given_.assign(nf, 0);
  face_alias_.assign(nf, {-1, 0});
  face_tris_.resize(nf);
  size_faces();
  measure_thickness();
  sample_edges();
  thin_edge_sizes();
  initial_vertex_sizes();
}

// Per face: the parameter scaling and the size its curvature allows.
void ModelSurface::size_faces() {
  const int nf = topo_.num_faces();
  geo_.resize(nf);
  face_size_.assign(nf, h_);
  for (int f = 0; f < nf; ++f) {
    geo_[f] = face_geometry(TopoDS::Face(topo_.faces(f + 1)));
    if (geo_[f].kmax > 0) face_size_[f] = std::clamp(params_.max_angle / geo_[f].kmax, hmin_, h_);
  }
}

// Each edge sampled finely once: parameters, arc length, and the size allowed there (its
// faces' sizes, its own local curvature).
void ModelSurface::sample_edges() {
  const int ne = topo_.num_edges();
  std::vector<double> edge_size(ne, h_);
  for (int f = 0; f < topo_.num_faces(); ++f)
    for (const int* e = topo_.face_edges.begin(f); e != topo_.face_edges.end(f); ++e)
      edge_size[*e] = std::min(edge_size[*e], face_size_[f]);
  samples_.resize(ne);
  for (int e = 0; e < ne; ++e) {
    if (topo_.edge_degenerate[e]) continue;
    const TopoDS_Edge E = TopoDS::Edge(topo_.edges(e + 1).Oriented(TopAbs_FORWARD));
    TopoDS_Vertex va, vb;
    TopExp::Vertices(E, va, vb);
    EdgeSamples& S = samples_[e];
    S.va = topo_.vertices.FindIndex(va) - 1, S.vb = topo_.vertices.FindIndex(vb) - 1;
    BRepAdaptor_Curve c(E);
    BRepLProp_CLProps props(c, 2, 1e-9);
    const double t0 = c.FirstParameter(), t1 = c.LastParameter();
    const int m = 128;
    gp_Pnt prev;
    for (int i = 0; i <= m; ++i) {
      const double t = t0 + (t1 - t0) * i / m;
      const gp_Pnt p = c.Value(t);
      S.t.push_back(t);
      S.s.push_back(i ? S.s.back() + p.Distance(prev) : 0.0);
      prev = p;
      props.SetParameter(t);
      double k = props.IsTangentDefined() ? std::abs(props.Curvature()) : 0.0;
      S.size.push_back(k > 0 ? std::min(edge_size[e], std::max(hmin_, params_.max_angle / k)) : edge_size[e]);
    }
  }
}

// The wall thickness of the faces along each edge, read through the edge's parameter curves.
void ModelSurface::thin_edge_sizes() {
  for (int f = 0; f < topo_.num_faces(); ++f) {
    if (thin_size_[f].empty()) continue;
    const TopoDS_Face F = TopoDS::Face(topo_.faces(f + 1).Oriented(TopAbs_FORWARD));
    for (const int* e = topo_.face_edges.begin(f); e != topo_.face_edges.end(f); ++e) {
      if (topo_.edge_degenerate[*e]) continue;
      double pf, pl;
      const Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(TopoDS::Edge(topo_.edges(*e + 1)), F, pf, pl);
      if (pc.IsNull()) continue;
      EdgeSamples& S = samples_[*e];
      for (size_t i = 0; i < S.t.size(); ++i) {
        const gp_Pnt2d w = pc->Value(S.t[i]);
        const double q[2] = {w.X() * geo_[f].su, w.Y() * geo_[f].sv};
        S.size[i] = thin_size_[f].size_at(q, S.size[i]);
      }
    }
  }
}

// Vertex sizes: no larger than the sizes along their edges nor their short edges' lengths,
// then limited by the gradation across edges.
void ModelSurface::initial_vertex_sizes() {
  vsize_.assign(topo_.num_vertices(), h_);
  for (int e = 0; e < topo_.num_edges(); ++e) {
    const EdgeSamples& S = samples_[e];
    if (S.va < 0) continue;
    const double len = S.s.back();
    vsize_[S.va] = std::min({vsize_[S.va], S.size.front(), std::max(len, hmin_ / 8)});
    vsize_[S.vb] = std::min({vsize_[S.vb], S.size.back(), std::max(len, hmin_ / 8)});
  }
  grade_vertex_sizes();
}

// Wall thickness (params.wall_layers > 0): walls thinner than two face sizes get about that
// many element layers across, size = thickness / (layers + 0.5), not below min_size (at
// thickness / layers exactly, the volume fill's circumradius rule still leaves many tets
// spanning the wall). Measured on a coarse tessellation of a copy of the model (OCCT's BRepMesh;
// the model itself keeps no triangulation): points spread over each triangle about a face
// size apart cast a ray inward, and the nearest triangle it meets gives the thickness there.
// Each point thinner than two face sizes becomes a fine point in the face's scaled parameters,
// which the face's SizeRaster (thin_size_, built once here) spreads at the gradation rate over
// the face's fill and its edges.
void ModelSurface::measure_thickness() {
  const int nf = topo_.num_faces();
  thin_size_.assign(nf, SizeRaster());
  wall_points_.clear();
  if (nf == 0 || params_.wall_layers <= 0) return;
  const Tessellation tess = coarse_tessellation();
  if (tess.F.rows() == 0) return;
  const MatX3d& V = tess.V;
  const MatX3i& F = tess.F;
  const TriangleRays rays(V, F);
  std::vector<std::vector<std::array<double, 3>>> thin_uv(nf);  // per face: (scaled u, v, size)
  for (long t = 0; t < F.rows(); ++t) {
    const int f = tess.face[t];
    if (f < 0) continue;
    const double hf = face_size_[f];
    const Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), c = V.row(F(t, 2));
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() <= 0) continue;
    n.normalize();
    const Eigen::Vector3d d = -n;  // into the material
    // samples: a barycentric grid about 0.7 face sizes apart (not below half the model's
    // size: a fillet's small face size says nothing about how thick the wall behind it is)
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int m = std::clamp(static_cast<int>(std::ceil(longest / (0.7 * std::max(hf, 0.5 * h_)))), 1, 64);
    for (int i = 0; i < m; ++i)
      for (int j = 0; i + j < m; ++j) {
        const double wa = (i + 1.0 / 3) / m, wb = (j + 1.0 / 3) / m, wc = 1 - wa - wb;
        const Eigen::Vector3d x = wa * a + wb * b + wc * c;
        const double thick = rays.first_hit(x.data(), d.data(), t, 2 * hf);
        if (thick >= 2 * hf || thick < 1e-9 * h_) continue;
        const double size = std::max(thick / (params_.wall_layers + 0.5), hmin_);
        if (size >= hf) continue;
        const Eigen::Vector3d mid = x + 0.5 * thick * d;
        wall_points_.push_back({mid[0], mid[1], mid[2], size});
        const auto &ua = tess.uv[F(t, 0)], &ub = tess.uv[F(t, 1)], &uc = tess.uv[F(t, 2)];
        thin_uv[f].push_back({wa * ua[0] + wb * ub[0] + wc * uc[0], wa * ua[1] + wb * ub[1] + wc * uc[1], size});
      }
  }
  for (int f = 0; f < nf; ++f)
    if (!thin_uv[f].empty()) thin_size_[f] = SizeRaster(thin_uv[f], face_size_[f], grade_);
}

// OCCT's BRepMesh of a copy of the model at 0.2 sizes, outward, with each node's scaled
// parameters on its face and each triangle's face (-1 where the face has no parameters).
ModelSurface::Tessellation ModelSurface::coarse_tessellation() const {
  BRepBuilderAPI_Copy copier(topo_.shape, Standard_True, Standard_False);
  const TopoDS_Shape copy = copier.Shape();
  BRepMesh_IncrementalMesh(copy, 0.2 * h_, Standard_False, 0.5, Standard_True);
  std::vector<std::array<double, 3>> xyz;
  std::vector<std::array<int, 3>> tri;
  Tessellation out;
  for (int f = 0; f < topo_.num_faces(); ++f) {
    const TopTools_ListOfShape& mod = copier.Modified(topo_.faces(f + 1));
    if (mod.IsEmpty()) continue;
    const TopoDS_Face face = TopoDS::Face(mod.First());
    TopLoc_Location loc;
    const Handle(Poly_Triangulation) pt = BRep_Tool::Triangulation(face, loc);
    if (pt.IsNull()) continue;
    const int base = static_cast<int>(xyz.size());
    for (int i = 1; i <= pt->NbNodes(); ++i) {
      const gp_Pnt q = pt->Node(i).Transformed(loc.Transformation());
      xyz.push_back({q.X(), q.Y(), q.Z()});
      const gp_Pnt2d w = pt->HasUVNodes() ? pt->UVNode(i) : gp_Pnt2d(0, 0);
      out.uv.push_back({w.X() * geo_[f].su, w.Y() * geo_[f].sv});
    }
    const bool reversed = face.Orientation() == TopAbs_REVERSED;
    for (int i = 1; i <= pt->NbTriangles(); ++i) {
      int a, b, c;
      pt->Triangle(i).Get(a, b, c);
      if (reversed) std::swap(b, c);
      tri.push_back({base + a - 1, base + b - 1, base + c - 1});
      out.face.push_back(pt->HasUVNodes() ? f : -1);
    }
  }
  out.V.resize(static_cast<long>(xyz.size()), 3);
  for (size_t i = 0; i < xyz.size(); ++i) out.V.row(static_cast<long>(i)) << xyz[i][0], xyz[i][1], xyz[i][2];
  out.F.resize(static_cast<long>(tri.size()), 3);
  for (size_t t = 0; t < tri.size(); ++t) out.F.row(static_cast<long>(t)) << tri[t][0], tri[t][1], tri[t][2];
  return out;
}

int ModelSurface::new_node(double x, double y, double z) {
  nodes_.push_back({x, y, z});
  return static_cast<int>(nodes_.size()) - 1;
}

void ModelSurface::set_vertex_node(int v, int node) { vertex_node_[v] = node; }

void ModelSurface::create_vertex_nodes(double merge_tolerance) {
  for (int v = 0; v < topo_.num_vertices(); ++v) {
    if (vertex_node_[v] >= 0) continue;
    const std::array<double, 3> p{topo_.vertex_point(v, 0), topo_.vertex_point(v, 1), topo_.vertex_point(v, 2)};
    if (merge_tolerance > 0)
      for (int u = 0; u < v && vertex_node_[v] < 0; ++u)
        if (vertex_node_[u] >= 0 && sqdist(nodes_[vertex_node_[u]], p) <= merge_tolerance * merge_tolerance)
          vertex_node_[v] = vertex_node_[u];
    if (vertex_node_[v] < 0) vertex_node_[v] = new_node(p[0], p[1], p[2]);
  }
}

double ModelSurface::edge_parameter(int e, const double* x, double* distance) const {
  const TopoDS_Edge E = TopoDS::Edge(topo_.edges(e + 1).Oriented(TopAbs_FORWARD));
  double first, last;
  Handle(Geom_Curve) curve = BRep_Tool::Curve(E, first, last);
  if (curve.IsNull()) {
    if (distance) *distance = 1e300;
    return first;
  }
  gp_Pnt proj;
  double t = first;
  const double d =
      ShapeAnalysis_Curve().Project(curve, gp_Pnt(x[0], x[1], x[2]), 1e-9, proj, t, first, last, Standard_False);
  if (distance) *distance = d;
  return std::clamp(t, std::min(first, last), std::max(first, last));
}

void ModelSurface::fix_edge_node(int e, int node) {
  const double t = edge_parameter(e, nodes_[node].data());
  for (const auto& [s, n] : fixed_[e])
    if (n == node) return;
  fixed_[e].push_back({t, node});
}

void ModelSurface::set_edge_mesh(int e, const std::vector<int>& ids) {
  const TopoDS_Edge E = TopoDS::Edge(topo_.edges(e + 1).Oriented(TopAbs_FORWARD));
  BRepAdaptor_Curve c(E);
  std::vector<double> par(ids.size());
  for (size_t i = 0; i < ids.size(); ++i)
    par[i] = i == 0                ? c.FirstParameter()
             : i + 1 == ids.size() ? c.LastParameter()
                                   : edge_parameter(e, nodes_[ids[i]].data());
  edge_param_[e] = std::move(par);
  edge_node_[e] = ids;
  edge_kind_[e] = EdgeKind::Given;
}

void ModelSurface::alias_edge(int e, int rep, bool reversed) {
  edge_kind_[e] = EdgeKind::Alias;
  alias_of_[e] = {rep, reversed ? 1 : 0};
}

void ModelSurface::refresh_alias(int e) {
  const auto [rep, reversed] = alias_of_[e];
  std::vector<int> ids = edge_node_[rep];
  if (reversed) std::reverse(ids.begin(), ids.end());
  const EdgeKind keep = edge_kind_[e];
  set_edge_mesh(e, ids);
  edge_kind_[e] = keep;
}

// Where the nodes of edge e go: spacing = the smallest of the local size and the sizes
// growing from both vertices at the gradation rate, at equal steps of ∫ ds / size between the
// vertices and the fixed nodes (step 5: nodes transferred from the other model are kept).
// Returns (parameter, node) from the first vertex to the last; node -1 where one is to be made.
ModelSurface::Division ModelSurface::division(int e) const {
  const EdgeSamples& S = samples_[e];
  const int m = static_cast<int>(S.t.size()) - 1;
  const double len = S.s.back();
  std::vector<double> size(m + 1), phi(m + 1, 0.0);
  for (int i = 0; i <= m; ++i) {
    size[i] = std::min({S.size[i], vsize_[S.va] + grade_ * S.s[i], vsize_[S.vb] + grade_ * (len - S.s[i])});
    size[i] = std::max(size[i], 1e-12);
  }
  // size also graded along the edge (a local curvature peak spreads out)
  for (int i = 1; i <= m; ++i) size[i] = std::min(size[i], size[i - 1] + grade_ * (S.s[i] - S.s[i - 1]));
  for (int i = m - 1; i >= 0; --i) size[i] = std::min(size[i], size[i + 1] + grade_ * (S.s[i + 1] - S.s[i]));
  for (int i = 1; i <= m; ++i) phi[i] = phi[i - 1] + (S.s[i] - S.s[i - 1]) * 0.5 * (1 / size[i] + 1 / size[i - 1]);
  const bool increasing = S.t.back() >= S.t.front();
  auto phi_at = [&](double t) {  // phi at parameter t, linear between samples
    double x = (t - S.t.front()) / (S.t.back() - S.t.front()) * m;
    if (!increasing) x = (S.t.front() - t) / (S.t.front() - S.t.back()) * m;
    x = std::clamp(x, 0.0, static_cast<double>(m));
    const int i = std::min(m - 1, static_cast<int>(x));
    return phi[i] + (x - i) * (phi[i + 1] - phi[i]);
  };
  auto t_at = [&](double target) {  // inverse of phi
    int j = static_cast<int>(std::upper_bound(phi.begin(), phi.end(), target) - phi.begin()) - 1;
    j = std::clamp(j, 0, m - 1);
    const double w = phi[j + 1] > phi[j] ? (target - phi[j]) / (phi[j + 1] - phi[j]) : 0.5;
    return S.t[j] + std::clamp(w, 0.0, 1.0) * (S.t[j + 1] - S.t[j]);
  };
  // break points: the ends and the fixed nodes, in order along the edge
  std::vector<std::pair<double, int>> breaks{{S.t.front(), vertex_node_[S.va]}};
  std::vector<std::pair<double, int>> fixed = fixed_[e];
  std::sort(fixed.begin(), fixed.end(),
            [&](const auto& a, const auto& b) { return increasing ? a.first < b.first : a.first > b.first; });
  for (const auto& fx : fixed)
    if (fx.second != vertex_node_[S.va] && fx.second != vertex_node_[S.vb]) breaks.push_back(fx);
  breaks.push_back({S.t.back(), vertex_node_[S.vb]});
  const int pieces = static_cast<int>(breaks.size()) - 1;
  std::vector<int> count(pieces);
  int total = 0;
  for (int k = 0; k < pieces; ++k) {
    const double dphi = phi_at(breaks[k + 1].first) - phi_at(breaks[k].first);
    count[k] = std::max(1, static_cast<int>(std::ceil(dphi - 0.3)));
    total += count[k];
  }
  if (S.va == S.vb)  // a closed edge needs at least three segments
    for (; total < 3; ++total) ++*std::max_element(count.begin(), count.end());
  std::vector<std::pair<double, int>> out{breaks[0]};
  for (int k = 0; k < pieces; ++k) {
    const double p0 = phi_at(breaks[k].first), p1 = phi_at(breaks[k + 1].first);
    for (int i = 1; i < count[k]; ++i) out.push_back({t_at(p0 + (p1 - p0) * i / count[k]), -1});
    out.push_back(breaks[k + 1]);
  }
  return out;
}

void ModelSurface::discretise(int e, const Division& d) {
  BRepAdaptor_Curve c(TopoDS::Edge(topo_.edges(e + 1).Oriented(TopAbs_FORWARD)));
  std::vector<double>& par = edge_param_[e];
  std::vector<int>& ids = edge_node_[e];
  par.clear(), ids.clear();
  for (const auto& [t, node] : d) {
    par.push_back(t);
    if (node >= 0) {
      ids.push_back(node);
    } else {
      const gp_Pnt p = c.Value(t);
      ids.push_back(new_node(p.X(), p.Y(), p.Z()));
    }
  }
}

// A vertex's size becomes the length of the shortest segment next to it when that is clearly
// shorter: an edge a little longer than the size is cut into pieces shorter than the size, and
// the edges meeting it at a vertex then start from that length instead of the full size (a
// 2 mm side at size 1.28 gets two pieces of 1 mm; the side meeting it at a right angle
// started at 1.25 mm, a corner triangle of 39°; now ~1 mm, 45°). One pass, then graded again.
// Returns the division of every free edge it made, with the vertex sizes it was made at.
std::vector<ModelSurface::EdgeDivision> ModelSurface::match_vertex_sizes() {
  std::vector<EdgeDivision> made(topo_.num_edges());
  bool changed = false;
  for (int e = 0; e < topo_.num_edges(); ++e) {
    if (topo_.edge_degenerate[e] || edge_kind_[e] != EdgeKind::Free) continue;
    const EdgeSamples& S = samples_[e];
    made[e] = {division(e), vsize_[S.va], vsize_[S.vb]};
    const Division& d = made[e].at;
    // one segment: its length is already below the vertex sizes; many: the rounding is spread
    if (d.size() < 3 || d.size() > 4) continue;
    BRepAdaptor_Curve c(TopoDS::Edge(topo_.edges(e + 1).Oriented(TopAbs_FORWARD)));
    const double first = c.Value(d[0].first).Distance(c.Value(d[1].first));
    const double last = c.Value(d[d.size() - 2].first).Distance(c.Value(d.back().first));
    for (auto [v, l] : {std::pair<int, double>{S.va, first}, std::pair<int, double>{S.vb, last}})
      if (l < 0.85 * vsize_[v]) vsize_[v] = std::max(l, hmin_), changed = true;
  }
  if (changed) grade_vertex_sizes();
  return made;
}

// Vertex sizes limited by the gradation across edges (relaxed to a fixed point).
void ModelSurface::grade_vertex_sizes() {
  for (bool changed = true; changed;) {
    changed = false;
    for (int e = 0; e < topo_.num_edges(); ++e) {
      const EdgeSamples& S = samples_[e];
      if (S.va < 0) continue;
      const double len = S.s.back();
      for (auto [x, y] : {std::pair<int, int>{S.va, S.vb}, std::pair<int, int>{S.vb, S.va}})
        if (vsize_[x] > vsize_[y] + grade_ * len * 1.0000001) vsize_[x] = vsize_[y] + grade_ * len, changed = true;
    }
  }
}

// The boundary of face f in its scaled parameters: local nodes (a seam's nodes appear twice,
// at both ends of the period), their global numbers, directed segments with the face on
// their left, and the B-Rep edge of each segment.
ModelSurface::Loops ModelSurface::face_loops(int f) const { return face_loops(f, geo_[f]); }

ModelSurface::Loops ModelSurface::face_loops(int f, const FaceGeometry& g) const {
  Loops L;
  const TopoDS_Face fwd = TopoDS::Face(topo_.faces(f + 1).Oriented(TopAbs_FORWARD));
  double u0, u1, v0, v1;
  BRepTools::UVBounds(fwd, u0, u1, v0, v1);
  const double tol = 1e-6 * std::hypot((u1 - u0) * g.su, (v1 - v0) * g.sv);
  std::unordered_map<int, std::vector<int>> locals;  // global node -> its local copies (seams)
  auto local_node = [&](int gid, double u, double v) {
    for (int l : locals[gid])
      if (std::hypot(L.uv[l][0] - u, L.uv[l][1] - v) <= std::max(tol, 1e-3 * face_size_[f])) return l;
    L.uv.push_back({u, v});
    L.global.push_back(gid);
    locals[gid].push_back(static_cast<int>(L.uv.size()) - 1);
    return static_cast<int>(L.uv.size()) - 1;
  };
  for (TopExp_Explorer ex(fwd, TopAbs_EDGE); ex.More(); ex.Next()) {
    const TopoDS_Edge E = TopoDS::Edge(ex.Current());
    const int e = topo_.edges.FindIndex(E) - 1;
    double pf, pl;
    Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(E, fwd, pf, pl);
    if (pc.IsNull() || e < 0) continue;
    std::vector<double> par = edge_param_[e];
    std::vector<int> ids = edge_node_[e];
    if (topo_.edge_degenerate[e]) {
      // A collapsed edge (cone apex, sphere pole): a segment in the parameters, one node
      // in space. Its pieces all carry the vertex's node; the triangles that collapse onto
      // it are dropped, which leaves a fan around the apex.
      TopoDS_Vertex va, vb;
      TopExp::Vertices(E, va, vb);
      const int vid = vertex_node_[topo_.vertices.FindIndex(va) - 1];
      // as many pieces as the fan needs for angles of about 50° at the apex: the angle the
      // surface sweeps around it, from the derivative across the collapsed edge
      const int n =
          std::clamp(static_cast<int>(std::ceil(apex_angle(fwd, pc, pf, pl) / (50.0 * M_PI / 180))), 2, kMaxApexPieces);
      par.clear();
      ids.assign(n + 1, vid);
      for (int i = 0; i <= n; ++i) par.push_back(pf + (pl - pf) * i / n);
    }
    std::vector<int> loc(par.size());
    for (size_t i = 0; i < par.size(); ++i) {
      gp_Pnt2d q = pc->Value(par[i]);
      loc[i] = local_node(ids[i], q.X() * g.su, q.Y() * g.sv);
    }
    const bool forward = E.Orientation() == TopAbs_FORWARD;
    for (size_t i = 0; i + 1 < loc.size(); ++i) {
      L.segs.push_back(forward ? std::array<int, 2>{loc[i], loc[i + 1]} : std::array<int, 2>{loc[i + 1], loc[i]});
      L.seg_edge.push_back(e);
      L.seg_piece.push_back(topo_.edge_degenerate[e] ? -1 : static_cast<int>(i));
    }
  }
  return L;
}

void ModelSurface::mesh_edges(const Progress& progress) {
  for (int v = 0; v < topo_.num_vertices(); ++v)
    if (vertex_node_[v] < 0) throw Error(ErrorCode::Internal, "mesh_edges: a vertex has no node yet");
  const std::vector<EdgeDivision> made = match_vertex_sizes();
  for (int e = 0; e < topo_.num_edges(); ++e) {
    if (topo_.edge_degenerate[e] || edge_kind_[e] != EdgeKind::Free) continue;
    // the division match_vertex_sizes made serves unless its vertices' sizes changed since
    // (a division depends on nothing else that changes here)
    const EdgeSamples& S = samples_[e];
    const EdgeDivision& d = made[e];
    discretise(e, d.size_a == vsize_[S.va] && d.size_b == vsize_[S.vb] ? d.at : division(e));
  }
  for (int e = 0; e < topo_.num_edges(); ++e)
    if (edge_kind_[e] == EdgeKind::Alias) refresh_alias(e);
  split_by_proximity(progress);
}

// Proximity: where two boundary segments of a face cross in its parameters or come closer
// than a third of their length (thin strips, nearly tangent edges), the polygon the front
// starts from would cross itself or leave no room; those pieces of their edges are split at
// their middle, locally, until no face has such a pair (or the floor is reached). Pieces longer
// than the face's size field there are split too. Given edges are never split; a piece of an
// aliased edge is split on the edge it copies. Each round looks again only at the faces one of
// whose edges was split.
// The pieces at the sharp corners are then made the same length (match_corner_pieces) and the
// faces that changed looked at again, up to three times.
void ModelSurface::split_by_proximity(const Progress& progress) {
  const SharpCorners corners = sharp_corners();
  std::vector<char> stale(topo_.num_faces(), 1);
  for (int pass = 0; pass < 3; ++pass) {
    split_rounds(corners, stale, progress);
    if (!match_corner_pieces(corners, stale)) break;
  }
}

// Up to ten rounds of proximity splits over the stale faces (see split_by_proximity).
void ModelSurface::split_rounds(const SharpCorners& corners, std::vector<char>& stale, const Progress& progress) {
  const int nf = topo_.num_faces();
  for (int round = 0; round < 10; ++round) {
    PieceSplits splits{std::vector<std::vector<int>>(topo_.num_edges()), false,
                       std::vector<char>(topo_.num_edges(), 0)};
    for (int f = 0; f < nf; ++f) {
      if (!stale[f] || face_given_[f]) continue;
      progress.check_cancel("surface meshing");
      stale[f] = 0;
      const Loops L = face_loops(f);
      const SegmentBoxes boxes(L);
      mark_long_pieces(f, L, boxes, corners, splits);
      mark_close_pieces(L, boxes, corners, splits);
    }
    if (!splits.any) break;
    for (int e = 0; e < topo_.num_edges(); ++e) split_close_[e] |= splits.close[e];
    split_pieces(splits.pieces, stale);
  }
}

ModelSurface::SegmentBoxes::SegmentBoxes(const Loops& L) {
  const size_t ns = L.segs.size();
  order.resize(ns), xlo.resize(ns), xhi.resize(ns), ylo.resize(ns), yhi.resize(ns), len.resize(ns);
  for (size_t i = 0; i < ns; ++i) {
    const auto& A = L.uv[L.segs[i][0]];
    const auto& B = L.uv[L.segs[i][1]];
    len[i] = std::hypot(B[0] - A[0], B[1] - A[1]);
    xlo[i] = std::min(A[0], B[0]), xhi[i] = std::max(A[0], B[0]);
    ylo[i] = std::min(A[1], B[1]), yhi[i] = std::max(A[1], B[1]);
    order[i] = static_cast<int>(i);
  }
  std::sort(order.begin(), order.end(), [&](int p, int q) { return xlo[p] < xlo[q]; });
}

// (edge, piece) of the edge a piece's splits go to: itself, or the free edge an alias copies;
// (-1, -1) when it may not be split (a given edge, or an alias of one).
std::pair<int, int> ModelSurface::free_piece(int e, int piece) const {
  if (piece < 0 || edge_kind_[e] == EdgeKind::Given) return {-1, -1};
  if (edge_kind_[e] == EdgeKind::Alias) {
    const auto [rep, reversed] = alias_of_[e];
    if (edge_kind_[rep] != EdgeKind::Free) return {-1, -1};
    if (reversed) piece = static_cast<int>(edge_node_[e].size()) - 2 - piece;
    e = rep;
  }
  return {e, piece};
}

// The two pieces at a corner of a face sharper than kNeedleAngle (measured on the pieces
// themselves, in the face's scaled parameters, where the face lies left of its loops) are
// not split, in any face, unless they cross another piece: one needle triangle takes the
// corner's angle (NIST 1's 11° slots, arcs tangent to a line). The pieces beyond are split
// by the rules below like any others, which grades them away from the corner. Cusps (an arc
// leaving a line tangentially, NIST 1's 4.5° on the pieces) are no exception: left unsplit
// near the cusp, the strip beyond the corner's needle was too thin for its pieces and the
// front closed it with caps (159°, under tets of radius ratio 0.087).
ModelSurface::SharpCorners ModelSurface::sharp_corners() const {
  SharpCorners sc;
  sc.needle_end.assign(topo_.num_edges(), {0, 0});
  for (int f = 0; f < topo_.num_faces(); ++f) {
    if (face_given_[f]) continue;
    const Loops L = face_loops(f);
    std::unordered_map<int, int> in, out;  // local node -> the piece ending / starting there
    std::unordered_set<int> many;
    for (size_t i = 0; i < L.segs.size(); ++i) {
      if (!in.emplace(L.segs[i][1], static_cast<int>(i)).second) many.insert(L.segs[i][1]);
      if (!out.emplace(L.segs[i][0], static_cast<int>(i)).second) many.insert(L.segs[i][0]);
    }
    for (const auto& [node, a] : in) {
      const auto it = out.find(node);
      if (it == out.end() || many.count(node)) continue;
      const int b = it->second;
      const auto &P = L.uv[L.segs[a][0]], &Q = L.uv[node], &R = L.uv[L.segs[b][1]];
      const double d1[2] = {Q[0] - P[0], Q[1] - P[1]}, d2[2] = {R[0] - Q[0], R[1] - Q[1]};
      const double turn = std::atan2(d1[0] * d2[1] - d1[1] * d2[0], d1[0] * d2[0] + d1[1] * d2[1]);
      const double corner = M_PI - turn;
      if (corner >= kNeedleAngle) continue;
      sc.all.push_back({L.global[node], {L.seg_edge[a], L.seg_edge[b]}});
      for (int sgm : {a, b}) {
        const auto [e, piece] = free_piece(L.seg_edge[sgm], L.seg_piece[sgm]);
        if (e < 0) continue;
        if (piece == 0) sc.needle_end[e][0] = 1;
        if (piece + 2 == static_cast<int>(edge_node_[e].size())) sc.needle_end[e][1] = 1;
      }
    }
  }
  return sc;
}

// Marks segment s of the loops L for a split at its middle (on the edge free_piece names),
// unless it is a needle corner's piece (and does not cross) or already at the floor length.
void ModelSurface::mark_piece(const Loops& L, int s, bool crossing, const SharpCorners& corners, PieceSplits& splits,
                              bool close) const {
  const auto [e, piece] = free_piece(L.seg_edge[s], L.seg_piece[s]);
  if (e < 0) return;
  const bool needle = (piece == 0 && corners.needle_end[e][0]) ||
                      (piece + 2 == static_cast<int>(edge_node_[e].size()) && corners.needle_end[e][1]);
  if (!crossing && needle) return;
  const auto& ids = edge_node_[e];
  const double l3 = std::sqrt(sqdist(nodes_[ids[piece]], nodes_[ids[piece + 1]]));
  if (l3 > hmin_ / 8) splits.pieces[e].push_back(piece), splits.any = true, splits.close[e] |= close ? 1 : 0;
}

// Pieces longer than 1.5 times the face's size field at their middle (finer features nearby
// in the face, e.g. a small hole close to a long straight edge).
void ModelSurface::mark_long_pieces(int f, const Loops& L, const SegmentBoxes& boxes, const SharpCorners& corners,
                                    PieceSplits& splits) const {
  const PointSizeField fine(fine_points(L.uv, L.segs, face_size_[f]), face_size_[f], grade_);
  for (size_t i = 0; i < L.segs.size(); ++i) {
    const auto& A = L.uv[L.segs[i][0]];
    const auto& B = L.uv[L.segs[i][1]];
    const double mid[2] = {0.5 * (A[0] + B[0]), 0.5 * (A[1] + B[1])};
    if (boxes.len[i] > 1.5 * thin_size_[f].size_at(mid, fine.size_at(mid, face_size_[f])))
      mark_piece(L, static_cast<int>(i), false, corners, splits);
  }
}

// Pairs of pieces of a face that cross or come closer than a third of the longer: the longer
// one leaves no room (both when they cross).
void ModelSurface::mark_close_pieces(const Loops& L, const SegmentBoxes& boxes, const SharpCorners& corners,
                                     PieceSplits& splits) const {
  const size_t ns = L.segs.size();
  const std::vector<double>& len = boxes.len;
  for (size_t oi = 0; oi < ns; ++oi) {
    const int i = boxes.order[oi];
    for (size_t oj = oi + 1; oj < ns; ++oj) {
      const int j = boxes.order[oj];
      const double gap = std::max(len[i], len[j]) / 3;
      if (boxes.xlo[j] > boxes.xhi[i] + gap) break;
      if (boxes.ylo[j] > boxes.yhi[i] + gap || boxes.ylo[i] > boxes.yhi[j] + gap) continue;
      const auto &si = L.segs[i], &sj = L.segs[j];
      if (si[0] == sj[0] || si[0] == sj[1] || si[1] == sj[0] || si[1] == sj[1]) continue;
      const auto &A = L.uv[si[0]], &B = L.uv[si[1]], &C = L.uv[sj[0]], &D = L.uv[sj[1]];
      const bool cross = segments_meet(A, B, C, D);
      const double d = cross ? 0.0
                             : std::min({point_segment_distance(A, C, D), point_segment_distance(B, C, D),
                                         point_segment_distance(C, A, B), point_segment_distance(D, A, B)});
      if (d >= gap) continue;
      if (cross || len[i] >= 0.7 * len[j]) mark_piece(L, i, cross, corners, splits, true);
      if (cross || len[j] >= 0.7 * len[i]) mark_piece(L, j, cross, corners, splits, true);
    }
  }
}

// Splits the marked pieces of each edge at their parameter's middle, refreshes the aliases of
// split edges, and marks stale the faces one of whose edges changed.
void ModelSurface::split_pieces(std::vector<std::vector<int>>& split, std::vector<char>& stale) {
  const int ne = topo_.num_edges();
  std::vector<char> changed(ne, 0);
  for (int e = 0; e < ne; ++e) {
    if (split[e].empty()) continue;
    changed[e] = 1;
    std::sort(split[e].begin(), split[e].end());
    split[e].erase(std::unique(split[e].begin(), split[e].end()), split[e].end());
    BRepAdaptor_Curve c(TopoDS::Edge(topo_.edges(e + 1).Oriented(TopAbs_FORWARD)));
    for (auto it = split[e].rbegin(); it != split[e].rend(); ++it) {
      const int k = *it;
      const double t = 0.5 * (edge_param_[e][k] + edge_param_[e][k + 1]);
      const gp_Pnt p = c.Value(t);
      edge_param_[e].insert(edge_param_[e].begin() + k + 1, t);
      edge_node_[e].insert(edge_node_[e].begin() + k + 1, new_node(p.X(), p.Y(), p.Z()));
    }
  }
  edges_changed(changed, stale);
}

// After the nodes of the edges marked in `changed` moved or grew: their aliases copy them
// again and every face on a changed edge is marked stale.
void ModelSurface::edges_changed(const std::vector<char>& changed_edges, std::vector<char>& stale) {
  std::vector<char> changed = changed_edges;
  for (int e = 0; e < topo_.num_edges(); ++e)
    if (edge_kind_[e] == EdgeKind::Alias && changed[alias_of_[e][0]]) refresh_alias(e), changed[e] = 1;
  for (int f = 0; f < topo_.num_faces(); ++f)
    for (const int* e = topo_.face_edges.begin(f); e != topo_.face_edges.end(f) && !stale[f]; ++e)
      stale[f] = changed[*e];
}

// The piece of edge e at its end node `node`, on the free edge that holds its nodes (itself,
// or the free edge it is an alias of): (that edge, index in its nodes of the piece's other
// node); (-1, -1) when e is given, an alias of a given edge, closed on `node` or not ending there.
std::array<int, 2> ModelSurface::corner_piece(int e, int node) const {
  if (edge_kind_[e] == EdgeKind::Given) return {-1, -1};
  if (edge_kind_[e] == EdgeKind::Alias) e = alias_of_[e][0];
  if (edge_kind_[e] != EdgeKind::Free) return {-1, -1};
  const std::vector<int>& ids = edge_node_[e];
  const int n = static_cast<int>(ids.size());
  if (n < 2 || (ids.front() == node) == (ids.back() == node)) return {-1, -1};
  return {e, ids.front() == node ? 1 : n - 2};
}

// The two pieces at each sharp corner of a face (needle or cusp) made the same length, the
// shorter one's, when the triangle closing the corner over them would have an angle above
// kCapAngle: at a corner of angle α, pieces of lengths a > b give a cap, not a needle, once a − b
// is more than a small share of α·b — NIST 1's fillet arcs leave straight edges tangentially,
// where pieces of 2.34 and 1.96 mm at 5.6° made a triangle with a 166° angle (radius ratio
// 0.028) under tets of 0.038; at equal lengths the corner's triangle is the needle its angle
// asks for (0.19). The longer piece gets a node on its curve at the shorter's length from the
// corner, or, when what would be left of it is under half the shorter and the piece's other
// node is neither a vertex nor a fixed node, that node moves there. Given edges stay as they
// are. Returns whether any edge changed (aliases refreshed, faces on it marked stale).
bool ModelSurface::match_corner_pieces(const SharpCorners& corners, std::vector<char>& stale) {
  std::vector<char> changed(topo_.num_edges(), 0);
  bool any = false;
  for (const SharpCorners::Corner& c : corners.all) {
    const std::array<int, 2> pa = corner_piece(c.edges[0], c.node), pb = corner_piece(c.edges[1], c.node);
    if (pa[0] < 0 || pb[0] < 0 || pa[0] == pb[0]) continue;
    const auto& V = nodes_[c.node];
    const auto& A = nodes_[edge_node_[pa[0]][pa[1]]];
    const auto& B = nodes_[edge_node_[pb[0]][pb[1]]];
    const double la = std::sqrt(sqdist(V, A)), lb = std::sqrt(sqdist(V, B)), ab = std::sqrt(sqdist(A, B));
    // the largest angle of the corner's triangle: at the far end of the shorter piece
    const double s = std::min(la, lb), l = std::max(la, lb);
    const double cos_far = (s * s + ab * ab - l * l) / (2 * s * ab + 1e-300);
    if (s <= 0 || ab <= 0 || cos_far > std::cos(kCapAngle)) continue;
    const auto [e, far] = la > lb ? pa : pb;
    std::vector<int>& ids = edge_node_[e];
    std::vector<double>& par = edge_param_[e];
    const int at = far == 1 ? 0 : far + 1;  // index of the corner's node
    BRepAdaptor_Curve curve(TopoDS::Edge(topo_.edges(e + 1).Oriented(TopAbs_FORWARD)));
    double lo = 0, hi = 1;  // share of the piece's parameter range: distance from the corner = s
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      const gp_Pnt p = curve.Value(par[at] + mid * (par[far] - par[at]));
      (p.Distance(gp_Pnt(V[0], V[1], V[2])) < s ? lo : hi) = mid;
    }
    const double t = par[at] + 0.5 * (lo + hi) * (par[far] - par[at]);
    const gp_Pnt p = curve.Value(t);
    const bool vertex = far == 0 || far + 1 == static_cast<int>(ids.size());
    const bool fixed = std::any_of(fixed_[e].begin(), fixed_[e].end(), [&](const auto& x) { return x.second == ids[far]; });
    if (l - s < 0.5 * s && !vertex && !fixed) {
      nodes_[ids[far]] = {p.X(), p.Y(), p.Z()};
      par[far] = t;
    } else {
      const int pos = far == 1 ? 1 : far + 1;  // between the corner's node and the far one
      par.insert(par.begin() + pos, t);
      ids.insert(ids.begin() + pos, new_node(p.X(), p.Y(), p.Z()));
    }
    changed[e] = 1, any = true;
  }
  if (any) edges_changed(changed, stale);
  return any;
}

const char* size_reason_name(SizeReason r) {
  switch (r) {
    case SizeReason::MaxSize:
      return "max size";
    case SizeReason::Curvature:
      return "curvature";
    case SizeReason::MinSize:
      return "min size";
    case SizeReason::Neighbour:
      return "gradation from a neighbour";
    case SizeReason::ShortEdge:
      return "short edge";
    case SizeReason::Proximity:
      return "proximity";
    case SizeReason::WallThickness:
      return "wall thickness";
    case SizeReason::NonDesign:
      return "non-design solid";
  }
  return "?";
}

std::vector<FaceSize> ModelSurface::face_sizes() const {
  std::vector<FaceSize> out;
  for (int f = 0; f < topo_.num_faces(); ++f) out.push_back(face_size_reason(f));
  return out;
}

// Face f's own size and its rule, then the finer candidates: a thin wall's size, boundary
// pieces below 0.7 of the own size (short edge: the piece is a whole edge; proximity: its
// edge was split for two close loops; non-design: it ends at a node another model fixed;
// otherwise graded from a neighbour) and the constraint segments.
FaceSize ModelSurface::face_size_reason(int f) const {
  FaceSize r;
  r.face = f + 1;
  r.size = r.face_size = face_size_[f];
  if (geo_[f].kmax > 0 && params_.max_angle / geo_[f].kmax < h_)
    r.reason = params_.max_angle / geo_[f].kmax <= hmin_ ? SizeReason::MinSize : SizeReason::Curvature;
  auto consider = [&r](double size, SizeReason why) {
    if (size < r.size) r.size = size, r.reason = why;
  };
  if (!thin_size_[f].empty()) consider(thin_size_[f].smallest(), SizeReason::WallThickness);
  const double fine = 0.7 * face_size_[f];
  auto length = [&](int a, int b) { return std::sqrt(sqdist(nodes_[a], nodes_[b])); };
  for (const int* e = topo_.face_edges.begin(f); e != topo_.face_edges.end(f); ++e) {
    const std::vector<int>& ids = edge_node_[*e];
    if (topo_.edge_degenerate[*e] || ids.size() < 2) continue;
    std::unordered_set<int> fixed;
    for (const auto& fx : fixed_[*e]) fixed.insert(fx.second);
    for (size_t i = 0; i + 1 < ids.size(); ++i) {
      const double l = length(ids[i], ids[i + 1]);
      if (l >= fine) continue;
      SizeReason why = SizeReason::Neighbour;
      if (ids.size() == 2)
        why = SizeReason::ShortEdge;
      else if (fixed.count(ids[i]) || fixed.count(ids[i + 1]) || edge_kind_[*e] == EdgeKind::Given)
        why = SizeReason::NonDesign;
      else if (split_close_[*e])
        why = SizeReason::Proximity;
      consider(l, why);
    }
  }
  for (const auto& c : constraint_[f]) consider(length(c[0], c[1]), SizeReason::NonDesign);
  return r;
}

void ModelSurface::constrain_face(int f, int a, int b) {
  if (a == b) return;
  for (const auto& s : constraint_[f])
    if ((s[0] == a && s[1] == b) || (s[0] == b && s[1] == a)) return;
  constraint_[f].push_back({a, b});
}

void ModelSurface::add_face_node(int f, int n) {
  if (std::find(face_extra_nodes_[f].begin(), face_extra_nodes_[f].end(), n) == face_extra_nodes_[f].end())
    face_extra_nodes_[f].push_back(n);
}

void ModelSurface::set_face_mesh(int f, std::vector<std::array<int, 3>> tris) {
  face_tris_[f] = std::move(tris);
  face_given_[f] = 1;
}

void ModelSurface::alias_face(int f, int src, bool reversed) { face_alias_[f] = {src, reversed ? 1 : 0}; }

double face_cpu_seconds(double triangles) { return 20.0 + std::max(0.0, triangles) / 2000.0; }

namespace {

/// `progress` whose cancelled() also answers yes once the calling thread has used `seconds`
/// of CPU from now (<= 0: never); `expired` is set when that is why.
Progress within_face_budget(const Progress& progress, double seconds, const std::shared_ptr<bool>& expired) {
  if (seconds <= 0) return progress;
  Progress timed = progress;
  const double stop_at = thread_cpu_seconds() + seconds;
  timed.cancelled = [progress, stop_at, expired] {
    if (progress.cancelled && progress.cancelled()) return true;
    *expired = *expired || thread_cpu_seconds() > stop_at;
    return *expired;
  };
  return timed;
}

}  // namespace

// The CPU seconds one way of filling face f may take: the given budget, or the automatic one
// for the triangles its area asks for at its own size (equilateral triangles of that side).
double ModelSurface::face_budget(int f) const {
  if (params_.face_cpu_seconds != 0) return params_.face_cpu_seconds;
  const double h = face_size_[f];
  return face_cpu_seconds(h > 0 ? topo_.face_area[f] / (0.433 * h * h) : 0.0);
}

// Step 9 / 11 for one face: the front fills the face's loops in its scaled parameters,
// honouring the constraint segments and nodes, then the triangles are improved on the
// surface (constraint nodes and segments fixed). A face the front cannot fill is retried
// (face_attempts), each way within the face's CPU budget (face_budget); the error kept is
// the first attempt's, with the ways tried named.
void ModelSurface::mesh_face(int f, const Progress& prog, FaceOut& out) const {
  const std::vector<FaceAttempt> attempts = face_attempts(f);
  const double seconds = face_budget(f);
  std::string first_error, tried;
  for (const FaceAttempt& a : attempts) {
    auto expired = std::make_shared<bool>(false);
    try {
      mesh_face_once(f, a, within_face_budget(prog, seconds, expired), out);
      out.attempt = a.name;
      return;
    } catch (const Error& err) {
      if (err.code() == ErrorCode::Cancelled && !*expired) throw;
      std::string why = err.what();
      if (*expired) {
        std::ostringstream s;
        s << "the face's mesh did not close within its budget of " << std::ceil(seconds) << " s of computing";
        why = s.str();
      }
      if (first_error.empty()) first_error = why;
      tried += std::string(tried.empty() ? "" : ", ") + a.name + (*expired ? " (out of time)" : "");
    }
  }
  out.error = first_error + " (tried: " + tried +
              "); a larger size, or repairing the face in CAD (its trimming curves), may let it mesh";
}

// The ways a face is filled, in order (params.face_attempts picks some, for tests): its loops
// as measured; with the gaps between their edges' ends closed; in isotropic parameters (the
// mean of the two scales, for faces whose scaling varies much); in the unscaled parameters
// with the gaps closed; split in two along a parameter line through its middle, gaps closed.
std::vector<ModelSurface::FaceAttempt> ModelSurface::face_attempts(int f) const {
  const FaceGeometry& g = geo_[f];
  const double iso = std::sqrt(g.su * g.sv);
  const std::vector<FaceAttempt> all{{"as measured", g, false},
                                     {"loop gaps closed", g, true},
                                     {"isotropic scaling", {iso, iso, g.kmax}, true},
                                     {"unscaled parameters", {1, 1, g.kmax}, true},
                                     {"split along a parameter line", g, true, true}};
  if (params_.face_attempts.empty()) return all;
  std::vector<FaceAttempt> some;
  for (int k : params_.face_attempts)
    if (k >= 0 && k < static_cast<int>(all.size())) some.push_back(all[k]);
  return some;
}

// One attempt at face f: its input in the attempt's parameters, the front, then the surface
// improvement. Throws the front's Error when it cannot fill the face.
void ModelSurface::mesh_face_once(int f, const FaceAttempt& a, const Progress& prog, FaceOut& out) const {
  FaceInput in = face_input(f, a.geo);
  if (a.close_gaps) close_loop_gaps(in);
  if (a.split) add_split_line(f, in, face_size_[f]);
  const Loops& L = in.loops;
  FaceFrontInput front;
  front.P.resize(static_cast<long>(L.uv.size()), 2);
  for (size_t i = 0; i < L.uv.size(); ++i) front.P.row(static_cast<long>(i)) << L.uv[i][0], L.uv[i][1];
  front.boundary.resize(static_cast<long>(L.segs.size()), 2);
  for (size_t i = 0; i < L.segs.size(); ++i) front.boundary.row(static_cast<long>(i)) << L.segs[i][0], L.segs[i][1];
  front.segments.resize(static_cast<long>(in.csegs.size()), 2);
  for (size_t i = 0; i < in.csegs.size(); ++i)
    front.segments.row(static_cast<long>(i)) << in.csegs[i][0], in.csegs[i][1];
  front.isolated = in.isolated;
  FaceFrontParams fp = params_.front;
  // size: the face's, but near boundary and constraint pieces finer than that (split by
  // proximity, from a finer neighbour, or from the other model) it grows from their length
  // at the gradation rate, and inside thin walls from half their thickness (its raster is in
  // the measured scaling: q mapped back there)
  const double hf = face_size_[f];
  std::vector<std::array<int, 2>> all_segs = L.segs;
  all_segs.insert(all_segs.end(), in.csegs.begin(), in.csegs.end());
  const PointSizeField fine(fine_points(L.uv, all_segs, hf), hf, grade_);
  const SizeRaster& thin = thin_size_[f];
  const double back[2] = {geo_[f].su / a.geo.su, geo_[f].sv / a.geo.sv};
  fp.size = [hf, &fine, &thin, back](const double* q) {
    const double qm[2] = {q[0] * back[0], q[1] * back[1]};
    return thin.size_at(qm, fine.size_at(q, hf));
  };
  FaceFrontResult r = fill_face(front, fp, prog);
  improve_on_surface(f, a.geo, in, r, out);
}

// Loops whose edges' ends do not meet in the parameters (trimmed B-spline faces whose
// parameter curves leave gaps wider than the merge tolerance of face_loops): a node's copies
// that only end a segment and those that only start one are the two sides of such a gap,
// and each such pair (nearest first) becomes one node, also in the constraint segments and
// isolated nodes. A seam's copies are balanced and stay.
void ModelSurface::close_loop_gaps(FaceInput& in) {
  Loops& L = in.loops;
  const size_t n = L.uv.size();
  std::vector<int> balance(n, 0);
  for (const auto& sg : L.segs) ++balance[sg[0]], --balance[sg[1]];
  std::unordered_map<int, std::vector<int>> copies;  // global node -> its unbalanced local copies
  for (size_t l = 0; l < n; ++l)
    if (balance[l] != 0) copies[L.global[l]].push_back(static_cast<int>(l));
  std::vector<int> to(n);
  for (size_t l = 0; l < n; ++l) to[l] = static_cast<int>(l);
  for (auto& [gid, ls] : copies)
    for (int a : ls)
      if (balance[a] > 0) {
        int best = -1;
        double dbest = 1e300;
        for (int b : ls)
          if (balance[b] < 0 && to[b] == b) {
            const double d = std::hypot(L.uv[a][0] - L.uv[b][0], L.uv[a][1] - L.uv[b][1]);
            if (d < dbest) dbest = d, best = b;
          }
        if (best < 0) continue;
        to[best] = a;
        balance[a] += balance[best];
        balance[best] = 0;
      }
  for (auto& sg : L.segs) sg = {to[sg[0]], to[sg[1]]};
  for (auto& sg : in.csegs) sg = {to[sg[0]], to[sg[1]]};
  for (int& i : in.isolated) i = to[i];
}

namespace {

/// Where the line x[axis] = at crosses a loop segment: the other coordinate there, the segment
/// and whether the face lies on the side of larger coordinates just past it.
struct LineCrossing {
  double t;
  int seg;
  bool inside_above;
};

/// The crossings of the line x[axis] = at with the segments of L (face to their left), in
/// order along the line.
std::vector<LineCrossing> line_crossings(const std::vector<std::array<double, 2>>& uv,
                                         const std::vector<std::array<int, 2>>& segs, int axis, double at) {
  const int other = 1 - axis;
  std::vector<LineCrossing> out;
  for (size_t k = 0; k < segs.size(); ++k) {
    const auto &a = uv[segs[k][0]], &b = uv[segs[k][1]];
    const double da = a[axis] - at, db = b[axis] - at;
    if ((da < 0) == (db < 0)) continue;
    // the face is left of a -> b: above the line (larger `other`) where the segment runs
    // towards +axis for axis u, towards -axis for axis v
    const bool forward = db > da;
    out.push_back(
        {a[other] + (b[other] - a[other]) * da / (da - db), static_cast<int>(k), axis == 0 ? forward : !forward});
  }
  std::sort(out.begin(), out.end(), [](const LineCrossing& x, const LineCrossing& y) { return x.t < y.t; });
  return out;
}

/// Whether the segment a-b (local nodes) meets any segment of `segs` that does not end at a
/// or b: exact orientation tests; touching counts as meeting.
bool chord_meets(const std::vector<std::array<double, 2>>& uv, const std::vector<std::array<int, 2>>& segs, int a,
                 int b) {
  for (const auto& sg : segs) {
    if (sg[0] == a || sg[0] == b || sg[1] == a || sg[1] == b) continue;
    if (segments_meet(uv[a], uv[b], uv[sg[0]], uv[sg[1]])) return true;
  }
  return false;
}

}  // namespace

// The retry that splits face f in two: the parameter line through the middle of the loops'
// longer extent (in the face's scaled parameters), on its longest stretch inside the face,
// from the boundary node nearest one end of that stretch to the one nearest the other, as a
// chain of constraint segments of about length h. Its inner nodes are new nodes of the face
// (global -1), kept in place like the loops' nodes, so both halves the front fills share the
// one discretisation. Throws Error(MeshingFailed), naming the face, where no such chord lies
// inside it.
void ModelSurface::add_split_line(int f, FaceInput& in, double h) {
  Loops& L = in.loops;
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (const auto& sg : L.segs)
    for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], L.uv[sg[0]][k]), hi[k] = std::max(hi[k], L.uv[sg[0]][k]);
  const int axis = hi[0] - lo[0] >= hi[1] - lo[1] ? 0 : 1;
  const double mid = 0.5 * (lo[axis] + hi[axis]);
  const std::vector<LineCrossing> c = line_crossings(L.uv, L.segs, axis, mid);
  int best = -1;
  for (size_t k = 0; k + 1 < c.size(); ++k)
    if (c[k].inside_above && !c[k + 1].inside_above && (best < 0 || c[k + 1].t - c[k].t > c[best + 1].t - c[best].t))
      best = static_cast<int>(k);
  auto nearer_end = [&](const LineCrossing& x) {  // the crossed segment's end nearer the line
    const auto& sg = L.segs[x.seg];
    return std::abs(L.uv[sg[0]][axis] - mid) <= std::abs(L.uv[sg[1]][axis] - mid) ? sg[0] : sg[1];
  };
  const int a = best < 0 ? -1 : nearer_end(c[best]), b = best < 0 ? -1 : nearer_end(c[best + 1]);
  if (best < 0 || a == b || chord_meets(L.uv, L.segs, a, b) || chord_meets(L.uv, in.csegs, a, b))
    throw Error(ErrorCode::MeshingFailed,
                "face " + std::to_string(f + 1) + ": no parameter line through its middle splits it in two");
  const double len = std::hypot(L.uv[b][0] - L.uv[a][0], L.uv[b][1] - L.uv[a][1]);
  // two copies of one node (across a periodic face): the chord closes a loop on the surface,
  // at least 3 pieces so that no two of its edges join the same two nodes
  const int n = std::max(L.global[a] == L.global[b] ? 3 : 2, static_cast<int>(std::ceil(len / h)));
  int prev = a;
  for (int i = 1; i < n; ++i) {
    const double t = static_cast<double>(i) / n;
    L.uv.push_back({L.uv[a][0] + t * (L.uv[b][0] - L.uv[a][0]), L.uv[a][1] + t * (L.uv[b][1] - L.uv[a][1])});
    L.global.push_back(-1);  // a node of this face alone, made when the face's mesh is taken
    const int cur = static_cast<int>(L.uv.size()) - 1;
    in.csegs.push_back({prev, cur});
    prev = cur;
  }
  in.csegs.push_back({prev, b});
}

// Face f's loops in its scaled parameters, then its constraint segments and nodes in the same
// local numbering: a boundary node takes its local copy (the one nearest the segment's other
// end on a seam), any other node its parameters by projection onto the surface (appended to
// the loops' nodes).
ModelSurface::FaceInput ModelSurface::face_input(int f, const FaceGeometry& g) const {
  const TopoDS_Face fwd = TopoDS::Face(topo_.faces(f + 1).Oriented(TopAbs_FORWARD));
  FaceInput in{face_loops(f, g), {}, {}};
  std::vector<std::array<double, 2>>& uv = in.loops.uv;
  std::vector<int>& global = in.loops.global;
  std::unordered_map<int, std::vector<int>> locals;
  for (size_t l = 0; l < global.size(); ++l) locals[global[l]].push_back(static_cast<int>(l));
  ShapeAnalysis_Surface sas(BRep_Tool::Surface(fwd));
  double u0, u1, v0, v1;
  BRepTools::UVBounds(fwd, u0, u1, v0, v1);
  auto project = [&](int n) {
    const auto& x = nodes_[n];
    gp_Pnt2d q = sas.ValueOfUV(gp_Pnt(x[0], x[1], x[2]), 1e-9);
    double u = q.X(), v = q.Y();
    const Handle(Geom_Surface)& s = sas.Surface();
    if (s->IsUPeriodic()) {
      const double T = s->UPeriod();
      while (u < u0 - 1e-9 * T) u += T;
      while (u > u1 + 1e-9 * T) u -= T;
    }
    if (s->IsVPeriodic()) {
      const double T = s->VPeriod();
      while (v < v0 - 1e-9 * T) v += T;
      while (v > v1 + 1e-9 * T) v -= T;
    }
    uv.push_back({u * g.su, v * g.sv});
    global.push_back(n);
    locals[n].push_back(static_cast<int>(uv.size()) - 1);
    return static_cast<int>(uv.size()) - 1;
  };
  auto local_of = [&](int n, int near) {
    auto it = locals.find(n);
    if (it == locals.end() || it->second.empty()) return project(n);
    int best = it->second[0];
    if (near >= 0)
      for (int l : it->second)
        if (std::hypot(uv[l][0] - uv[near][0], uv[l][1] - uv[near][1]) <
            std::hypot(uv[best][0] - uv[near][0], uv[best][1] - uv[near][1]))
          best = l;
    return best;
  };
  for (const auto& s : constraint_[f]) {
    const bool a_unique = locals.count(s[0]) && locals[s[0]].size() == 1;
    int a, b;
    if (a_unique || !locals.count(s[1])) {
      a = local_of(s[0], -1);
      b = local_of(s[1], a);
    } else {
      b = local_of(s[1], -1);
      a = local_of(s[0], b);
    }
    in.csegs.push_back({a, b});
  }
  for (int n : face_extra_nodes_[f])
    if (!locals.count(n)) in.isolated.push_back(local_of(n, -1));
  return in;
}

// Local optimisation of the front's triangles r judged on the surface; the face's input
// nodes stay, constraint segments are locked, and triangles collapsed on an apex keep their
// edges. Leaves the face's mesh in `out`.
void ModelSurface::improve_on_surface(int f, const FaceGeometry& g, const FaceInput& in, FaceFrontResult& r,
                                      FaceOut& out) const {
  const TopoDS_Face fwd = TopoDS::Face(topo_.faces(f + 1).Oriented(TopAbs_FORWARD));
  BRepAdaptor_Surface s(fwd, Standard_False);
  const double su = g.su, sv = g.sv;
  SurfaceEval eval = [&s, su, sv](const double* q, double* x, double* du, double* dv) {
    gp_Pnt p;
    gp_Vec a, b;
    s.D1(q[0] / su, q[1] / sv, p, a, b);
    x[0] = p.X(), x[1] = p.Y(), x[2] = p.Z();
    du[0] = a.X() / su, du[1] = a.Y() / su, du[2] = a.Z() / su;
    dv[0] = b.X() / sv, dv[1] = b.Y() / sv, dv[2] = b.Z() / sv;
  };
  const std::vector<int>& global = in.loops.global;
  std::vector<std::array<int, 2>> locked = in.csegs;
  const long nin = static_cast<long>(global.size());
  for (long t = 0; t < r.T.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = r.T(t, k), b = r.T(t, (k + 1) % 3), c = r.T(t, (k + 2) % 3);
      if (a < nin && b < nin && global[a] >= 0 && global[a] == global[b])
        locked.push_back({a, c}), locked.push_back({b, c});
    }
  optimize_on_surface(r.P, r.T, out.X, static_cast<int>(nin), eval, locked, params_.optimize_rounds);
  out.global = global;
  out.T = std::move(r.T);
}

void ModelSurface::mesh_faces(const Progress& progress) {
  const int nf = topo_.num_faces();
  // faces in parallel (largest first), merged in face order so the result does not depend
  // on the threads
  std::vector<int> order;
  std::vector<double> work(nf, 0.0);
  for (int f = 0; f < nf; ++f)
    if (!face_given_[f] && face_alias_[f][0] < 0) {
      order.push_back(f);
      work[f] = topo_.face_area[f] / (face_size_[f] * face_size_[f]);
    }
  std::sort(order.begin(), order.end(), [&](int x, int y) { return work[x] > work[y]; });
  std::vector<FaceOut> face_out(nf);
  parallel_tasks(order, thread_count(params_.threads), progress, "surface meshing",
                 [&](int f, const Progress& prog) { mesh_face(f, prog, face_out[f]); });
  for (int f = 0; f < nf; ++f) {
    if (face_given_[f] || face_alias_[f][0] >= 0) continue;
    take_face_mesh(f, face_out[f]);
    face_out[f] = FaceOut();
  }
  for (int f = 0; f < nf; ++f)
    if (face_alias_[f][0] >= 0) copy_aliased_face(f);
}

// A filled face's mesh into the pool: its own nodes that its triangles use become pool nodes
// (the optimiser's collapses leave some unused), its triangles turn out of the solid that holds
// the face, those collapsed on an apex are dropped. A face that failed is listed with its reason.
void ModelSurface::take_face_mesh(int f, const FaceOut& fo) {
  if (!fo.error.empty()) {
    failed_.push_back(f + 1);
    reasons_.push_back(fo.error);
    return;
  }
  if (fo.attempt != face_attempts(f).front().name) retried_.push_back({f + 1, fo.attempt});
  const long nin = static_cast<long>(fo.global.size());
  std::vector<int> to_global(fo.X.rows(), -1);
  for (long i = 0; i < nin; ++i) to_global[i] = fo.global[i];  // -1: a split line's node, made below
  for (long t = 0; t < fo.T.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int i = fo.T(t, k);
      if (to_global[i] < 0) to_global[i] = new_node(fo.X(i, 0), fo.X(i, 1), fo.X(i, 2));
    }
  const bool flip = topo_.faces(f + 1).Orientation() == TopAbs_REVERSED;
  auto& tris = face_tris_[f];
  tris.clear();
  for (long t = 0; t < fo.T.rows(); ++t) {
    std::array<int, 3> tri{to_global[fo.T(t, 0)], to_global[fo.T(t, 1)], to_global[fo.T(t, 2)]};
    if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;  // collapsed on an apex
    if (flip) std::swap(tri[1], tri[2]);
    tris.push_back(tri);
  }
}

// An aliased face (solids that touch): the source's triangles, after checking that their
// boundary is this face's boundary.
void ModelSurface::copy_aliased_face(int f) {
  const auto [src, reversed] = face_alias_[f];
  std::vector<std::array<int, 3>> tris = face_tris_[src];
  if (reversed)
    for (auto& t : tris) std::swap(t[1], t[2]);
  std::set<std::pair<int, int>> mine, theirs;
  const Loops L = face_loops(f);
  for (const auto& s : L.segs) mine.insert(std::minmax(L.global[s[0]], L.global[s[1]]));
  std::map<std::pair<int, int>, int> uses;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
  for (const auto& [e, n] : uses)
    if (n == 1) theirs.insert(e);
  if (tris.empty() || mine != theirs) {
    failed_.push_back(f + 1);
    std::ostringstream m;
    m << "Face" << f + 1 << " lies on Face" << src + 1
      << " but their boundaries differ (only identical touching faces are supported)";
    reasons_.push_back(m.str());
    return;
  }
  face_tris_[f] = std::move(tris);
}

std::vector<std::array<int, 3>> ModelSurface::solid_triangles(int s) const {
  std::vector<std::array<int, 3>> rows;
  for (const auto& [f, flip] : solid_faces(topo_, s))
    for (auto t : face_tris_[f - 1]) {
      if (flip) std::swap(t[1], t[2]);
      rows.push_back(t);
    }
  return rows;
}

SurfaceMesh ModelSurface::result() const {
  SurfaceMesh out;
  out.failed_faces = failed_;
  out.reasons = reasons_;
  const int nv = topo_.num_vertices();
  std::unordered_map<int, int> renum;
  std::vector<int> used;
  auto take = [&](int n) {
    auto [it, inserted] = renum.emplace(n, static_cast<int>(used.size()));
    if (inserted) used.push_back(n);
    return it->second;
  };
  for (int v = 0; v < nv; ++v) take(vertex_node_[v]);
  long nt = 0;
  for (const auto& tris : face_tris_) nt += static_cast<long>(tris.size());
  out.F.resize(nt, 3);
  out.face.resize(nt);
  long row = 0;
  for (int f = 0; f < topo_.num_faces(); ++f)
    for (const auto& t : face_tris_[f]) {
      out.F.row(row) << take(t[0]), take(t[1]), take(t[2]);
      out.face[row++] = f + 1;
    }
  out.V.resize(static_cast<long>(used.size()), 3);
  for (size_t i = 0; i < used.size(); ++i)
    out.V.row(static_cast<long>(i)) << nodes_[used[i]][0], nodes_[used[i]][1], nodes_[used[i]][2];
  return out;
}

SurfaceMesh mesh_surface(const brep::TopologyIndex& topo, const SurfaceMeshParams& params, const Progress& progress) {
  std::vector<std::array<double, 3>> nodes;
  ModelSurface model(topo, nodes, params);
  model.create_vertex_nodes();
  model.mesh_edges(progress);
  model.mesh_faces(progress);
  return model.result();
}

MatX3i solid_triangles(const brep::TopologyIndex& topo, const SurfaceMesh& mesh, int s) {
  std::map<int, bool> flip;
  for (const auto& [f, reversed] : solid_faces(topo, s)) flip[f] = reversed;
  std::vector<std::array<int, 3>> rows;
  for (long t = 0; t < mesh.F.rows(); ++t) {
    auto it = flip.find(mesh.face[t]);
    if (it == flip.end()) continue;
    if (it->second)
      rows.push_back({mesh.F(t, 0), mesh.F(t, 2), mesh.F(t, 1)});
    else
      rows.push_back({mesh.F(t, 0), mesh.F(t, 1), mesh.F(t, 2)});
  }
  MatX3i out(static_cast<long>(rows.size()), 3);
  for (size_t i = 0; i < rows.size(); ++i) out.row(i) << rows[i][0], rows[i][1], rows[i][2];
  return out;
}

long open_edges(const MatX3i& T) { return check_surface(T).unpaired_edges; }

std::vector<long> open_edges_per_solid(const brep::TopologyIndex& topo, const SurfaceMesh& mesh) {
  std::vector<long> result;
  for (int s = 0; s < topo.num_solids(); ++s) result.push_back(open_edges(solid_triangles(topo, mesh, s)));
  return result;
}

}  // namespace topopt::mesh
