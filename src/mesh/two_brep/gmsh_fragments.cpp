// The Gmsh fallback through OCC fragments (see gmsh_fragments.h), as named steps: import and
// fragment, generate, collect nodes and tets (or fill the volumes by our front), orient, tag
// the boundary. Gmsh keeps global state, so calls are serialised by a mutex; nothing else
// here is shared.
#include "mesh/two_brep/gmsh_fragments.h"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <unordered_map>

#include "brep/point_locator.h"
#include "common/error.h"
#include "common/face_key.h"
#include "common/tet_boundary.h"
#include "mesh/two_brep/volume_steps.h"

namespace topopt::mesh {
namespace {

using DimTags = std::vector<std::pair<int, int>>;

std::mutex& gmsh_mutex() {
  static std::mutex m;  // Gmsh's own state is global; this only serialises access to it
  return m;
}

/// Gmsh started without reading or saving option files, silent, on one thread.
struct GmshSession {
  GmshSession() {
    gmsh::initialize(0, nullptr, /*readConfigFiles=*/false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.NumThreads", 1);
    gmsh::option::setNumber("General.SaveOptions", 0);
    gmsh::option::setNumber("General.SaveSession", 0);
  }
  ~GmshSession() { gmsh::finalize(); }
};

/// The Gmsh model as our model sees it: nodes indexed 0.. in Gmsh's order, and the Gmsh
/// volume of each non-design solid.
struct GmshModel {
  std::vector<int> nd_volume;                  ///< Gmsh volume tag of each non-design solid, input order
  std::unordered_map<std::size_t, int> index;  ///< Gmsh node tag -> row of V
  MatX3d V;
  std::vector<std::array<int, 4>> tets;
  std::vector<int> domain;
};

/// The face (0-based) of `locator`'s model nearest to p among those within tolerance, or -1.
int face_at(const brep::PointLocator& locator, const gp_Pnt& p, double tol) {
  int best = -1;
  double d = 1e300;
  for (const auto& h : locator.faces_at(p, tol))
    if (h.distance < d) d = h.distance, best = h.index;
  return best;
}

// Ω and each solid of Ω̄ imported, fragmented into one conformal model; each non-design
// solid must come out as one volume.
void import_and_fragment(const brep::TwoBReps& model, GmshModel& g) {
  DimTags part, pieces, out;
  std::vector<DimTags> out_map;
  gmsh::model::add("topopt");
  gmsh::model::occ::importShapesNativePointer(&model.part.shape, part, true);
  if (model.nondesign.num_solids() > 0) {
    for (int s = 1; s <= model.nondesign.num_solids(); ++s) {
      DimTags one;
      const TopoDS_Shape& solid = model.nondesign.solids(s);
      gmsh::model::occ::importShapesNativePointer(&solid, one, true);
      pieces.insert(pieces.end(), one.begin(), one.end());
    }
    gmsh::model::occ::fragment(part, pieces, out, out_map);
    for (size_t i = 0; i < pieces.size(); ++i) {
      const auto& m = out_map[part.size() + i];
      if (m.size() != 1 || m[0].first != 3)
        throw Error(ErrorCode::MeshingFailed,
                    "non-design solid " + std::to_string(i + 1) +
                        " did not fragment into one volume; check that it lies inside the part");
      g.nd_volume.push_back(m[0].second);
    }
  }
  gmsh::model::occ::synchronize();
}

void generate(const FragmentMeshParams& params) {
  gmsh::option::setNumber("Mesh.MeshSizeMax", params.size);
  gmsh::option::setNumber("Mesh.MeshSizeMin", params.min_size);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", params.elements_per_turn);
  gmsh::option::setNumber("Mesh.Optimize", 1);
  gmsh::model::mesh::generate(params.volume_by_front ? 2 : 3);
}

void collect_nodes(GmshModel& g) {
  std::vector<std::size_t> tags;
  std::vector<double> coords, para;
  gmsh::model::mesh::getNodes(tags, coords, para, -1, -1, false, false);
  g.V.resize(static_cast<long>(tags.size()), 3);
  for (size_t i = 0; i < tags.size(); ++i) {
    g.index[tags[i]] = static_cast<int>(i);
    g.V.row(static_cast<long>(i)) << coords[3 * i], coords[3 * i + 1], coords[3 * i + 2];
  }
}

/// The tets of each Gmsh volume, tagged with their domain.
void collect_tets(GmshModel& g) {
  DimTags vols;
  gmsh::model::getEntities(vols, 3);
  for (auto [d, vt] : vols) {
    int domain = 0;
    auto it = std::find(g.nd_volume.begin(), g.nd_volume.end(), vt);
    if (it != g.nd_volume.end()) domain = 1 + static_cast<int>(it - g.nd_volume.begin());
    std::vector<std::size_t> et, nt;
    gmsh::model::mesh::getElementsByType(4, et, nt, vt);
    for (size_t k = 0; k < et.size(); ++k) {
      g.tets.push_back(
          {g.index.at(nt[4 * k]), g.index.at(nt[4 * k + 1]), g.index.at(nt[4 * k + 2]), g.index.at(nt[4 * k + 3])});
      g.domain.push_back(domain);
    }
  }
}

/// Turns the triangles so that each edge is used in opposite directions by its two
/// triangles (a walk across shared edges from each unvisited triangle).
void orient_consistently(std::vector<std::array<int, 3>>& tri) {
  std::map<std::pair<int, int>, std::vector<int>> edge_tris;
  for (size_t k = 0; k < tri.size(); ++k)
    for (int e = 0; e < 3; ++e) edge_tris[std::minmax(tri[k][e], tri[k][(e + 1) % 3])].push_back(static_cast<int>(k));
  std::vector<char> done(tri.size(), 0);
  for (size_t seed = 0; seed < tri.size(); ++seed) {
    if (done[seed]) continue;
    std::vector<int> stack{static_cast<int>(seed)};
    done[seed] = 1;
    while (!stack.empty()) {
      const int k = stack.back();
      stack.pop_back();
      for (int e = 0; e < 3; ++e) {
        const int a = tri[k][e], b = tri[k][(e + 1) % 3];
        for (int j : edge_tris[std::minmax(a, b)]) {
          if (done[j]) continue;
          bool same = false;  // j must use the edge as b → a
          for (int f = 0; f < 3; ++f) same |= tri[j][f] == a && tri[j][(f + 1) % 3] == b;
          if (same) std::swap(tri[j][1], tri[j][2]);
          done[j] = 1;
          stack.push_back(j);
        }
      }
    }
  }
}

/// The closed surface of Gmsh volumes (their combined boundary), oriented outwards.
MatX3i oriented_shell(const GmshModel& g, const DimTags& volumes) {
  DimTags bnd;
  gmsh::model::getBoundary(volumes, bnd, true, false, false);
  std::vector<std::array<int, 3>> tri;
  for (auto [d, st] : bnd) {
    std::vector<std::size_t> et, nt;
    gmsh::model::mesh::getElementsByType(2, et, nt, std::abs(st));
    for (size_t k = 0; k < et.size(); ++k)
      tri.push_back({g.index.at(nt[3 * k]), g.index.at(nt[3 * k + 1]), g.index.at(nt[3 * k + 2])});
  }
  orient_consistently(tri);
  MatX3i F(static_cast<long>(tri.size()), 3);
  double vol = 0;  // outward when the enclosed volume is positive
  for (size_t k = 0; k < tri.size(); ++k) {
    F.row(static_cast<long>(k)) << tri[k][0], tri[k][1], tri[k][2];
    const Eigen::Vector3d a = g.V.row(tri[k][0]), b = g.V.row(tri[k][1]), c = g.V.row(tri[k][2]);
    vol += a.dot(b.cross(c)) / 6.0;
  }
  if (vol < 0) F.col(1).swap(F.col(2));
  return F;
}

// Steps 12-14 by our front on Gmsh's surface mesh (volume_steps.h).
void fill_by_front(GmshModel& g, const Progress& progress) {
  std::vector<MatX3i> nondesign;
  for (int v : g.nd_volume) nondesign.push_back(oriented_shell(g, {{3, v}}));
  DimTags vols;
  gmsh::model::getEntities(vols, 3);
  progress.say("mesh", 0.5, "advancing front: the non-design solids, then the design domain around them");
  const TwoBRepVolumes r =
      fill_two_brep_volumes(g.V, nondesign, oriented_shell(g, vols), VolumeFillParams{}, 0, progress);
  g.V = r.V;
  for (long t = 0; t < r.T.rows(); ++t) {
    g.tets.push_back({r.T(t, 0), r.T(t, 1), r.T(t, 2), r.T(t, 3)});
    g.domain.push_back(r.domain[t]);
  }
}

/// The tets as a TetMesh, each turned positive.
TetMesh oriented_tets(const GmshModel& g) {
  if (g.tets.empty()) throw Error(ErrorCode::MeshingFailed, "Gmsh produced no tetrahedra; try a smaller mesh size");
  TetMesh m;
  m.V = g.V;
  m.T.resize(static_cast<long>(g.tets.size()), 4);
  m.domain.resize(static_cast<long>(g.tets.size()));
  for (size_t t = 0; t < g.tets.size(); ++t) {
    const auto& k = g.tets[t];
    m.T.row(static_cast<long>(t)) << k[0], k[1], k[2], k[3];
    Eigen::Matrix3d J;
    for (int a = 0; a < 3; ++a) J.row(a) = m.V.row(k[a + 1]) - m.V.row(k[0]);
    if (J.determinant() < 0) std::swap(m.T(static_cast<long>(t), 2), m.T(static_cast<long>(t), 3));
    m.domain[static_cast<long>(t)] = g.domain[t];
  }
  return m;
}

/// Boundary of Ω (outward, from the tets), each triangle tagged through the Gmsh surface it
/// belongs to, and that surface through the B-Rep faces its centre lies on.
void tag_boundary(TetMesh& m, const GmshModel& g, const brep::TwoBReps& model, double hmin) {
  m.F = boundary_triangles(m.T);
  std::map<FaceKey, int> surface_of;
  DimTags surfs;
  gmsh::model::getEntities(surfs, 2);
  for (auto [d, st] : surfs) {
    std::vector<std::size_t> et, nt;
    gmsh::model::mesh::getElementsByType(2, et, nt, st);
    for (size_t k = 0; k < et.size(); ++k)
      surface_of[face_key(g.index.at(nt[3 * k]), g.index.at(nt[3 * k + 1]), g.index.at(nt[3 * k + 2]))] = st;
  }
  const double tol = 1e-6 * model.part.diagonal() + 1e-3 * hmin;
  brep::PointLocator on_part(model.part, tol);
  std::unique_ptr<brep::PointLocator> on_nondesign;
  if (model.nondesign.num_faces() > 0) on_nondesign = std::make_unique<brep::PointLocator>(model.nondesign, tol);
  std::map<int, std::pair<int, int>> faces_of_surface;  // gmsh surface -> (Ω face, Ω̄ face), 1-based
  m.face.resize(m.F.rows());
  m.nd_face.resize(m.F.rows());
  for (long t = 0; t < m.F.rows(); ++t) {
    auto it = surface_of.find(face_key(m.F(t, 0), m.F(t, 1), m.F(t, 2)));
    const int st = it == surface_of.end() ? -1 : it->second;
    auto known = faces_of_surface.find(st);
    if (known == faces_of_surface.end() || st < 0) {
      const Eigen::RowVector3d c = (m.V.row(m.F(t, 0)) + m.V.row(m.F(t, 1)) + m.V.row(m.F(t, 2))) / 3.0;
      const gp_Pnt p(c[0], c[1], c[2]);
      // the centroid of a flat triangle on a curved face is off the face by the sag
      const double sag = 0.25 * (m.V.row(m.F(t, 0)) - m.V.row(m.F(t, 1))).squaredNorm() / std::max(hmin, 1e-9);
      const std::pair<int, int> v{face_at(on_part, p, sag) + 1, on_nondesign ? face_at(*on_nondesign, p, sag) + 1 : 0};
      if (st >= 0) known = faces_of_surface.emplace(st, v).first;
      m.face[t] = v.first, m.nd_face[t] = v.second;
    } else {
      m.face[t] = known->second.first, m.nd_face[t] = known->second.second;
    }
  }
}

}  // namespace

TetMesh mesh_with_gmsh_fragments(const brep::TwoBReps& model, const FragmentMeshParams& params,
                                 const Progress& progress) {
  if (!(params.size > 0 && params.min_size > 0 && params.min_size <= params.size))
    throw Error(ErrorCode::Internal, "mesh_with_gmsh_fragments needs its sizes set (pipeline::gmsh_mesh_params)");
  progress.say("mesh", 0, "meshing with size " + std::to_string(params.size) + " mm (Gmsh fragments)");
  std::lock_guard<std::mutex> lock(gmsh_mutex());
  GmshSession session;
  GmshModel g;
  try {
    import_and_fragment(model, g);
    generate(params);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(ErrorCode::MeshingFailed, std::string("Gmsh could not mesh the part: ") + e.what());
  } catch (...) {
    throw Error(ErrorCode::MeshingFailed, "Gmsh could not mesh the part (try another mesh size)");
  }
  progress.say("mesh", 0.8, "collecting the mesh");
  collect_nodes(g);
  if (params.volume_by_front)
    fill_by_front(g, progress);
  else
    collect_tets(g);
  TetMesh m = oriented_tets(g);
  tag_boundary(m, g, model, params.min_size);
  progress.say("mesh", 1, std::to_string(m.T.rows()) + " tets");
  return m;
}

}  // namespace topopt::mesh
