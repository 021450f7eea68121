// Surface meshing by the B-Rep hierarchy (see surface_mesher.h).
#include "mesh/surface_mesher.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepAdaptor_Surface.hxx>
#include <BRepLProp_CLProps.hxx>
#include <BRepLProp_SLProps.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Geom2d_Curve.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Vertex.hxx>
#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <cmath>
#include <map>
#include <unordered_map>

#include "common/error.h"
#include "common/parallel.h"
#include "mesh/predicates.h"
#include "mesh/surface_optimize.h"

namespace topopt::mesh {
namespace {

/// What the faces need to know about a face's parametrisation: a per-direction scale making
/// lengths in (su·u, sv·v) approximate lengths on the surface, and the largest curvature.
struct FaceGeometry {
  double su = 1, sv = 1, kmax = 0;
};

FaceGeometry face_geometry(const TopoDS_Face& f) {
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

/// Size field near fine boundary pieces of a face: min(h, s_i + grade·|q − p_i|) over the
/// points (u, v, s_i), looked up in a uniform grid whose cells cover the reach of a point.
class PointGrid {
 public:
  PointGrid(std::vector<std::array<double, 3>> pts, double h, double grade) : pts_(std::move(pts)), grade_(grade) {
    if (pts_.empty()) return;
    double smin = h;
    lo_[0] = hi_[0] = pts_[0][0], lo_[1] = hi_[1] = pts_[0][1];
    for (const auto& p : pts_) {
      smin = std::min(smin, p[2]);
      lo_[0] = std::min(lo_[0], p[0]), hi_[0] = std::max(hi_[0], p[0]);
      lo_[1] = std::min(lo_[1], p[1]), hi_[1] = std::max(hi_[1], p[1]);
    }
    reach_ = (h - smin) / grade_;
    cell_ = std::max({reach_ / 2, (hi_[0] - lo_[0]) / 512, (hi_[1] - lo_[1]) / 512, 1e-300});
    nx_ = static_cast<long>((hi_[0] - lo_[0]) / cell_) + 1, ny_ = static_cast<long>((hi_[1] - lo_[1]) / cell_) + 1;
    start_.assign(nx_ * ny_ + 1, 0);
    for (const auto& p : pts_) ++start_[cell(p.data()) + 1];
    for (size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
    items_.resize(pts_.size());
    std::vector<long> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < pts_.size(); ++i) items_[fill[cell(pts_[i].data())]++] = static_cast<int>(i);
  }
  double size_at(const double* q, double h) const {
    if (pts_.empty()) return h;
    double s = h;
    const long i0 = std::max(0L, static_cast<long>(std::floor((q[0] - reach_ - lo_[0]) / cell_)));
    const long i1 = std::min(nx_ - 1, static_cast<long>(std::floor((q[0] + reach_ - lo_[0]) / cell_)));
    const long j0 = std::max(0L, static_cast<long>(std::floor((q[1] - reach_ - lo_[1]) / cell_)));
    const long j1 = std::min(ny_ - 1, static_cast<long>(std::floor((q[1] + reach_ - lo_[1]) / cell_)));
    for (long i = i0; i <= i1; ++i)
      for (long j = j0; j <= j1; ++j) {
        const long c = i * ny_ + j;
        for (long k = start_[c]; k < start_[c + 1]; ++k) {
          const auto& p = pts_[items_[k]];
          s = std::min(s, p[2] + grade_ * std::hypot(q[0] - p[0], q[1] - p[1]));
        }
      }
    return s;
  }

 private:
  long cell(const double* p) const {
    return static_cast<long>((p[0] - lo_[0]) / cell_) * ny_ + static_cast<long>((p[1] - lo_[1]) / cell_);
  }
  std::vector<std::array<double, 3>> pts_;
  double grade_, reach_ = 0, cell_ = 1, lo_[2] = {0, 0}, hi_[2] = {0, 0};
  long nx_ = 0, ny_ = 0;
  std::vector<long> start_;
  std::vector<int> items_;
};

/// Boundary nodes of a face whose spacing (mean length of their segments) is below 0.7 h:
/// (u, v, spacing), the sources of the face's graded size field.
std::vector<std::array<double, 3>> fine_points(const std::vector<std::array<double, 2>>& uv,
                                               const std::vector<std::array<int, 2>>& segs, double h) {
  std::vector<double> spacing(uv.size(), 0.0);
  std::vector<int> count(uv.size(), 0);
  for (const auto& sg : segs) {
    const double l = std::hypot(uv[sg[1]][0] - uv[sg[0]][0], uv[sg[1]][1] - uv[sg[0]][1]);
    for (int k : sg) spacing[k] += l, ++count[k];
  }
  std::vector<std::array<double, 3>> fine;
  for (size_t i = 0; i < uv.size(); ++i)
    if (count[i] && spacing[i] / count[i] < 0.7 * h) fine.push_back({uv[i][0], uv[i][1], spacing[i] / count[i]});
  return fine;
}

double sqdist(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
}

}  // namespace

SurfaceMesh mesh_surface(const brep::TopologyIndex& topo, const SurfaceMeshParams& params, const Progress& progress) {
  SurfaceMesh out;
  const double h = params.size > 0 ? params.size : topo.diagonal() / 50;
  const double hmin = params.min_size > 0 ? params.min_size : h / 10;
  const int nv = topo.num_vertices(), ne = topo.num_edges(), nf = topo.num_faces();
  std::vector<std::array<double, 3>> nodes;
  for (int v = 0; v < nv; ++v) nodes.push_back({topo.vertex_point(v, 0), topo.vertex_point(v, 1), topo.vertex_point(v, 2)});

  // ---- per face: parameter scaling and the size its curvature allows
  std::vector<FaceGeometry> geo(nf);
  std::vector<double> face_size(nf, h);
  for (int f = 0; f < nf; ++f) {
    geo[f] = face_geometry(TopoDS::Face(topo.faces(f + 1)));
    if (geo[f].kmax > 0) face_size[f] = std::clamp(params.max_angle / geo[f].kmax, hmin, h);
  }
  // ---- edges (step 5 for one model): each discretised once, vertices at its ends
  std::vector<double> edge_size(ne, h);
  for (int f = 0; f < nf; ++f)
    for (const int* e = topo.face_edges.begin(f); e != topo.face_edges.end(f); ++e)
      edge_size[*e] = std::min(edge_size[*e], face_size[f]);
  std::vector<std::vector<double>> edge_param(ne);
  std::vector<std::vector<int>> edge_node(ne);
  // Each edge sampled finely once: parameters, arc length, and the size allowed there (its
  // faces' sizes and its own local curvature).
  struct EdgeSamples {
    std::vector<double> t, s, size;
    int va = -1, vb = -1;
  };
  std::vector<EdgeSamples> samples(ne);
  for (int e = 0; e < ne; ++e) {
    if (topo.edge_degenerate[e]) continue;
    const TopoDS_Edge E = TopoDS::Edge(topo.edges(e + 1).Oriented(TopAbs_FORWARD));
    TopoDS_Vertex va, vb;
    TopExp::Vertices(E, va, vb);
    EdgeSamples& S = samples[e];
    S.va = topo.vertices.FindIndex(va) - 1, S.vb = topo.vertices.FindIndex(vb) - 1;
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
      S.size.push_back(k > 0 ? std::min(edge_size[e], std::max(hmin, params.max_angle / k)) : edge_size[e]);
    }
  }
  // Vertex sizes: no larger than the sizes along their edges nor their short edges' lengths,
  // then limited by the gradation across edges (relaxed to a fixed point).
  const double grade = params.gradation - 1;
  std::vector<double> vsize(nv, h);
  for (int e = 0; e < ne; ++e) {
    const EdgeSamples& S = samples[e];
    if (S.va < 0) continue;
    const double len = S.s.back();
    vsize[S.va] = std::min({vsize[S.va], S.size.front(), std::max(len, hmin / 8)});
    vsize[S.vb] = std::min({vsize[S.vb], S.size.back(), std::max(len, hmin / 8)});
  }
  for (bool changed = true; changed;) {
    changed = false;
    for (int e = 0; e < ne; ++e) {
      const EdgeSamples& S = samples[e];
      if (S.va < 0) continue;
      const double len = S.s.back();
      for (auto [x, y] : {std::pair<int, int>{S.va, S.vb}, std::pair<int, int>{S.vb, S.va}})
        if (vsize[x] > vsize[y] + grade * len * 1.0000001) vsize[x] = vsize[y] + grade * len, changed = true;
    }
  }
  // Nodes along edge e: spacing = the smallest of the local size and the sizes growing from
  // both vertices at the gradation rate, placed at equal steps of ∫ ds / size.
  auto discretise = [&](int e) {
    const EdgeSamples& S = samples[e];
    const int m = static_cast<int>(S.t.size()) - 1;
    const double len = S.s.back();
    std::vector<double> size(m + 1), phi(m + 1, 0.0);
    for (int i = 0; i <= m; ++i) {
      size[i] = std::min({S.size[i], vsize[S.va] + grade * S.s[i], vsize[S.vb] + grade * (len - S.s[i])});
      size[i] = std::max(size[i], 1e-12);
    }
    // size also graded along the edge (a local curvature peak spreads out)
    for (int i = 1; i <= m; ++i) size[i] = std::min(size[i], size[i - 1] + grade * (S.s[i] - S.s[i - 1]));
    for (int i = m - 1; i >= 0; --i) size[i] = std::min(size[i], size[i + 1] + grade * (S.s[i + 1] - S.s[i]));
    for (int i = 1; i <= m; ++i) phi[i] = phi[i - 1] + (S.s[i] - S.s[i - 1]) * 0.5 * (1 / size[i] + 1 / size[i - 1]);
    int n = std::max(1, static_cast<int>(std::ceil(phi[m] - 0.3)));
    if (S.va == S.vb) n = std::max(n, 3);
    std::vector<double>& par = edge_param[e];
    par.assign(1, S.t.front());
    int j = 0;
    for (int k = 1; k < n; ++k) {
      const double target = phi[m] * k / n;
      while (j < m && phi[j + 1] < target) ++j;
      const double w = phi[j + 1] > phi[j] ? (target - phi[j]) / (phi[j + 1] - phi[j]) : 0.5;
      par.push_back(S.t[j] + w * (S.t[j + 1] - S.t[j]));
    }
    par.push_back(S.t.back());
    BRepAdaptor_Curve c(TopoDS::Edge(topo.edges(e + 1).Oriented(TopAbs_FORWARD)));
    std::vector<int>& ids = edge_node[e];
    ids.assign(1, S.va);
    for (int i = 1; i < n; ++i) {
      gp_Pnt p = c.Value(par[i]);
      nodes.push_back({p.X(), p.Y(), p.Z()});
      ids.push_back(static_cast<int>(nodes.size()) - 1);
    }
    ids.push_back(S.vb);
  };
  for (int e = 0; e < ne; ++e)
    if (!topo.edge_degenerate[e]) discretise(e);

