// Native single-model meshing: surface mesher + 3D advancing front (see native_mesher.h).
#include "mesh/two_brep/native_mesher.h"

#include <BRepAdaptor_Curve.hxx>
#include <BRepClass_FaceClassifier.hxx>
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
#include "mesh/two_brep/gmsh_fragments.h"
#include "mesh/volume/background_size.h"

namespace topopt::mesh {
namespace {

/// What the 14 steps share: one node pool, the surface meshes of the two models on it, and
/// the tets made so far.
struct Steps {
  const brep::TwoBReps& in;
  const NativeMeshParams& params;
  const Progress& progress;
  std::vector<std::array<double, 3>> nodes;
  ModelSurface part, nd;  // Ω and Ω̄
  std::vector<std::array<int, 4>> tets;
  std::vector<int> domain;
  MatX4i tets_in_part;                           // step 13: Ω̄'s tets as tets already present in Ω
  std::map<std::array<int, 3>, int> nd_face_of;  // Ω triangle (sorted nodes) -> Ω̄ face (1-based)
  double tol;
  std::shared_ptr<BackgroundSize> background;

  Steps(const brep::TwoBReps& model, const NativeMeshParams& p, const SurfaceMeshParams& sp, const Progress& prog)
      : in(model),
        params(p),
        progress(prog),
        part(model.part, nodes, sp),
        nd(model.nondesign, nodes, sp),
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
  for (int v = 0; v < s.in.nondesign.num_vertices(); ++v) {
    const brep::Location& at = s.in.nd_on_part.vertex[v];
    if (at.on == brep::On::Vertex) s.nd.set_vertex_node(v, s.part.vertex_node(at.index));
  }
}
void step3_nondesign_vertex_nodes(Steps& s) { s.nd.create_vertex_nodes(s.tol); }

// Step 4: Ω̄'s vertex nodes that lie on edges of Ω must be nodes of those edges' meshes.
void step4_transfer_nodes_to_part_edges(Steps& s) {
  for (int v = 0; v < s.in.nondesign.num_vertices(); ++v) {
    const brep::Location& at = s.in.nd_on_part.vertex[v];
    if (at.on == brep::On::Edge) s.part.fix_edge_node(at.index, s.nd.vertex_node(v));
  }
}
// Step 5: Ω's edges, through those nodes.
void step5_mesh_part_edges(Steps& s) { s.part.mesh_edges(s.progress); }

// Step 6: an edge of Ω̄ lying on an edge of Ω takes the run of that edge's nodes between its
// own end nodes, walking in the direction of its curve (around, for closed edges).
void step6_transfer_edge_segments(Steps& s) {
  for (int e = 0; e < s.in.nondesign.num_edges(); ++e) {
    const brep::Location& at = s.in.nd_on_part.edge[e];
    if (at.on != brep::On::Edge || s.in.nondesign.edge_degenerate[e]) continue;
    std::vector<int> ids = s.part.edge_nodes(at.index);
    const bool closed = ids.size() > 2 && ids.front() == ids.back();
    if (closed) ids.pop_back();
    const int n = static_cast<int>(ids.size());
    const int a = s.nd.vertex_node(s.in.nondesign.edge_vertices(e, 0));
    const int b = s.nd.vertex_node(s.in.nondesign.edge_vertices(e, 1));
    const int ia = static_cast<int>(std::find(ids.begin(), ids.end(), a) - ids.begin());
    const double t_start =
        BRepAdaptor_Curve(TopoDS::Edge(s.in.nondesign.edges(e + 1).Oriented(TopAbs_FORWARD))).FirstParameter();
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
      const double t = s.nd.edge_parameter(e, s.nodes[run[1]].data(), &d);
      const double score = std::abs(t - t_start) + (d > 1e-3 * s.part.size() + s.tol ? 1e200 : 0.0);
      if (score < best_score) best_score = score, best = run;
    }
    if (best.empty() || best_score >= 1e200) {
      std::ostringstream m;
      m << "non-design Edge" << e + 1 << " lies on the part's Edge" << at.index + 1
        << " but its ends are not nodes of that edge's mesh";
      throw Error(ErrorCode::MeshingFailed, m.str());
    }
    s.nd.set_edge_mesh(e, best);
  }
}

// Step 7: the rest of Ω̄'s edges (an edge of one non-design solid lying on an edge of
// another, where they touch, is meshed once and shared).
void step7_mesh_nondesign_edges(Steps& s) {
  const brep::TopologyIndex& t = s.in.nondesign;
  std::vector<int> solid_of(t.num_edges(), -1);
  for (int f = 0; f < t.num_faces(); ++f)
    for (const int* e = t.face_edges.begin(f); e != t.face_edges.end(f); ++e) solid_of[*e] = t.face_solid[f];
  auto point_at = [&](int e, double w) {
    BRepAdaptor_Curve c(TopoDS::Edge(t.edges(e + 1).Oriented(TopAbs_FORWARD)));
    const gp_Pnt p = c.Value(c.FirstParameter() + w * (c.LastParameter() - c.FirstParameter()));
    return std::array<double, 3>{p.X(), p.Y(), p.Z()};
  };
  for (int e2 = 0; e2 < t.num_edges(); ++e2) {
    if (t.edge_degenerate[e2] || s.nd.edge_given(e2)) continue;
    const int a2 = s.nd.vertex_node(t.edge_vertices(e2, 0)), b2 = s.nd.vertex_node(t.edge_vertices(e2, 1));
    for (int e1 = 0; e1 < e2; ++e1) {
      if (t.edge_degenerate[e1] || s.nd.edge_given(e1) || solid_of[e1] == solid_of[e2]) continue;
      const int a1 = s.nd.vertex_node(t.edge_vertices(e1, 0)), b1 = s.nd.vertex_node(t.edge_vertices(e1, 1));
      if (std::minmax(a1, b1) != std::minmax(a2, b2)) continue;
      double d = 0;
      const std::array<double, 3> q = point_at(e2, 0.25);
      const double tq = s.nd.edge_parameter(e1, q.data(), &d);
      if (d > 1e-3 * s.part.size() + s.tol) continue;
      BRepAdaptor_Curve c1(TopoDS::Edge(t.edges(e1 + 1).Oriented(TopAbs_FORWARD)));
      const bool reversed =
          a1 != b1 ? a1 != a2 : (tq - c1.FirstParameter()) > 0.5 * (c1.LastParameter() - c1.FirstParameter());
      s.nd.alias_edge(e2, e1, reversed);
      break;
    }
  }
  s.nd.mesh_edges(s.progress);
}

// Step 8: Ω̄'s segments (and lone vertex nodes) lying on faces of Ω constrain those faces.
void step8_transfer_segments_to_part_faces(Steps& s) {
  const brep::TopologyIndex& t = s.in.nondesign;
  for (int e = 0; e < t.num_edges(); ++e) {
    const brep::Location& at = s.in.nd_on_part.edge[e];
    if (at.on != brep::On::Face) continue;
    const std::vector<int>& ids = s.nd.edge_nodes(e);
    for (size_t i = 0; i + 1 < ids.size(); ++i) s.part.constrain_face(at.index, ids[i], ids[i + 1]);
  }
  for (int v = 0; v < t.num_vertices(); ++v) {
    const brep::Location& at = s.in.nd_on_part.vertex[v];
    if (at.on == brep::On::Face) s.part.add_face_node(at.index, s.nd.vertex_node(v));
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
  const brep::TopologyIndex& t = s.in.nondesign;
  std::map<int, std::vector<int>> on_face;  // Ω face -> Ω̄ faces on it
  for (int f = 0; f < t.num_faces(); ++f)
    if (s.in.nd_on_part.face[f].on == brep::On::Face) on_face[s.in.nd_on_part.face[f].index].push_back(f);
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
            s.nd_face_of[key] = f + 1;
          }
      }
      if (mine.empty()) {
        std::ostringstream m;
        m << "non-design Face" << f + 1 << " lies on the part's Face" << pf + 1
          << " but no region of that face's mesh falls inside it";
        throw Error(ErrorCode::MeshingFailed, m.str());
      }
      s.nd.set_face_mesh(f, std::move(mine));
    }
  }
}

