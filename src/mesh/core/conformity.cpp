#include "mesh/core/conformity.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

#include "brep/point_locator.h"
#include "common/face_key.h"

namespace topopt::mesh {

bool ConformityReport::ok() const {
  return inverted_tets == 0 && duplicate_nodes == 0 && overshared_faces == 0 && boundary_not_in_F == 0 &&
         F_not_boundary == 0 && open_boundary_edges == 0 && interface_off_nondesign == 0 && volumes_ok;
}

nlohmann::json ConformityReport::to_json() const {
  return {{"ok", ok()},
          {"nodes", nodes},
          {"tets", tets},
          {"boundary_triangles", boundary_triangles},
          {"inverted_tets", inverted_tets},
          {"duplicate_nodes", duplicate_nodes},
          {"overshared_faces", overshared_faces},
          {"boundary_not_in_F", boundary_not_in_F},
          {"F_not_boundary", F_not_boundary},
          {"open_boundary_edges", open_boundary_edges},
          {"interface_triangles", interface_triangles},
          {"interface_sampled", interface_sampled},
          {"interface_off_nondesign", interface_off_nondesign},
          {"domain_volume", domain_volume},
          {"expected_volume", expected_volume},
          {"max_volume_error", max_volume_error}};
}

namespace {

using Key3 = FaceKey;
using Key3Hash = FaceKeyHash;
Key3 sorted(int a, int b, int c) { return face_key(a, b, c); }

double signed_volume(const TetMesh& m, int t) {
  Eigen::Vector3d a = m.V.row(m.T(t, 1)) - m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 2)) - m.V.row(m.T(t, 0)),
                  c = m.V.row(m.T(t, 3)) - m.V.row(m.T(t, 0));
  return a.cross(b).dot(c) / 6.0;
}

int count_duplicates(const MatX3d& V, double tol) {
  // Hash nodes into cells of size tol; compare with the 27 neighbouring cells.
  std::unordered_map<long long, std::vector<int>> cells;
  auto key = [&](long long i, long long j, long long k) {
    return (i * 73856093LL) ^ (j * 19349663LL) ^ (k * 83492791LL);
  };
  auto cell = [&](double x) { return static_cast<long long>(std::floor(x / tol)); };
  int dup = 0;
  for (int v = 0; v < V.rows(); ++v) {
    long long ci = cell(V(v, 0)), cj = cell(V(v, 1)), ck = cell(V(v, 2));
    bool found = false;
    for (long long di = -1; di <= 1 && !found; ++di)
      for (long long dj = -1; dj <= 1 && !found; ++dj)
        for (long long dk = -1; dk <= 1 && !found; ++dk) {
          auto it = cells.find(key(ci + di, cj + dj, ck + dk));
          if (it == cells.end()) continue;
          for (int w : it->second)
            if ((V.row(v) - V.row(w)).norm() <= tol) {
              found = true;
              break;
            }
        }
    dup += found;
    cells[key(ci, cj, ck)].push_back(v);
  }
  return dup;
}

}  // namespace