  // The boundary of face f in its scaled parameters: local nodes (a seam's nodes appear
  // twice, at both ends of the period), their global numbers, directed segments with the
  // face on their left, and the B-Rep edge of each segment.
  struct Loops {
    std::vector<std::array<double, 2>> uv;
    std::vector<int> global;
    std::vector<std::array<int, 2>> segs;
    std::vector<int> seg_edge;
    std::vector<int> seg_piece;  ///< which piece of the edge's discretisation (-1: collapsed edge)
  };
  auto face_loops = [&](int f) {
    Loops L;
    const TopoDS_Face fwd = TopoDS::Face(topo.faces(f + 1).Oriented(TopAbs_FORWARD));
    const FaceGeometry& g = geo[f];
    double u0, u1, v0, v1;
    BRepTools::UVBounds(fwd, u0, u1, v0, v1);
    const double tol = 1e-6 * std::hypot((u1 - u0) * g.su, (v1 - v0) * g.sv);
    std::unordered_map<int, std::vector<int>> locals;  // global node -> its local copies (seams)
    auto local_node = [&](int gid, double u, double v) {
      for (int l : locals[gid])
        if (std::hypot(L.uv[l][0] - u, L.uv[l][1] - v) <= std::max(tol, 1e-3 * face_size[f])) return l;
      L.uv.push_back({u, v});
      L.global.push_back(gid);
      locals[gid].push_back(static_cast<int>(L.uv.size()) - 1);
      return static_cast<int>(L.uv.size()) - 1;
    };
    for (TopExp_Explorer ex(fwd, TopAbs_EDGE); ex.More(); ex.Next()) {
      const TopoDS_Edge E = TopoDS::Edge(ex.Current());
      const int e = topo.edges.FindIndex(E) - 1;
      double pf, pl;
      Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(E, fwd, pf, pl);
      if (pc.IsNull() || e < 0) continue;
      std::vector<double> par = edge_param[e];
      std::vector<int> ids = edge_node[e];
      if (topo.edge_degenerate[e]) {
        // A collapsed edge (cone apex, sphere pole): a segment in the parameters, one node
        // in space. Its pieces all carry the vertex's node; the triangles that collapse onto
        // it are dropped below, which leaves a fan around the apex.
        TopoDS_Vertex va, vb;
        TopExp::Vertices(E, va, vb);
        const int vid = topo.vertices.FindIndex(va) - 1;
        const gp_Pnt2d qa = pc->Value(pf), qb = pc->Value(pl);
        const double uvlen = std::hypot((qb.X() - qa.X()) * g.su, (qb.Y() - qa.Y()) * g.sv);
        const int n = std::max(2, static_cast<int>(std::ceil(uvlen / face_size[f])));
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
        L.seg_piece.push_back(topo.edge_degenerate[e] ? -1 : static_cast<int>(i));
      }
    }
    return L;
  };