// Step 11: the rest of Ω̄'s faces (a face where two non-design solids touch is meshed once
// and shared, reversed); then every non-design solid's surface must be closed.
void step11_mesh_nondesign_faces(Steps& s) {
  for (const brep::Contact& c : s.in.relations.contacts)
    for (const auto& [fa, fb] : c.faces) s.nd.alias_face(fb, fa, true);
  s.nd.mesh_faces(s.progress);
  if (!s.nd.failed_faces().empty())
    throw Error(ErrorCode::MeshingFailed,
                "the surface mesher could not mesh" +
                    face_list(s.nd.failed_faces(), s.nd.failure_reasons(), "non-design solids"));
  for (int i = 0; i < s.in.nondesign.num_solids(); ++i)
    if (const long open = open_edges(rows_of(s.nd.solid_triangles(i)))) {
      std::ostringstream m;
      m << "the surface mesh of non-design solid " << i + 1 << " is not closed (" << open
        << " edges); a face of it may lie partly on the part's boundary or on another solid";
      throw Error(ErrorCode::MeshingFailed, m.str());
    }
}

/// One fill by the 3D front of the region bounded by `boundary` (around the tets T0) on the
/// nodes V; a front that cannot close is reported with `what` in front of its message.
VolumeFillResult fill(const Steps& s, const MatX3d& V, const std::vector<std::array<int, 3>>& boundary,
                      const MatX4i& T0, const std::string& what, const Progress& progress) {
  VolumeFillParams vp = s.params.volume;
  if (!vp.size) {
    auto bg = s.background;
    vp.size = [bg](const double* x) { return bg->at(x); };
  }
  try {
    return fill_volume(V, rows_of(boundary), T0, vp, progress);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::MeshingFailed) throw;
    throw Error(ErrorCode::MeshingFailed, what + ": " + e.what());
  }
}

