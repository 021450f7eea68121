// The native mesher: the 14 steps over Ω and Ω̄ as named functions (see native_mesher.h).
#include "mesh/two_brep/native_mesher.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRep_Tool.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS.hxx>
#include <algorithm>
#include <array>
#include <chrono>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "common/error.h"
#include "common/parallel.h"
#include "mesh/core/conformity.h"
#include "mesh/two_brep/volume_steps.h"
#include "mesh/volume/background_size.h"
#include "mesh/volume/sliver_pass.h"

namespace topopt::mesh {
namespace {

/// What the 14 steps share: one node pool, the surface meshes of the two models on it, and
/// the tets of steps 12-14.
struct Steps {
  const brep::TwoBReps& in;
  const brep::MeshedNonDesign& nd;  // Ω̄ as meshed: imprinted where it has partial contact
  const NativeMeshParams& params;
  const Progress& progress;
  std::vector<std::array<double, 3>> nodes;
  ModelSurface part, nondesign;                  // Ω and Ω̄
  std::map<std::array<int, 3>, int> nd_face_of;  // Ω triangle (sorted nodes) -> Ω̄ face (1-based)
  double tol;
  TwoBRepVolumes volumes;  // steps 12-14: every node of the pool and the tets

  Steps(const brep::TwoBReps& model, const NativeMeshParams& p, const Progress& prog)
      : in(model),
        nd(model.meshed),
        params(p),
        progress(prog),
        part(model.part, nodes, p.surface),
        nondesign(model.meshed.topo, nodes, p.surface),
        tol(1e-6 * model.part.diagonal()) {}
};

MatX3d pool_matrix(const std::vector<std::array<double, 3>>& nodes) {
  MatX3d V(static_cast<long>(nodes.size()), 3);
  for (size_t i = 0; i < nodes.size(); ++i) V.row(static_cast<long>(i)) << nodes[i][0], nodes[i][1], nodes[i][2];
  return V;
}

MatX3i rows_of(const std::vector<std::array<int, 3>>& tris) {
  MatX3i F(static_cast<long>(tris.size()), 3);
  for (size_t i = 0; i < tris.size(); ++i) F.row(static_cast<long>(i)) << tris[i][0], tris[i][1], tris[i][2];
  return F;
}

std::string face_list(const std::vector<int>& faces, const std::vector<std::string>& reasons, const char* model) {
  std::ostringstream m;
  for (size_t k = 0; k < faces.size() && k < 5; ++k) m << (k ? ", " : " ") << "Face" << faces[k];
  m << " of the " << model << " (" << reasons[0] << ")";
  return m.str();
}

// Steps 1-3: nodes on Ω's vertices; Ω̄'s vertices that lie on them take those nodes; the
// rest of Ω̄'s vertices get their own (shared between non-design solids that touch there).
void step1_part_vertex_nodes(Steps& s) { s.part.create_vertex_nodes(); }
void step2_transfer_vertex_nodes(Steps& s) {
  for (int v = 0; v < s.nd.topo.num_vertices(); ++v) {
    const brep::Location& at = s.nd.on_part.vertex[v];
    if (at.on == brep::On::Vertex) s.nondesign.set_vertex_node(v, s.part.vertex_node(at.index));
  }
}
void step3_nondesign_vertex_nodes(Steps& s) { s.nondesign.create_vertex_nodes(s.tol); }

// Step 4: Ω̄'s vertex nodes that lie on edges of Ω must be nodes of those edges' meshes.
void step4_transfer_nodes_to_part_edges(Steps& s) {
  for (int v = 0; v < s.nd.topo.num_vertices(); ++v) {
    const brep::Location& at = s.nd.on_part.vertex[v];
    if (at.on == brep::On::Edge) s.part.fix_edge_node(at.index, s.nondesign.vertex_node(v));
  }
}
// Step 5: Ω's edges, through those nodes.
void step5_mesh_part_edges(Steps& s) { s.part.mesh_edges(s.progress); }

// Step 6: an edge of Ω̄ lying on an edge of Ω takes the run of that edge's nodes between its
// own end nodes, walking in the direction of its curve (around, for closed edges).
void step6_transfer_edge_segments(Steps& s) {
  for (int e = 0; e < s.nd.topo.num_edges(); ++e) {
    const brep::Location& at = s.nd.on_part.edge[e];
    if (at.on != brep::On::Edge || s.nd.topo.edge_degenerate[e]) continue;
    std::vector<int> ids = s.part.edge_nodes(at.index);
    const bool closed = ids.size() > 2 && ids.front() == ids.back();
    if (closed) ids.pop_back();
    const int n = static_cast<int>(ids.size());
    const int a = s.nondesign.vertex_node(s.nd.topo.edge_vertices(e, 0));
    const int b = s.nondesign.vertex_node(s.nd.topo.edge_vertices(e, 1));
    const int ia = static_cast<int>(std::find(ids.begin(), ids.end(), a) - ids.begin());
    const double t_start =
        BRepAdaptor_Curve(TopoDS::Edge(s.nd.topo.edges(e + 1).Oriented(TopAbs_FORWARD))).FirstParameter();
    std::vector<int> best;
    double best_score = 1e300;
    for (int dir : {1, -1}) {
      std::vector<int> run{a};
      for (int i = ia + dir, steps = 0; steps < n; i += dir, ++steps) {
        if (!closed && (i < 0 || i >= n)) {
          run.clear();
          break;
        }
        const int k = ids[((i % n) + n) % n];
        run.push_back(k);
        if (k == b) break;
      }
      if (ia >= n || run.size() < 2 || run.back() != b) continue;
      // the run must follow Ω̄'s edge from its start: the first node's parameter nearest
      // the curve's start, on the curve
      double d = 0;
      const double t = s.nondesign.edge_parameter(e, s.nodes[run[1]].data(), &d);
      const double score = std::abs(t - t_start) + (d > 1e-3 * s.part.size() + s.tol ? 1e200 : 0.0);
      if (score < best_score) best_score = score, best = run;
    }
    if (best.empty() || best_score >= 1e200) {
      std::ostringstream m;
      m << "non-design Edge" << e + 1 << " lies on the part's Edge" << at.index + 1
        << " but its ends are not nodes of that edge's mesh";
      throw Error(ErrorCode::MeshingFailed, m.str());
    }
    s.nondesign.set_edge_mesh(e, best);
  }
}

// Step 7: the rest of Ω̄'s edges (an edge of one non-design solid lying on an edge of
// another, where they touch, is meshed once and shared).
void step7_mesh_nondesign_edges(Steps& s) {
  const brep::TopologyIndex& t = s.nd.topo;
  std::vector<int> solid_of(t.num_edges(), -1);
  for (int f = 0; f < t.num_faces(); ++f)
    for (const int* e = t.face_edges.begin(f); e != t.face_edges.end(f); ++e) solid_of[*e] = t.face_solid[f];
  auto point_at = [&](int e, double w) {
    BRepAdaptor_Curve c(TopoDS::Edge(t.edges(e + 1).Oriented(TopAbs_FORWARD)));
    const gp_Pnt p = c.Value(c.FirstParameter() + w * (c.LastParameter() - c.FirstParameter()));
    return std::array<double, 3>{p.X(), p.Y(), p.Z()};
  };
  for (int e2 = 0; e2 < t.num_edges(); ++e2) {
    if (t.edge_degenerate[e2] || s.nondesign.edge_given(e2)) continue;
    const int a2 = s.nondesign.vertex_node(t.edge_vertices(e2, 0)),
              b2 = s.nondesign.vertex_node(t.edge_vertices(e2, 1));
    for (int e1 = 0; e1 < e2; ++e1) {
      if (t.edge_degenerate[e1] || s.nondesign.edge_given(e1) || solid_of[e1] == solid_of[e2]) continue;
      const int a1 = s.nondesign.vertex_node(t.edge_vertices(e1, 0)),
                b1 = s.nondesign.vertex_node(t.edge_vertices(e1, 1));
      if (std::minmax(a1, b1) != std::minmax(a2, b2)) continue;
      double d = 0;
      const std::array<double, 3> q = point_at(e2, 0.25);
      const double tq = s.nondesign.edge_parameter(e1, q.data(), &d);
      if (d > 1e-3 * s.part.size() + s.tol) continue;
      BRepAdaptor_Curve c1(TopoDS::Edge(t.edges(e1 + 1).Oriented(TopAbs_FORWARD)));
      const bool reversed =
          a1 != b1 ? a1 != a2 : (tq - c1.FirstParameter()) > 0.5 * (c1.LastParameter() - c1.FirstParameter());
      s.nondesign.alias_edge(e2, e1, reversed);
      break;
    }
  }
  s.nondesign.mesh_edges(s.progress);
}

// Step 8: Ω̄'s segments (and lone vertex nodes) lying on faces of Ω constrain those faces.
void step8_transfer_segments_to_part_faces(Steps& s) {
  const brep::TopologyIndex& t = s.nd.topo;
  for (int e = 0; e < t.num_edges(); ++e) {
    const brep::Location& at = s.nd.on_part.edge[e];
    if (at.on != brep::On::Face) continue;
    const std::vector<int>& ids = s.nondesign.edge_nodes(e);
    for (size_t i = 0; i + 1 < ids.size(); ++i) s.part.constrain_face(at.index, ids[i], ids[i + 1]);
  }
  for (int v = 0; v < t.num_vertices(); ++v) {
    const brep::Location& at = s.nd.on_part.vertex[v];
    if (at.on == brep::On::Face) s.part.add_face_node(at.index, s.nondesign.vertex_node(v));
  }
}

// Step 9: Ω's faces, honouring those segments.
void step9_mesh_part_faces(Steps& s) {
  s.part.mesh_faces(s.progress);
  if (!s.part.failed_faces().empty())
    throw Error(ErrorCode::MeshingFailed, "the surface mesher could not mesh" +
                                              face_list(s.part.failed_faces(), s.part.failure_reasons(), "part"));
}

// Step 10: the triangles of a face of Ω that lie on a face of Ω̄ become that face's mesh.
// The constraint segments cut Ω's face mesh into regions; each region is given to the Ω̄
// face that contains it (judged by the B-Rep classifier on a few of its triangles).
void step10_transfer_triangles(Steps& s) {
  const brep::TopologyIndex& t = s.nd.topo;
  std::map<int, std::vector<int>> on_face;  // Ω face -> Ω̄ faces on it
  for (int f = 0; f < t.num_faces(); ++f)
    if (s.nd.on_part.face[f].on == brep::On::Face) on_face[s.nd.on_part.face[f].index].push_back(f);
  for (const auto& [pf, nd_faces] : on_face) {
    const auto& tris = s.part.face_triangles(pf);
    std::set<std::pair<int, int>> cuts;
    for (const auto& c : s.part.face_constraints(pf)) cuts.insert(std::minmax(c[0], c[1]));
    // regions: triangles joined across edges that are not constraint segments
    std::map<std::pair<int, int>, std::vector<int>> by_edge;
    for (size_t k = 0; k < tris.size(); ++k)
      for (int j = 0; j < 3; ++j) by_edge[std::minmax(tris[k][j], tris[k][(j + 1) % 3])].push_back(static_cast<int>(k));
    std::vector<int> region(tris.size(), -1);
    int nreg = 0;
    for (size_t k0 = 0; k0 < tris.size(); ++k0) {
      if (region[k0] >= 0) continue;
      std::vector<int> stack{static_cast<int>(k0)};
      region[k0] = nreg;
      while (!stack.empty()) {
        const int k = stack.back();
        stack.pop_back();
        for (int j = 0; j < 3; ++j) {
          const auto key = std::minmax(tris[k][j], tris[k][(j + 1) % 3]);
          if (cuts.count(key)) continue;
          for (int o : by_edge[key])
            if (region[o] < 0) region[o] = nreg, stack.push_back(o);
        }
      }
      ++nreg;
    }
    std::vector<std::vector<int>> members(nreg);
    for (size_t k = 0; k < tris.size(); ++k) members[region[k]].push_back(static_cast<int>(k));
    for (int f : nd_faces) {
      const TopoDS_Face face = TopoDS::Face(t.faces(f + 1));
      BRepClass_FaceClassifier classifier;
      std::vector<std::array<int, 3>> mine;
      for (int r = 0; r < nreg; ++r) {
        const auto& m = members[r];
        int in = 0, votes = 0;
        for (int i = 0; i < 5 && i < static_cast<int>(m.size()); ++i) {
          const auto& tri = tris[m[(m.size() * (2 * i + 1)) / 10]];
          gp_XYZ c(0, 0, 0);
          for (int v : tri) c += gp_XYZ(s.nodes[v][0], s.nodes[v][1], s.nodes[v][2]);
          classifier.Perform(face, gp_Pnt(c / 3), 1e-3 * s.part.size());
          const TopAbs_State st = classifier.State();
          in += st == TopAbs_IN || st == TopAbs_ON;
          ++votes;
        }
        if (2 * in > votes)
          for (int k : m) {
            mine.push_back(tris[k]);
            std::array<int, 3> key = tris[k];
            std::sort(key.begin(), key.end());
            s.nd_face_of[key] = s.nd.face_origin[f] + 1;  // the input's face number
          }
      }
      if (mine.empty()) {
        std::ostringstream m;
        m << "non-design Face" << s.nd.face_origin[f] + 1 << " lies on the part's Face" << pf + 1
          << " but no region of that face's mesh falls inside it";
        throw Error(ErrorCode::MeshingFailed, m.str());
      }
      s.nondesign.set_face_mesh(f, std::move(mine));
    }
  }
}

// Step 11: the rest of Ω̄'s faces (a face where two non-design solids touch is meshed once
// and shared, reversed); then every non-design solid's surface must be closed.
void step11_mesh_nondesign_faces(Steps& s) {
  for (const brep::Contact& c : s.nd.relations.contacts)
    for (const auto& [fa, fb] : c.faces) s.nondesign.alias_face(fb, fa, true);
  s.nondesign.mesh_faces(s.progress);
  if (!s.nondesign.failed_faces().empty()) {
    std::vector<int> input_faces;  // in the input's numbers (a face split by the imprint is named as a whole)
    for (int f : s.nondesign.failed_faces()) input_faces.push_back(s.nd.face_origin[f - 1] + 1);
    throw Error(ErrorCode::MeshingFailed,
                "the surface mesher could not mesh" +
                    face_list(input_faces, s.nondesign.failure_reasons(), "non-design solids"));
  }
  for (int i = 0; i < s.nd.topo.num_solids(); ++i)
    if (const long open = open_edges(rows_of(s.nondesign.solid_triangles(i)))) {
      std::ostringstream m;
      m << "the surface mesh of non-design solid " << i + 1 << " is not closed (" << open
        << " edges); a face of it may lie partly on the part's boundary or on another solid";
      throw Error(ErrorCode::MeshingFailed, m.str());
    }
}

// Steps 12-14 (volume_steps.h) on both models' surfaces, at the volume size graded from
// every surface triangle (Ω's and Ω̄'s) and seeded at the middle of thin walls.
void steps12_to_14_fill_volumes(Steps& s) {
  std::vector<std::array<int, 3>> all = s.part.solid_triangles(0);
  std::vector<MatX3i> nondesign;
  for (int i = 0; i < s.nd.topo.num_solids(); ++i) {
    const auto t = s.nondesign.solid_triangles(i);
    all.insert(all.end(), t.begin(), t.end());
    nondesign.push_back(rows_of(t));
  }
  std::vector<std::array<double, 4>> walls = s.part.wall_points();
  walls.insert(walls.end(), s.nondesign.wall_points().begin(), s.nondesign.wall_points().end());
  const MatX3d V = pool_matrix(s.nodes);
  const SurfaceMeshParams& sp = s.params.surface;
  auto background = std::make_shared<BackgroundSize>(V, rows_of(all), sp.size, sp.gradation - 1, walls);
  VolumeFillParams vp = s.params.volume;
  if (!vp.size) vp.size = [background](const double* x) { return background->at(x); };
  s.volumes = fill_two_brep_volumes(V, nondesign, rows_of(s.part.solid_triangles(0)), vp, sp.threads, s.progress);
}

/// The result: the nodes the tets use, Ω's boundary with its face numbers (and Ω̄'s where
/// a triangle also lies on a non-design face).
TetMesh output_mesh(const Steps& s) {
  const TwoBRepVolumes& v = s.volumes;
  std::vector<int> renum(static_cast<size_t>(v.V.rows()), -1);
  int kept = 0;
  for (long t = 0; t < v.T.rows(); ++t)
    for (int c = 0; c < 4; ++c)
      if (renum[v.T(t, c)] < 0) renum[v.T(t, c)] = kept++;
  TetMesh m;
  m.V.resize(kept, 3);
  for (long i = 0; i < v.V.rows(); ++i)
    if (renum[i] >= 0) m.V.row(renum[i]) = v.V.row(i);
  m.T.resize(v.T.rows(), 4);
  for (long t = 0; t < v.T.rows(); ++t)
    m.T.row(t) << renum[v.T(t, 0)], renum[v.T(t, 1)], renum[v.T(t, 2)], renum[v.T(t, 3)];
  m.domain = v.domain;
  long nb = 0;
  for (int f = 0; f < s.in.part.num_faces(); ++f) nb += static_cast<long>(s.part.face_triangles(f).size());
  m.F.resize(nb, 3);
  m.face.resize(nb);
  m.nd_face = VecXi::Zero(nb);
  long row = 0;
  for (int f = 0; f < s.in.part.num_faces(); ++f)
    for (const auto& t : s.part.face_triangles(f)) {
      m.F.row(row) << renum[t[0]], renum[t[1]], renum[t[2]];
      m.face[row] = f + 1;
      std::array<int, 3> key = t;
      std::sort(key.begin(), key.end());
      auto it = s.nd_face_of.find(key);
      if (it != s.nd_face_of.end()) m.nd_face[row] = it->second;
      ++row;
    }
  return m;
}

/// The sliver pass's projection onto Ω's faces (1-based): the nearest point of the face's
/// surface, each surface taken from the B-Rep once; false when OCCT finds none or fails.
std::function<bool(int, Eigen::Vector3d&)> onto_part_faces(const brep::TopologyIndex& part) {
  auto surfaces = std::make_shared<std::vector<Handle(Geom_Surface)>>(static_cast<size_t>(part.num_faces()));
  return [&part, surfaces](int face, Eigen::Vector3d& x) {
    if (face < 1 || face > part.num_faces()) return false;
    try {
      Handle(Geom_Surface)& surface = (*surfaces)[face - 1];
      if (surface.IsNull()) surface = BRep_Tool::Surface(TopoDS::Face(part.faces(face)));
      GeomAPI_ProjectPointOnSurf nearest(gp_Pnt(x.x(), x.y(), x.z()), surface);
      if (nearest.NbPoints() == 0) return false;
      const gp_Pnt q = nearest.NearestPoint();
      x = Eigen::Vector3d(q.X(), q.Y(), q.Z());
      return true;
    } catch (const Standard_Failure&) {
      return false;
    }
  };
}

/// The result is checked before anyone uses it: a transfer the classification could not make
/// (e.g. a non-design face lying across two faces of the part) shows up here, not in SIMP.
void check_output(const TetMesh& m, const brep::TwoBReps& model) {
  ConformityParams cp;
  cp.volume_tolerance = 0.05;  // gross errors only: the faceting of curved faces is not one
  const ConformityReport c = check_conformity(m, &model, cp);
  if (!c.ok()) {
    std::ostringstream msg;
    msg << "the mesh is not conformal (" << c.to_json().dump() << ")";
    throw Error(ErrorCode::MeshingFailed, msg.str());
  }
}

}  // namespace

TetMesh mesh_native(const brep::TwoBReps& model, const NativeMeshParams& params, const Progress& progress,
                    MeshRun* run) {
  if (!(params.surface.size > 0 && params.surface.min_size > 0))
    throw Error(ErrorCode::Internal, "mesh_native needs its sizes set (pipeline::native_mesh_params decides them)");
  if (model.meshed.topo.num_solids() != model.nondesign.num_solids())
    throw Error(ErrorCode::Internal,
                "mesh_native needs the model from brep::load_two_breps (its imprinted Ω̄ is missing)");
  using clock = std::chrono::steady_clock;
  auto t0 = clock::now();
  auto lap = [&](const char* stage) {
    const auto t1 = clock::now();
    if (run) run->seconds.push_back({stage, std::chrono::duration<double>(t1 - t0).count()});
    t0 = t1;
  };
  if (run) run->mesher = "native", run->seconds.clear();
  Steps s(model, params, progress);  // both models on the part's size, so that what one transfers suits the other
  progress.say("mesh", 0.02, "edges");
  step1_part_vertex_nodes(s);
  step2_transfer_vertex_nodes(s);
  step3_nondesign_vertex_nodes(s);
  step4_transfer_nodes_to_part_edges(s);
  step5_mesh_part_edges(s);
  step6_transfer_edge_segments(s);
  step7_mesh_nondesign_edges(s);
  lap("steps 1-7: vertices and edges");
  progress.say("mesh", 0.05, "faces");
  step8_transfer_segments_to_part_faces(s);
  if (run) run->face_sizes = s.part.face_sizes();
  step9_mesh_part_faces(s);
  step10_transfer_triangles(s);
  step11_mesh_nondesign_faces(s);
  lap("steps 8-11: faces");
  progress.say("mesh", 0.3, "volumes");
  steps12_to_14_fill_volumes(s);
  if (run) {
    const double both = std::chrono::duration<double>(clock::now() - t0).count();
    run->seconds.push_back({"step 12: non-design volumes", both - s.volumes.seconds_design});
    run->seconds.push_back({"steps 13-14: design volume", s.volumes.seconds_design});
  }
  t0 = clock::now();
  TetMesh m = output_mesh(s);
  progress.say("mesh", 0.95, "slivers");
  SliverPassParams slivers;  // the fills never move boundary or interface nodes: this pass may, on their face
  slivers.onto_face = onto_part_faces(model.part);
  remove_final_slivers(m, slivers);
  lap("sliver pass");
  check_output(m, model);
  lap("conformity check");
  return m;
}

}  // namespace topopt::mesh