  // ---- proximity: where two boundary segments of a face cross in its parameters or come
  // closer than a third of their length (thin strips, nearly tangent edges), the polygon the
  // front starts from would cross itself or leave no room; those pieces of their edges are
  // split at their middle, locally, until no face has such a pair (or the floor is reached).
  // Each round looks again only at the faces one of whose edges was split; the loops of the
  // last look are the ones the faces are meshed from.
  const double floor_len = hmin / 8;
  std::vector<Loops> loops_of(nf);
  std::vector<char> stale(nf, 1);
  for (int round = 0; round < 10; ++round) {
    std::vector<std::vector<int>> split(ne);  // pieces of each edge to split
    bool any = false;
    for (int f = 0; f < nf; ++f) {
      if (!stale[f]) continue;
      progress.check_cancel("surface meshing");
      loops_of[f] = face_loops(f);
      stale[f] = 0;
      const Loops& L = loops_of[f];
      const size_t ns = L.segs.size();
      std::vector<int> order(ns);
      std::vector<double> xlo(ns), xhi(ns), ylo(ns), yhi(ns), len(ns);
      for (size_t i = 0; i < ns; ++i) {
        const auto& A = L.uv[L.segs[i][0]];
        const auto& B = L.uv[L.segs[i][1]];
        len[i] = std::hypot(B[0] - A[0], B[1] - A[1]);
        xlo[i] = std::min(A[0], B[0]), xhi[i] = std::max(A[0], B[0]);
        ylo[i] = std::min(A[1], B[1]), yhi[i] = std::max(A[1], B[1]);
        order[i] = static_cast<int>(i);
      }
      std::sort(order.begin(), order.end(), [&](int p, int q) { return xlo[p] < xlo[q]; });
      auto point_seg = [&](const std::array<double, 2>& P, const std::array<double, 2>& A, const std::array<double, 2>& B) {
        const double dx = B[0] - A[0], dy = B[1] - A[1], l2 = dx * dx + dy * dy;
        const double t = l2 > 0 ? std::clamp(((P[0] - A[0]) * dx + (P[1] - A[1]) * dy) / l2, 0.0, 1.0) : 0.0;
        return std::hypot(P[0] - A[0] - t * dx, P[1] - A[1] - t * dy);
      };
      auto mark = [&](int s) {
        const int e = L.seg_edge[s], piece = L.seg_piece[s];
        if (piece < 0) return;
        const auto& ids = edge_node[e];
        const double l3 = std::sqrt(sqdist(nodes[ids[piece]], nodes[ids[piece + 1]]));
        if (l3 > floor_len) split[e].push_back(piece), any = true;
      };
      // pieces longer than the face's size field there (finer features nearby in the face,
      // e.g. a small hole close to a long straight edge) are split too
      {
        const std::vector<std::array<double, 3>> fine = fine_points(L.uv, L.segs, face_size[f]);
        const PointGrid grid(fine, face_size[f], grade);
        for (size_t i = 0; i < ns; ++i) {
          const auto& A = L.uv[L.segs[i][0]];
          const auto& B = L.uv[L.segs[i][1]];
          const double mid[2] = {0.5 * (A[0] + B[0]), 0.5 * (A[1] + B[1])};
          if (len[i] > 1.5 * grid.size_at(mid, face_size[f])) mark(static_cast<int>(i));
        }
      }
      for (size_t oi = 0; oi < ns; ++oi) {
        const int i = order[oi];
        for (size_t oj = oi + 1; oj < ns; ++oj) {
          const int j = order[oj];
          const double gap = std::max(len[i], len[j]) / 3;
          if (xlo[j] > xhi[i] + gap) break;
          if (ylo[j] > yhi[i] + gap || ylo[i] > yhi[j] + gap) continue;
          const auto &si = L.segs[i], &sj = L.segs[j];
          if (si[0] == sj[0] || si[0] == sj[1] || si[1] == sj[0] || si[1] == sj[1]) continue;
          const auto &A = L.uv[si[0]], &B = L.uv[si[1]], &C = L.uv[sj[0]], &D = L.uv[sj[1]];
          const bool cross = predicates::orient2d(A.data(), B.data(), C.data()) *
                                     predicates::orient2d(A.data(), B.data(), D.data()) <= 0 &&
                             predicates::orient2d(C.data(), D.data(), A.data()) *
                                     predicates::orient2d(C.data(), D.data(), B.data()) <= 0;
          const double d = cross ? 0.0 : std::min({point_seg(A, C, D), point_seg(B, C, D), point_seg(C, A, B), point_seg(D, A, B)});
          if (d < gap) {
            // the longer one is what leaves no room; both when they cross
            if (cross || len[i] >= 0.7 * len[j]) mark(i);
            if (cross || len[j] >= 0.7 * len[i]) mark(j);
          }
        }
      }
    }
    if (!any) break;
    for (int e = 0; e < ne; ++e) {
      if (split[e].empty()) continue;
      std::sort(split[e].begin(), split[e].end());
      split[e].erase(std::unique(split[e].begin(), split[e].end()), split[e].end());
      BRepAdaptor_Curve c(TopoDS::Edge(topo.edges(e + 1).Oriented(TopAbs_FORWARD)));
      for (auto it = split[e].rbegin(); it != split[e].rend(); ++it) {
        const int k = *it;
        const double t = 0.5 * (edge_param[e][k] + edge_param[e][k + 1]);
        const gp_Pnt p = c.Value(t);
        nodes.push_back({p.X(), p.Y(), p.Z()});
        edge_param[e].insert(edge_param[e].begin() + k + 1, t);
        edge_node[e].insert(edge_node[e].begin() + k + 1, static_cast<int>(nodes.size()) - 1);
      }
    }
    for (int f = 0; f < nf; ++f)
      for (const int* e = topo.face_edges.begin(f); e != topo.face_edges.end(f) && !stale[f]; ++e)
        stale[f] = !split[*e].empty();
  }

