// Interim mesher through Gmsh's OCC fragments (see gmsh_fragments.h). Gmsh keeps global
// state, so calls are serialised by a mutex; nothing else here is shared.
#include "mesh/two_brep/gmsh_fragments.h"

#include <gmsh.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <unordered_map>

#include "brep/point_locator.h"
#include "common/error.h"
#include "common/face_key.h"
#include "io/msh.h"
#include "mesh/volume/volume_front.h"

namespace topopt::mesh {
namespace {

std::mutex& gmsh_mutex() {
  static std::mutex m;  // Gmsh's own state is global; this only serialises access to it
  return m;
}

struct GmshSession {
  GmshSession() {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.NumThreads", 1);
  }
  ~GmshSession() { gmsh::finalize(); }
};

inline FaceKey key3(int a, int b, int c) { return face_key(a, b, c); }

/// The face (0-based) of `locator`'s model nearest to p among those within tolerance, or -1.
int face_at(const brep::PointLocator& locator, const gp_Pnt& p, double tol) {
  auto hits = locator.faces_at(p, tol);
  int best = -1;
  double d = 1e300;
  for (const auto& h : hits)
    if (h.distance < d) d = h.distance, best = h.index;
  return best;
}

}  // namespace

TetMesh mesh_with_gmsh_fragments(const brep::TwoBReps& model, const FragmentMeshParams& params,
                                 const Progress& progress) {
  const double diag = model.part.diagonal();
  double h = params.size > 0 ? params.size : diag / 50.0;
  double hmin = params.min_size > 0 ? params.min_size : h / 5.0;
  if (hmin > h) throw Error(ErrorCode::InvalidParameter, "the minimum mesh size is larger than the mesh size");
  double volume = std::abs(model.part.solid_volume.sum());
  double estimate = 6.0 * volume / (h * h * h) * 1.2;  // ~6 tets per h³ cube for a good mesh
  if (estimate > params.max_tets)
    throw Error(ErrorCode::TooLarge,
                "a mesh size of " + std::to_string(h) + " mm would give about " +
                    std::to_string(static_cast<long>(estimate)) +
                    " tetrahedra, more than this machine can optimise; use a mesh size of at least " +
                    std::to_string(h * std::cbrt(estimate / params.max_tets)) + " mm");
  progress.say("mesh", 0, "meshing with size " + std::to_string(h) + " mm (Gmsh fragments)");
  std::lock_guard<std::mutex> lock(gmsh_mutex());
  GmshSession session;
  std::vector<std::pair<int, int>> part, nd, out;
  std::vector<std::vector<std::pair<int, int>>> out_map;
  std::vector<int> nd_volume;  // gmsh volume tag of each non-design solid, in input order
  std::set<int> design;
  try {
    gmsh::model::add("topopt");
    gmsh::model::occ::importShapesNativePointer(&model.part.shape, part, true);
    if (model.nondesign.num_solids() > 0) {
      for (int s = 1; s <= model.nondesign.num_solids(); ++s) {
        std::vector<std::pair<int, int>> one;
        const TopoDS_Shape& solid = model.nondesign.solids(s);
        gmsh::model::occ::importShapesNativePointer(&solid, one, true);
        nd.insert(nd.end(), one.begin(), one.end());
      }
      gmsh::model::occ::fragment(part, nd, out, out_map);
      for (size_t i = 0; i < nd.size(); ++i) {
        const auto& m = out_map[part.size() + i];
        if (m.size() != 1 || m[0].first != 3)
          throw Error(ErrorCode::MeshingFailed,
                      "non-design solid " + std::to_string(i + 1) +
                          " did not fragment into one volume; check that it lies inside the part");
        nd_volume.push_back(m[0].second);
      }
    }
    gmsh::model::occ::synchronize();
    std::vector<std::pair<int, int>> vols;
    gmsh::model::getEntities(vols, 3);
    for (auto [d, t] : vols)
      if (std::find(nd_volume.begin(), nd_volume.end(), t) == nd_volume.end()) design.insert(t);
    gmsh::option::setNumber("Mesh.MeshSizeMax", h);
    gmsh::option::setNumber("Mesh.MeshSizeMin", hmin);
    gmsh::option::setNumber(
        "Mesh.MeshSizeFromCurvature",
        40);  // elements per 2π: the faceting error of a bore (≈ (2π/N)²/6 of a ring's volume) stays under 0.5 %
    gmsh::option::setNumber("Mesh.Optimize", 1);
    gmsh::model::mesh::generate(params.native_volume ? 2 : 3);
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(ErrorCode::MeshingFailed, std::string("Gmsh could not mesh the part: ") + e.what());
  } catch (...) {
    throw Error(ErrorCode::MeshingFailed, "Gmsh could not mesh the part (try another mesh size)");
  }
  progress.say("mesh", 0.8, "collecting the mesh");
  std::vector<std::size_t> tags;
  std::vector<double> coords, para;
  gmsh::model::mesh::getNodes(tags, coords, para, -1, -1, false, false);
  std::unordered_map<std::size_t, int> index;
  TetMesh m;
  m.V.resize(tags.size(), 3);
  for (size_t i = 0; i < tags.size(); ++i) {
    index[tags[i]] = static_cast<int>(i);
    m.V.row(i) << coords[3 * i], coords[3 * i + 1], coords[3 * i + 2];
  }
  std::vector<std::array<int, 4>> tets;
  std::vector<int> dom;
  std::vector<std::pair<int, int>> vols;
  gmsh::model::getEntities(vols, 3);
  for (auto [d, vt] : vols) {
    int domain = 0;
    auto it = std::find(nd_volume.begin(), nd_volume.end(), vt);
    if (it != nd_volume.end()) domain = 1 + static_cast<int>(it - nd_volume.begin());
    std::vector<std::size_t> et, nt;
    gmsh::model::mesh::getElementsByType(4, et, nt, vt);
    for (size_t k = 0; k < et.size(); ++k) {
      tets.push_back({index.at(nt[4 * k]), index.at(nt[4 * k + 1]), index.at(nt[4 * k + 2]), index.at(nt[4 * k + 3])});
      dom.push_back(domain);
    }
  }
  if (params.native_volume) {
    // Steps 12–14 on Gmsh's surface mesh: each non-design solid filled from its boundary,
    // then Ω filled around their tets, by our advancing front.
    auto shell = [&](const std::vector<std::pair<int, int>>& volumes) {
      std::vector<std::pair<int, int>> bnd;
      gmsh::model::getBoundary(volumes, bnd, true, false, false);
      std::vector<std::array<int, 3>> tri;
      for (auto [d, st] : bnd) {
        std::vector<std::size_t> et, nt;
        gmsh::model::mesh::getElementsByType(2, et, nt, std::abs(st));
        for (size_t k = 0; k < et.size(); ++k)
          tri.push_back({index.at(nt[3 * k]), index.at(nt[3 * k + 1]), index.at(nt[3 * k + 2])});
      }
      // Orient consistently by walking across shared edges (each edge used in opposite
      // directions by its two triangles), then outward by the sign of the enclosed volume.
      std::map<std::pair<int, int>, std::vector<int>> edge_tris;
      for (size_t k = 0; k < tri.size(); ++k)
        for (int e = 0; e < 3; ++e)
          edge_tris[std::minmax(tri[k][e], tri[k][(e + 1) % 3])].push_back(static_cast<int>(k));
      std::vector<char> done(tri.size(), 0);
      for (size_t seed = 0; seed < tri.size(); ++seed) {
        if (done[seed]) continue;
        std::vector<int> stack{static_cast<int>(seed)};
        done[seed] = 1;
        while (!stack.empty()) {
          int k = stack.back();
          stack.pop_back();
          for (int e = 0; e < 3; ++e) {
            int a = tri[k][e], b = tri[k][(e + 1) % 3];
            for (int j : edge_tris[std::minmax(a, b)]) {
              if (done[j]) continue;
              // j must use the edge as b → a
              bool same = false;
              for (int f = 0; f < 3; ++f) same |= tri[j][f] == a && tri[j][(f + 1) % 3] == b;
              if (same) std::swap(tri[j][1], tri[j][2]);
              done[j] = 1;
              stack.push_back(j);
            }
          }
        }
      }
      MatX3i F(tri.size(), 3);
      double vol = 0;
      for (size_t k = 0; k < tri.size(); ++k) {
        F.row(k) << tri[k][0], tri[k][1], tri[k][2];
        Eigen::Vector3d a = m.V.row(tri[k][0]), b = m.V.row(tri[k][1]), c = m.V.row(tri[k][2]);
        vol += a.dot(b.cross(c)) / 6.0;
      }
      if (vol < 0) F.col(1).swap(F.col(2));
      return F;
    };
    auto append = [&](const VolumeFillResult& r, int domain) {
      m.V = r.V;
      for (long t = 0; t < r.T.rows(); ++t) {
        tets.push_back({r.T(t, 0), r.T(t, 1), r.T(t, 2), r.T(t, 3)});
        dom.push_back(domain);
      }
    };
    VolumeFillParams vp;
    for (size_t i = 0; i < nd_volume.size(); ++i) {
      progress.say("mesh", 0.5, "advancing front: non-design solid " + std::to_string(i + 1));
      append(fill_volume(m.V, shell({{3, nd_volume[i]}}), MatX4i(), vp, progress), static_cast<int>(i) + 1);
    }
    MatX4i T0(tets.size(), 4);
    for (size_t t = 0; t < tets.size(); ++t) T0.row(t) << tets[t][0], tets[t][1], tets[t][2], tets[t][3];
    progress.say("mesh", 0.7, "advancing front: the design domain around the non-design tets");
    append(fill_volume(m.V, shell(vols), T0, vp, progress), 0);
  }
  if (tets.empty()) throw Error(ErrorCode::MeshingFailed, "Gmsh produced no tetrahedra; try a smaller mesh size");
  m.T.resize(tets.size(), 4);
  m.domain.resize(tets.size());
  for (size_t t = 0; t < tets.size(); ++t) {
    m.T.row(t) << tets[t][0], tets[t][1], tets[t][2], tets[t][3];
    Eigen::Matrix3d J;
    for (int a = 0; a < 3; ++a) J.row(a) = m.V.row(tets[t][a + 1]) - m.V.row(tets[t][0]);
    if (J.determinant() < 0) std::swap(m.T(t, 2), m.T(t, 3));
    m.domain[t] = dom[t];
  }
  // Boundary of Ω (outward, from the tets), each triangle tagged through the Gmsh surface
  // it belongs to, and that surface through the B-Rep faces its centre lies on.
  m.F = io::boundary_triangles(m.T);
  std::map<std::array<int, 3>, int> surface_of;
  std::vector<std::pair<int, int>> surfs;
  gmsh::model::getEntities(surfs, 2);
  for (auto [d, st] : surfs) {
    std::vector<std::size_t> et, nt;
    gmsh::model::mesh::getElementsByType(2, et, nt, st);
    for (size_t k = 0; k < et.size(); ++k)
      surface_of[key3(index.at(nt[3 * k]), index.at(nt[3 * k + 1]), index.at(nt[3 * k + 2]))] = st;
  }
  const double tol = 1e-6 * diag + 1e-3 * hmin;
  brep::PointLocator on_part(model.part, tol);
  std::unique_ptr<brep::PointLocator> on_nd;
  if (model.nondesign.num_faces() > 0) on_nd = std::make_unique<brep::PointLocator>(model.nondesign, tol);
  std::map<int, std::pair<int, int>> faces_of_surface;  // gmsh surface -> (Ω face, Ω̄ face), 1-based
  m.face.resize(m.F.rows());
  m.nd_face.resize(m.F.rows());
  for (long t = 0; t < m.F.rows(); ++t) {
    auto it = surface_of.find(key3(m.F(t, 0), m.F(t, 1), m.F(t, 2)));
    int st = it == surface_of.end() ? -1 : it->second;
    auto known = faces_of_surface.find(st);
    if (known == faces_of_surface.end() || st < 0) {
      Eigen::RowVector3d c = (m.V.row(m.F(t, 0)) + m.V.row(m.F(t, 1)) + m.V.row(m.F(t, 2))) / 3.0;
      gp_Pnt p(c[0], c[1], c[2]);
      // the centroid of a flat triangle on a curved face is off the face by the sag
      double sag = 0.25 * (m.V.row(m.F(t, 0)) - m.V.row(m.F(t, 1))).squaredNorm() / std::max(hmin, 1e-9);
      int f = face_at(on_part, p, sag);
      int g = on_nd ? face_at(*on_nd, p, sag) : -1;
      std::pair<int, int> v{f + 1, g + 1};
      if (st >= 0) known = faces_of_surface.emplace(st, v).first;
      m.face[t] = v.first, m.nd_face[t] = v.second;
    } else {
      m.face[t] = known->second.first, m.nd_face[t] = known->second.second;
    }
  }
  progress.say("mesh", 1, std::to_string(m.T.rows()) + " tets");
  return m;
}

}  // namespace topopt::mesh
