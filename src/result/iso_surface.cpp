// Marching tetrahedra on the tagged mesh (see iso_surface.h).
#include "result/iso_surface.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <unordered_map>

#include "common/error.h"
#include "common/face_key.h"

namespace topopt::result {
namespace {

/// Faces of a positive tet, opposite vertex i, oriented outwards.
constexpr int kFace[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

using Hash3 = FaceKeyHash;
inline FaceKey sorted3(int a, int b, int c) { return face_key(a, b, c); }

/// Value of the level-set function at a node: never exactly 0 (a node on the threshold
/// counts as inside), so every crossing lies strictly inside an edge.
inline double level(const VecXd& nd, int node, double threshold) {
  double v = nd[node] - threshold;
  return v == 0 ? 1e-12 : v;
}

double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d) {
  return std::abs((b - a).dot((c - a).cross(d - a))) / 6.0;
}

/// Volume of the part of tet p[0..3] where the linear function with node values f >= 0.
double kept_volume(const std::array<Eigen::Vector3d, 4>& p, const std::array<double, 4>& f) {
  int pos[4], neg[4], np = 0, nn = 0;
  for (int i = 0; i < 4; ++i) (f[i] >= 0 ? pos[np++] : neg[nn++]) = i;
  double vol = tet_volume(p[0], p[1], p[2], p[3]);
  auto cut = [&](int i, int j) { return Eigen::Vector3d(p[i] + f[i] / (f[i] - f[j]) * (p[j] - p[i])); };
  if (np == 0) return 0;
  if (np == 4) return vol;
  if (np == 1) {
    int a = pos[0];
    double r = 1;
    for (int j = 0; j < 4; ++j)
      if (j != a) r *= f[a] / (f[a] - f[j]);
    return vol * r;
  }
  if (np == 3) {
    int d = neg[0];
    double r = 1;
    for (int j = 0; j < 4; ++j)
      if (j != d) r *= -f[d] / (f[j] - f[d]);
    return vol * (1 - r);
  }
  // two in (a, b), two out (c, d): the prism a p_ac p_ad | b p_bc p_bd
  int a = pos[0], b = pos[1], c = neg[0], d = neg[1];
  Eigen::Vector3d A0 = p[a], A1 = cut(a, c), A2 = cut(a, d), B0 = p[b], B1 = cut(b, c), B2 = cut(b, d);
  return tet_volume(A0, A1, A2, B2) + tet_volume(A0, A1, B1, B2) + tet_volume(A0, B0, B1, B2);
}

/// Parity of the permutation (a, b, c, d) of (0, 1, 2, 3): true if even.
bool even_permutation(int a, int b, int c, int d) {
  int v[4] = {a, b, c, d}, inv = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) inv += v[i] > v[j];
  return inv % 2 == 0;
}

}  // namespace

VecXd node_densities(const TetMesh& mesh, const VecXd& density) {
  const long nv = mesh.V.rows();
  VecXd sum = VecXd::Zero(nv), wsum = VecXd::Zero(nv);
  std::vector<char> design_node(nv, 0);
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (mesh.domain.size() == mesh.T.rows() && mesh.domain[t] != 0) continue;
    Eigen::Vector3d p0 = mesh.V.row(mesh.T(t, 0));
    double v = std::abs((Eigen::Vector3d(mesh.V.row(mesh.T(t, 1))) - p0)
                            .dot((Eigen::Vector3d(mesh.V.row(mesh.T(t, 2))) - p0)
                                     .cross(Eigen::Vector3d(mesh.V.row(mesh.T(t, 3))) - p0))) /
               6.0;
    for (int a = 0; a < 4; ++a) {
      sum[mesh.T(t, a)] += v * density[t];
      wsum[mesh.T(t, a)] += v;
    }
  }
  VecXd out(nv);
  for (long i = 0; i < nv; ++i) out[i] = wsum[i] > 0 ? sum[i] / wsum[i] : 1.0;
  return out;
}