  // ---- faces (step 9 for one model): the front fills each face's loops, faces in parallel
  // (largest first), merged in face order so the result does not depend on the threads
  struct FaceOut {
    std::vector<int> global;  // boundary nodes' global numbers (the first rows of X)
    MatX3d X;                 // every node of the face's mesh
    MatX3i T;
    std::string error;
  };
  std::vector<FaceOut> face_out(nf);
  auto mesh_face = [&](int f, const Progress& prog) {
    FaceOut& fo = face_out[f];
    const TopoDS_Face fwd = TopoDS::Face(topo.faces(f + 1).Oriented(TopAbs_FORWARD));
    const FaceGeometry& g = geo[f];
    Loops loops = stale[f] ? face_loops(f) : std::move(loops_of[f]);
    const std::vector<std::array<double, 2>>& uv = loops.uv;
    const std::vector<std::array<int, 2>>& segs = loops.segs;
    fo.global = std::move(loops.global);
    FaceFrontInput in;
    in.P.resize(uv.size(), 2);
    for (size_t i = 0; i < uv.size(); ++i) in.P.row(i) << uv[i][0], uv[i][1];
    in.boundary.resize(segs.size(), 2);
    for (size_t i = 0; i < segs.size(); ++i) in.boundary.row(i) << segs[i][0], segs[i][1];
    FaceFrontParams fp = params.front;
    // size: the face's, but near boundary pieces finer than that (split by proximity, or
    // from a finer neighbour) it grows from their length at the gradation rate
    const double hf = face_size[f];
    const PointGrid grid(fine_points(uv, segs, hf), hf, grade);
    fp.size = [hf, &grid](const double* q) { return grid.size_at(q, hf); };
    FaceFrontResult r;
    try {
      r = fill_face(in, fp, prog);
    } catch (const Error& err) {
      if (err.code() == ErrorCode::Cancelled) throw;
      fo.error = err.what();
      return;
    }
    // local optimisation judged on the surface; triangles collapsed on an apex keep their edges
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
    std::vector<std::array<int, 2>> locked;
    const long nin = static_cast<long>(fo.global.size());
    for (long t = 0; t < r.T.rows(); ++t)
      for (int k = 0; k < 3; ++k) {
        const int a = r.T(t, k), b = r.T(t, (k + 1) % 3), c = r.T(t, (k + 2) % 3);
        if (a < nin && b < nin && fo.global[a] == fo.global[b]) locked.push_back({a, c}), locked.push_back({b, c});
      }
    optimize_on_surface(r.P, r.T, fo.X, static_cast<int>(nin), eval, locked, params.optimize_rounds);
    fo.T = std::move(r.T);
  };
  {
    std::vector<int> order(nf);
    std::vector<double> work(nf, 0.0);
    for (int f = 0; f < nf; ++f) order[f] = f, work[f] = topo.face_area[f] / (face_size[f] * face_size[f]);
    std::sort(order.begin(), order.end(), [&](int x, int y) { return work[x] > work[y]; });
    std::atomic<int> next{0};
    std::atomic<bool> stop{false};
    std::exception_ptr failure;
    std::mutex failure_mutex;
    Progress quiet;  // worker threads: no caller callbacks (they may not be thread-safe)
    quiet.cancelled = [&stop] { return stop.load(); };
    auto worker = [&](bool main_thread) {
      const Progress& prog = main_thread ? progress : quiet;
      try {
        for (int i; !stop.load() && (i = next.fetch_add(1)) < nf;) {
          if (main_thread) progress.check_cancel("surface meshing");
          mesh_face(order[i], prog);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        stop = true;
      }
    };
    const int threads = std::min(thread_count(params.threads), std::max(1, nf));
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker, false);
    worker(true);
    for (auto& th : pool) th.join();
    if (failure) std::rethrow_exception(failure);
  }
  std::vector<std::array<int, 3>> tris;
  std::vector<int> tri_face;
  for (int f = 0; f < nf; ++f) {
    FaceOut& fo = face_out[f];
    if (!fo.error.empty()) {
      out.failed_faces.push_back(f + 1);
      out.reasons.push_back(fo.error);
      continue;
    }
    const long nin = static_cast<long>(fo.global.size());
    std::vector<int> to_global(fo.X.rows());
    for (long i = 0; i < fo.X.rows(); ++i) {
      if (i < nin) {
        to_global[i] = fo.global[i];
      } else {
        nodes.push_back({fo.X(i, 0), fo.X(i, 1), fo.X(i, 2)});
        to_global[i] = static_cast<int>(nodes.size()) - 1;
      }
    }
    const bool flip = topo.faces(f + 1).Orientation() == TopAbs_REVERSED;
    for (long t = 0; t < fo.T.rows(); ++t) {
      std::array<int, 3> tri{to_global[fo.T(t, 0)], to_global[fo.T(t, 1)], to_global[fo.T(t, 2)]};
      if (tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0]) continue;  // collapsed on an apex
      if (flip) std::swap(tri[1], tri[2]);
      tris.push_back(tri);
      tri_face.push_back(f + 1);
    }
    fo = FaceOut();
  }
  // Nodes: the vertices, then those the triangles use (the nodes of an edge whose faces all
  // failed stay unused).
  std::vector<int> renum(nodes.size(), -1);
  int kept = 0;
  for (int v = 0; v < nv; ++v) renum[v] = kept++;
  for (const auto& t : tris)
    for (int v : t)
      if (renum[v] < 0) renum[v] = kept++;
  out.V.resize(kept, 3);
  for (size_t i = 0; i < nodes.size(); ++i)
    if (renum[i] >= 0) out.V.row(renum[i]) << nodes[i][0], nodes[i][1], nodes[i][2];
  out.F.resize(static_cast<long>(tris.size()), 3);
  out.face.resize(static_cast<long>(tris.size()));
  for (size_t t = 0; t < tris.size(); ++t) {
    out.F.row(t) << renum[tris[t][0]], renum[tris[t][1]], renum[tris[t][2]];
    out.face[t] = tri_face[t];
  }
  return out;
}