/// A fill's new nodes join the pool and its tets the mesh, tagged `dom`. The fill ran on the
/// first n0 nodes of the pool (its rows from n0 on are its own new nodes).
void merge(Steps& s, const VolumeFillResult& r, long n0, int dom) {
  const long offset = static_cast<long>(s.nodes.size()) - n0;  // where these new nodes start, minus n0
  for (long k = n0; k < r.V.rows(); ++k) s.nodes.push_back({r.V(k, 0), r.V(k, 1), r.V(k, 2)});
  for (long t = 0; t < r.T.rows(); ++t) {
    std::array<int, 4> tet;
    for (int c = 0; c < 4; ++c) tet[c] = static_cast<int>(r.T(t, c) < n0 ? r.T(t, c) : r.T(t, c) + offset);
    s.tets.push_back(tet);
    s.domain.push_back(dom);
  }
}

// Step 12: each non-design solid filled from its closed surface. The solids are independent,
// so they are filled in parallel (largest first) on the same snapshot of the node pool; their
// new nodes and tets are merged in input order.
void step12_fill_nondesign(Steps& s) {
  const int n = s.in.nondesign.num_solids();
  if (n == 0) return;
  const MatX3d V = pool_matrix(s.nodes);
  std::vector<std::vector<std::array<int, 3>>> boundary(n);
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) boundary[i] = s.nd.solid_triangles(i), order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return boundary[a].size() > boundary[b].size(); });
  std::vector<VolumeFillResult> results(n);
  parallel_tasks(order, thread_count(s.params.surface.threads), s.progress, "volume meshing",
                 [&](int i, const Progress& prog) {
                   results[i] = fill(s, V, boundary[i], MatX4i(), "non-design solid " + std::to_string(i + 1), prog);
                 });
  s.progress.check_cancel("volume meshing");
  for (int i = 0; i < n; ++i) merge(s, results[i], V.rows(), i + 1);
}
// Step 13: Ω̄'s tets become tets already present in Ω (on the shared node pool): the front of
// step 14 starts from their free faces.
void step13_transfer_tets(Steps& s) {
  s.tets_in_part.resize(static_cast<long>(s.tets.size()), 4);
  for (size_t i = 0; i < s.tets.size(); ++i)
    s.tets_in_part.row(static_cast<long>(i)) << s.tets[i][0], s.tets[i][1], s.tets[i][2], s.tets[i][3];
}
// Step 14: the rest of Ω, from its boundary triangles plus the free faces of those tets.
void step14_fill_design(Steps& s) {
  const MatX3d V = pool_matrix(s.nodes);
  merge(s, fill(s, V, s.part.solid_triangles(0), s.tets_in_part, "design domain", s.progress), V.rows(), 0);
}

}  // namespace