double kept_design_volume(const TetMesh& mesh, const VecXd& nd, double threshold) {
  double total = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (mesh.domain.size() == mesh.T.rows() && mesh.domain[t] != 0) continue;
    std::array<Eigen::Vector3d, 4> p;
    std::array<double, 4> f;
    for (int a = 0; a < 4; ++a) p[a] = mesh.V.row(mesh.T(t, a)), f[a] = level(nd, mesh.T(t, a), threshold);
    total += kept_volume(p, f);
  }
  return total;
}

double threshold_for_volume(const TetMesh& mesh, const VecXd& nd, double volume_fraction) {
  if (!(volume_fraction > 0 && volume_fraction < 1))
    throw Error(ErrorCode::InvalidParameter, "the volume fraction must lie strictly between 0 and 1");
  const double target = volume_fraction * kept_design_volume(mesh, nd, -1.0);
  double lo = 0, hi = 1;
  for (int k = 0; k < 50; ++k) {
    double mid = 0.5 * (lo + hi);
    (kept_design_volume(mesh, nd, mid) > target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

TriSurface extract_iso_surface(const TetMesh& mesh, const VecXd& nd, double threshold) {
  const long nt = mesh.T.rows();
  const bool tagged = mesh.domain.size() == nt;
  auto is_design = [&](long t) { return !tagged || mesh.domain[t] == 0; };
  TriSurface s;
  std::vector<Eigen::Vector3d> pts;
  std::vector<int> lock, pface;
  std::vector<std::array<int, 3>> tris;
  std::vector<int> tags;
  std::unordered_map<int, int> node_point;        // mesh node -> point
  std::map<std::pair<int, int>, int> edge_point;  // sorted mesh edge -> point
  auto node_pt = [&](int n) {
    auto [it, fresh] = node_point.emplace(n, static_cast<int>(pts.size()));
    if (fresh) pts.push_back(mesh.V.row(n)), lock.push_back(0), pface.push_back(0);
    return it->second;
  };
  auto edge_pt = [&](int a, int b) {
    auto key = std::minmax(a, b);
    auto [it, fresh] = edge_point.emplace(std::make_pair(key.first, key.second), static_cast<int>(pts.size()));
    if (fresh) {
      double fa = level(nd, a, threshold), fb = level(nd, b, threshold);
      double w = fa / (fa - fb);
      pts.push_back(Eigen::Vector3d(mesh.V.row(a)) +
                    w * (Eigen::Vector3d(mesh.V.row(b)) - Eigen::Vector3d(mesh.V.row(a))));
      lock.push_back(0), pface.push_back(0);
    }
    return it->second;
  };
  auto emit = [&](int a, int b, int c, int tag) {
    tris.push_back({a, b, c});
    tags.push_back(tag);
  };

  // 1. iso-triangles inside design tets
  for (long t = 0; t < nt; ++t) {
    if (!is_design(t)) continue;
    int v[4];
    double f[4];
    int np = 0;
    for (int a = 0; a < 4; ++a) v[a] = mesh.T(t, a), f[a] = level(nd, v[a], threshold), np += f[a] > 0;
    if (np == 0 || np == 4) continue;
    if (np == 1 || np == 3) {
      int i = 0;
      while ((f[i] > 0) != (np == 1)) ++i;  // the lone vertex
      const int* o = kFace[i];
      int p0 = edge_pt(v[i], v[o[0]]), p1 = edge_pt(v[i], v[o[1]]), p2 = edge_pt(v[i], v[o[2]]);
      if (np == 1)
        emit(p0, p1, p2, 0);
      else
        emit(p0, p2, p1, 0);
      continue;
    }
    int pos[2], neg[2], kp = 0, kn = 0;
    for (int a = 0; a < 4; ++a) (f[a] > 0 ? pos[kp++] : neg[kn++]) = a;
    int a = pos[0], b = pos[1], c = neg[0], d = neg[1];
    int pac = edge_pt(v[a], v[c]), pad = edge_pt(v[a], v[d]), pbd = edge_pt(v[b], v[d]), pbc = edge_pt(v[b], v[c]);
    if (even_permutation(a, b, c, d)) {
      emit(pac, pad, pbd, 0), emit(pac, pbd, pbc, 0);
    } else {
      emit(pac, pbc, pbd, 0), emit(pac, pbd, pad, 0);
    }
  }

  // 2. faces: Ω's boundary (kept parts) and non-design/design interfaces (void parts)
  // Clips the oriented triangle (x, y, z) to where keep(f) holds and emits it.
  auto clip = [&](int x, int y, int z, bool keep_positive, int tag, int lock_level) {
    int v[3] = {x, y, z};
    bool in[3];
    int nin = 0;
    for (int k = 0; k < 3; ++k) {
      double f = level(nd, v[k], threshold);
      in[k] = keep_positive ? f > 0 : f < 0;
      nin += in[k];
    }
    if (nin == 0) return;
    std::vector<int> poly;
    for (int k = 0; k < 3; ++k) {
      int a = v[k], b = v[(k + 1) % 3];
      if (in[k]) poly.push_back(node_pt(a));
      if (in[k] != in[(k + 1) % 3]) {
        int e = edge_pt(a, b);
        poly.push_back(e);
        if (lock_level == 1 && tag > 0 && lock[e] < 2)  // a point of the cut line; on two faces: fixed
          pface[e] = (pface[e] == 0 || pface[e] == tag) ? tag : -1;
      }
    }
    for (int p : poly) lock[p] = std::max(lock[p], lock_level);
    for (size_t k = 1; k + 1 < poly.size(); ++k) emit(poly[0], poly[k], poly[k + 1], tag);
  };
  std::unordered_map<std::array<int, 3>, std::pair<long, int>, Hash3> face_owner;  // face -> (tet, local)
  face_owner.reserve(2 * nt);
  std::vector<std::array<long, 2>> interfaces;  // (non-design tet, local face)
  for (long t = 0; t < nt; ++t)
    for (int i = 0; i < 4; ++i) {
      auto key = sorted3(mesh.T(t, kFace[i][0]), mesh.T(t, kFace[i][1]), mesh.T(t, kFace[i][2]));
      auto [it, fresh] = face_owner.emplace(key, std::make_pair(t, i));
      if (fresh) continue;
      long u = it->second.first;
      int ui = it->second.second;
      if (is_design(t) != is_design(u))
        interfaces.push_back(is_design(t) ? std::array<long, 2>{u, ui} : std::array<long, 2>{t, i});
      face_owner.erase(it);
    }
  // what is left in face_owner is the boundary of the mesh; Ω's face tags from mesh.F
  std::unordered_map<std::array<int, 3>, int, Hash3> face_tag;
  for (long k = 0; k < mesh.F.rows(); ++k)
    face_tag[sorted3(mesh.F(k, 0), mesh.F(k, 1), mesh.F(k, 2))] = mesh.face.size() ? mesh.face[k] : 0;
  for (const auto& [key, owner] : face_owner) {
    long t = owner.first;
    const int* o = kFace[owner.second];
    int x = mesh.T(t, o[0]), y = mesh.T(t, o[1]), z = mesh.T(t, o[2]);
    auto ft = face_tag.find(key);
    int tag = ft != face_tag.end() ? ft->second : 0;
    if (tag == 0) tag = 1 << 29;  // a boundary face the mesh did not tag: still Ω's boundary
    if (is_design(t)) {
      clip(x, y, z, true, tag, 1);
      continue;
    }
    // Ω's boundary on a non-design solid: kept whole, split where the cut of a neighbouring
    // design face meets its edges (no T-junctions), fanned from its centre.
    int v[3] = {x, y, z};
    std::vector<int> poly;
    for (int k = 0; k < 3; ++k) {
      int a = v[k], b = v[(k + 1) % 3];
      poly.push_back(node_pt(a));
      if ((level(nd, a, threshold) > 0) != (level(nd, b, threshold) > 0)) poly.push_back(edge_pt(a, b));
    }
    for (int p : poly) lock[p] = 2;
    if (poly.size() == 3) {
      emit(poly[0], poly[1], poly[2], tag);
      continue;
    }
    int centre = static_cast<int>(pts.size());
    pts.push_back((Eigen::Vector3d(mesh.V.row(x)) + Eigen::Vector3d(mesh.V.row(y)) + Eigen::Vector3d(mesh.V.row(z))) /
                  3);
    lock.push_back(2), pface.push_back(0);
    for (size_t k = 0; k < poly.size(); ++k) emit(centre, poly[k], poly[(k + 1) % poly.size()], tag);
  }
  for (const auto& [t, i] : interfaces) {
    const int* o = kFace[i];
    clip(mesh.T(t, o[0]), mesh.T(t, o[1]), mesh.T(t, o[2]), false, -mesh.domain[t], 2);
  }
  s.V.resize(pts.size(), 3);
  for (size_t i = 0; i < pts.size(); ++i) s.V.row(i) = pts[i];
  s.F.resize(tris.size(), 3);
  for (size_t i = 0; i < tris.size(); ++i) s.F.row(i) << tris[i][0], tris[i][1], tris[i][2];
  s.tag = Eigen::Map<VecXi>(tags.data(), tags.size());
  s.lock = Eigen::Map<VecXi>(lock.data(), lock.size());
  s.point_face = Eigen::Map<VecXi>(pface.data(), pface.size());
  for (int k = 0; k < s.tag.size(); ++k)
    if (s.tag[k] == (1 << 29)) s.tag[k] = 0;
  // planes of planar Ω faces
  int max_face = mesh.face.size() ? mesh.face.maxCoeff() : 0;
  s.face_plane.assign(max_face + 1, Eigen::Vector4d::Zero());
  std::vector<char> bad(max_face + 1, 0), seen(max_face + 1, 0);
  for (long k = 0; k < mesh.F.rows(); ++k) {
    int f = mesh.face.size() ? mesh.face[k] : 0;
    if (f <= 0) continue;
    Eigen::Vector3d a = mesh.V.row(mesh.F(k, 0)), b = mesh.V.row(mesh.F(k, 1)), c = mesh.V.row(mesh.F(k, 2));
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() == 0) continue;
    n.normalize();
    if (!seen[f]) {
      seen[f] = 1;
      s.face_plane[f] << n, n.dot(a);
    } else if (!bad[f]) {
      Eigen::Vector3d n0 = s.face_plane[f].head<3>();
      if (n.dot(n0) < 1 - 1e-9 || std::abs(n0.dot(a) - s.face_plane[f][3]) > 1e-7 * (1 + std::abs(s.face_plane[f][3])))
        bad[f] = 1;
    }
  }
  for (int f = 0; f <= max_face; ++f)
    if (bad[f]) s.face_plane[f].setZero();
  return s;
}

SurfaceCheck check_surface(const MatX3d& V, const MatX3i& F) {
  SurfaceCheck c;
  std::map<std::pair<int, int>, int> directed;
  for (long t = 0; t < F.rows(); ++t)
    for (int k = 0; k < 3; ++k) directed[{F(t, k), F(t, (k + 1) % 3)}]++;
  for (const auto& [e, n] : directed) {
    auto back = directed.find({e.second, e.first});
    int m = back == directed.end() ? 0 : back->second;
    if (n > 1) c.overshared_edges++;
    if (m == 0)
      c.open_edges++;
    else if (n != m)
      c.misoriented_edges++;
  }
  for (long t = 0; t < F.rows(); ++t) {
    Eigen::Vector3d a = V.row(F(t, 0)), b = V.row(F(t, 1)), d = V.row(F(t, 2));
    c.volume += a.dot(b.cross(d)) / 6.0;
  }
  return c;
}

}  // namespace topopt::result