ConformityReport check_conformity(const TetMesh& m, const brep::TwoBReps* geometry, const ConformityParams& params) {
  ConformityReport r;
  r.nodes = static_cast<int>(m.V.rows());
  r.tets = static_cast<int>(m.T.rows());
  r.boundary_triangles = static_cast<int>(m.F.rows());
  if (r.nodes == 0) return r;

  const double diag = (m.V.colwise().maxCoeff() - m.V.colwise().minCoeff()).norm();
  r.duplicate_nodes = count_duplicates(m.V, params.duplicate_tolerance > 0 ? params.duplicate_tolerance : 1e-9 * diag);

  int num_domains = m.domain.size() ? m.domain.maxCoeff() + 1 : 1;
  if (geometry) num_domains = std::max(num_domains, geometry->nondesign.num_solids() + 1);
  r.domain_volume.assign(num_domains, 0.0);

  // Tet faces: (sorted key) → (count, first tet).
  std::unordered_map<Key3, std::pair<int, int>, Key3Hash> faces;
  faces.reserve(4 * m.T.rows());
  const auto& local = kTetFace;
  std::vector<std::pair<Key3, std::pair<int, int>>> interfaces;  // key, (tet a, tet b)
  for (int t = 0; t < m.T.rows(); ++t) {
    double v = signed_volume(m, t);
    if (!(v > 0)) ++r.inverted_tets;
    int d = m.domain.size() ? m.domain[t] : 0;
    if (d >= 0 && d < num_domains) r.domain_volume[d] += v;
    for (const auto& f : local) {
      Key3 k = sorted(m.T(t, f[0]), m.T(t, f[1]), m.T(t, f[2]));
      auto [it, inserted] = faces.try_emplace(k, 1, t);
      if (!inserted) {
        if (++it->second.first == 2 && m.domain.size() && m.domain[it->second.second] != m.domain[t])
          interfaces.push_back({k, {it->second.second, t}});
      }
    }
  }
  std::unordered_map<Key3, int, Key3Hash> boundary;
  for (int f = 0; f < m.F.rows(); ++f) boundary[sorted(m.F(f, 0), m.F(f, 1), m.F(f, 2))] = f;
  for (const auto& [k, info] : faces) {
    if (info.first > 2) ++r.overshared_faces;
    if (info.first == 1 && !boundary.count(k)) ++r.boundary_not_in_F;
  }
  for (const auto& [k, f] : boundary) {
    auto it = faces.find(k);
    if (it == faces.end() || it->second.first != 1) ++r.F_not_boundary;
  }
  // Closed, consistently oriented boundary: each directed edge once, its reverse once.
  std::unordered_map<long long, int> directed;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int e = 0; e < 3; ++e) ++directed[static_cast<long long>(m.F(f, e)) * r.nodes + m.F(f, (e + 1) % 3)];
  for (const auto& [key, n] : directed) {
    long long a = key / r.nodes, b = key % r.nodes;
    auto rev = directed.find(b * r.nodes + a);
    if (n != 1 || rev == directed.end() || rev->second != 1) ++r.open_boundary_edges;
  }

  r.interface_triangles = static_cast<int>(interfaces.size());
  if (geometry) {
    r.expected_volume.assign(num_domains, 0.0);
    double nd_total = 0;
    for (int i = 0; i < geometry->nondesign.num_solids(); ++i) {
      r.expected_volume[i + 1] = std::abs(geometry->nondesign.solid_volume[i]);
      nd_total += r.expected_volume[i + 1];
    }
    r.expected_volume[0] = std::abs(geometry->part.solid_volume[0]) - nd_total;
    for (int d = 0; d < num_domains; ++d) {
      if (r.expected_volume[d] <= 0) continue;
      double err = std::abs(r.domain_volume[d] - r.expected_volume[d]) / r.expected_volume[d];
      r.max_volume_error = std::max(r.max_volume_error, err);
    }
    r.volumes_ok = r.max_volume_error <= params.volume_tolerance;

    // Interface triangles must lie on Ω̄'s faces: test their centroids.
    const double tol = 1e-6 * std::max(geometry->part.diagonal(), 1.0);
    brep::PointLocator locate(geometry->nondesign, tol);
    const int n = static_cast<int>(interfaces.size());
    const int step = std::max(1, n / std::max(1, params.max_interface_samples));
    for (int i = 0; i < n; i += step) {
      const Key3& k = interfaces[i].first;
      Eigen::RowVector3d c = (m.V.row(k[0]) + m.V.row(k[1]) + m.V.row(k[2])) / 3.0;
      // A flat triangle's centroid is off a curved face by its sagitta: allow the edge length
      // times a small factor as extra tolerance.
      double h = std::max({(m.V.row(k[0]) - m.V.row(k[1])).norm(), (m.V.row(k[1]) - m.V.row(k[2])).norm(),
                           (m.V.row(k[2]) - m.V.row(k[0])).norm()});
      ++r.interface_sampled;
      if (locate.faces_at(gp_Pnt(c[0], c[1], c[2]), 0.05 * h).empty()) ++r.interface_off_nondesign;
    }
  }
  return r;
}

}  // namespace topopt::mesh