TetMesh mesh_native(const brep::TwoBReps& model, const NativeMeshParams& params, const Progress& progress,
                    MeshRun* run) {
  using clock = std::chrono::steady_clock;
  auto t0 = clock::now();
  auto lap = [&](const char* stage) {
    const auto t1 = clock::now();
    if (run) run->seconds.push_back({stage, std::chrono::duration<double>(t1 - t0).count()});
    t0 = t1;
  };
  if (run) run->mesher = "native", run->seconds.clear();
  // both models on the part's size, so that what one transfers suits the other
  SurfaceMeshParams sp = params.surface;
  if (sp.size <= 0) sp.size = model.part.diagonal() / 50;
  if (sp.min_size <= 0) sp.min_size = sp.size / 10;
  {
    const double h = sp.size, volume = std::abs(model.part.solid_volume.sum());
    const double estimate = 6.0 * volume / (h * h * h) * 1.2;  // ~6 tets per h³ for a good mesh
    if (estimate > params.max_tets)
      throw Error(ErrorCode::TooLarge,
                  "a mesh size of " + std::to_string(h) + " mm would give about " +
                      std::to_string(static_cast<long>(estimate)) +
                      " tetrahedra, more than this machine can optimise; use a mesh size of at least " +
                      std::to_string(h * std::cbrt(estimate / params.max_tets)) + " mm");
  }
  NativeMeshParams bounded = params;
  bounded.volume.max_tets = static_cast<long>(std::min<double>(params.volume.max_tets, 2 * params.max_tets));
  Steps s(model, bounded, sp, progress);
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
  step9_mesh_part_faces(s);
  step10_transfer_triangles(s);
  step11_mesh_nondesign_faces(s);
  lap("steps 8-11: faces");
  progress.say("mesh", 0.3, "volumes");
  {
    // graded volume size from every surface triangle (Ω's and Ω̄'s)
    std::vector<std::array<int, 3>> all = s.part.solid_triangles(0);
    for (int i = 0; i < model.nondesign.num_solids(); ++i) {
      const auto t = s.nd.solid_triangles(i);
      all.insert(all.end(), t.begin(), t.end());
    }
    // and the middle of thin walls when wall_layers asks for layers across them
    std::vector<std::array<double, 4>> walls = s.part.wall_points();
    walls.insert(walls.end(), s.nd.wall_points().begin(), s.nd.wall_points().end());
    s.background =
        std::make_shared<BackgroundSize>(pool_matrix(s.nodes), rows_of(all), sp.size, sp.gradation - 1, walls);
  }
  step12_fill_nondesign(s);
  lap("step 12: non-design volumes");
  step13_transfer_tets(s);
  step14_fill_design(s);
  lap("steps 13-14: design volume");

  // output: the nodes the tets use, Ω's boundary with its face numbers (and Ω̄'s where a
  // triangle also lies on a non-design face)
  std::vector<int> renum(s.nodes.size(), -1);
  int kept = 0;
  for (const auto& t : s.tets)
    for (int v : t)
      if (renum[v] < 0) renum[v] = kept++;
  TetMesh m;
  m.V.resize(kept, 3);
  for (size_t i = 0; i < s.nodes.size(); ++i)
    if (renum[i] >= 0) m.V.row(renum[i]) << s.nodes[i][0], s.nodes[i][1], s.nodes[i][2];
  m.T.resize(static_cast<long>(s.tets.size()), 4);
  m.domain.resize(static_cast<long>(s.tets.size()));
  for (size_t i = 0; i < s.tets.size(); ++i) {
    m.T.row(static_cast<long>(i)) << renum[s.tets[i][0]], renum[s.tets[i][1]], renum[s.tets[i][2]], renum[s.tets[i][3]];
    m.domain[static_cast<long>(i)] = s.domain[i];
  }
  long nb = 0;
  for (int f = 0; f < model.part.num_faces(); ++f) nb += static_cast<long>(s.part.face_triangles(f).size());
  m.F.resize(nb, 3);
  m.face.resize(nb);
  m.nd_face = VecXi::Zero(nb);
  long row = 0;
  for (int f = 0; f < model.part.num_faces(); ++f)
    for (const auto& t : s.part.face_triangles(f)) {
      m.F.row(row) << renum[t[0]], renum[t[1]], renum[t[2]];
      m.face[row] = f + 1;
      std::array<int, 3> key = t;
      std::sort(key.begin(), key.end());
      auto it = s.nd_face_of.find(key);
      if (it != s.nd_face_of.end()) m.nd_face[row] = it->second;
      ++row;
    }
  // the result is checked before anyone uses it: a transfer the classification could not make
  // (e.g. a non-design face lying across two faces of the part) shows up here, not in SIMP
  ConformityParams cp;
  cp.volume_tolerance = 0.05;  // gross errors only: the faceting of curved faces is not one
  const ConformityReport c = check_conformity(m, &model, cp);
  lap("conformity check");
  if (!c.ok()) {
    std::ostringstream msg;
    msg << "the mesh is not conformal (" << c.to_json().dump() << ")";
    throw Error(ErrorCode::MeshingFailed, msg.str());
  }
  return m;
}