MatX3i solid_triangles(const brep::TopologyIndex& topo, const SurfaceMesh& mesh, int s) {
  std::map<int, bool> flip;
  for (TopExp_Explorer ex(topo.solids(s + 1), TopAbs_FACE); ex.More(); ex.Next()) {
    const int f = topo.faces.FindIndex(ex.Current());
    if (f > 0) flip[f] = ex.Current().Orientation() != topo.faces(f).Orientation();
  }
  std::vector<std::array<int, 3>> rows;
  for (long t = 0; t < mesh.F.rows(); ++t) {
    auto it = flip.find(mesh.face[t]);
    if (it == flip.end()) continue;
    if (it->second) rows.push_back({mesh.F(t, 0), mesh.F(t, 2), mesh.F(t, 1)});
    else rows.push_back({mesh.F(t, 0), mesh.F(t, 1), mesh.F(t, 2)});
  }
  MatX3i out(static_cast<long>(rows.size()), 3);
  for (size_t i = 0; i < rows.size(); ++i) out.row(i) << rows[i][0], rows[i][1], rows[i][2];
  return out;
}

std::vector<long> open_edges_per_solid(const brep::TopologyIndex& topo, const SurfaceMesh& mesh) {
  std::vector<long> result;
  for (int s = 0; s < topo.num_solids(); ++s) {
    // the solid's faces with their orientation relative to the indexed face
    std::map<int, bool> flip;
    for (TopExp_Explorer ex(topo.solids(s + 1), TopAbs_FACE); ex.More(); ex.Next()) {
      const int f = topo.faces.FindIndex(ex.Current());
      if (f > 0) flip[f] = ex.Current().Orientation() != topo.faces(f).Orientation();
    }
    std::map<std::pair<int, int>, int> directed;
    for (long t = 0; t < mesh.F.rows(); ++t) {
      auto it = flip.find(mesh.face[t]);
      if (it == flip.end()) continue;
      for (int k = 0; k < 3; ++k) {
        int a = mesh.F(t, k), b = mesh.F(t, (k + 1) % 3);
        if (it->second) std::swap(a, b);
        ++directed[{a, b}];
      }
    }
    long open = 0;
    for (const auto& [e, n] : directed) {
      auto rev = directed.find({e.second, e.first});
      if (n != 1 || rev == directed.end() || rev->second != 1) ++open;
    }
    result.push_back(open);
  }
  return result;
}

}  // namespace topopt::mesh