TetMesh mesh_two_breps(const brep::TwoBReps& model, const std::string& mesher, double size, double min_size,
                       const Progress& progress, MeshRun* run, int wall_layers) {
  if (mesher != "auto" && mesher != "native" && mesher != "gmsh")
    throw Error(ErrorCode::InvalidParameter, "the mesher is \"auto\", \"native\" or \"gmsh\", not \"" + mesher + "\"");
  if (mesher != "gmsh") {
    NativeMeshParams np;
    np.surface.size = size;
    np.surface.min_size = min_size;
    np.surface.wall_layers = wall_layers;
    // auto: whatever stops the native mesher (a front that cannot close, or a bug) falls
    // back to Gmsh with a warning; a cancel or a mesh too large for memory does not
    std::string reason;
    try {
      return mesh_native(model, np, progress, run);
    } catch (const Error& e) {
      if (mesher == "native" || e.code() == ErrorCode::Cancelled || e.code() == ErrorCode::TooLarge) throw;
      reason = e.what();
    } catch (const std::exception& e) {
      if (mesher == "native") throw;
      reason = e.what();
    }
    if (run) run->fallback_reason = reason;
    progress.warn("the native mesher could not mesh this part (" + reason +
                  "); meshing with Gmsh's OCC fragments instead");
  }
  FragmentMeshParams mp;
  mp.size = size;
  mp.min_size = min_size;
  const auto t0 = std::chrono::steady_clock::now();
  TetMesh m = mesh_with_gmsh_fragments(model, mp, progress);
  if (run) {
    run->mesher = "gmsh";
    run->seconds = {{"gmsh fragments, surface and volume",
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()}};
  }
  return m;
}

}  // namespace topopt::mesh
