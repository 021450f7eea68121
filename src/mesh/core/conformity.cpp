#include "mesh/core/conformity.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <unordered_map>

#include "brep/point_locator.h"
#include "common/error.h"
#include "common/face_key.h"
#include "mesh/core/predicates.h"
#include "mesh/core/tet_quality.h"

namespace topopt::mesh {

bool ConformityReport::ok() const {
  return inverted_tets == 0 && flat_tets == 0 && duplicate_nodes == 0 && overshared_faces == 0 &&
         boundary_not_in_F == 0 && F_not_boundary == 0 && open_boundary_edges == 0 && interface_off_nondesign == 0 &&
         volumes_ok;
}

nlohmann::json ConformityReport::to_json() const {
  nlohmann::json worst = nlohmann::json::array();
  for (const TetDefect& d : worst_tets) worst.push_back(d.to_json());
  return {{"ok", ok()},
          {"nodes", nodes},
          {"tets", tets},
          {"boundary_triangles", boundary_triangles},
          {"inverted_tets", inverted_tets},
          {"flat_tets", flat_tets},
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
          {"max_volume_error", max_volume_error},
          {"worst_tets", worst}};
}

nlohmann::json TetDefect::to_json() const {
  return {{"tet", tet},
          {"centroid", {centroid.x(), centroid.y(), centroid.z()}},
          {"radius_ratio", radius_ratio},
          {"min_dihedral", min_dihedral},
          {"orientation", orientation}};
}

namespace {

std::string where(const TetDefect& d) {
  std::ostringstream s;
  s << "tet " << d.tet << " near (" << d.centroid.x() << ", " << d.centroid.y() << ", " << d.centroid.z()
    << ") with radius ratio " << d.radius_ratio << " and smallest dihedral angle " << d.min_dihedral << "°";
  return s.str();
}

/// "<n> <what>, the worst <tet> near (x, y, z) ..." for the first defect of that orientation.
void describe_tets(std::ostringstream& s, const ConformityReport& r, int n, const char* what, int orientation) {
  if (n == 0) return;
  s << "; " << n << " " << what;
  for (const TetDefect& d : r.worst_tets)
    if (d.orientation == orientation || (orientation == 0 && d.orientation > 0)) {
      s << ", the worst " << where(d);
      break;
    }
}

}  // namespace

std::string ConformityReport::describe() const {
  if (ok()) return "";
  std::ostringstream s;
  describe_tets(s, *this, inverted_tets, "inverted tets (negative volume)", -1);
  describe_tets(s, *this, flat_tets, "flat tets (four nodes on one plane, or nearly)", 0);
  const std::pair<int, const char*> counts[] = {
      {duplicate_nodes, "nodes at the place of another node"},
      {overshared_faces, "tet faces shared by more than two tets"},
      {boundary_not_in_F, "free tet faces that are not boundary triangles (holes)"},
      {F_not_boundary, "boundary triangles that are not the face of exactly one tet"},
      {open_boundary_edges, "open or inconsistently oriented boundary edges"},
      {interface_off_nondesign, "faces between design and non-design tets that lie on no non-design face"}};
  for (const auto& [n, what] : counts)
    if (n) s << "; " << n << " " << what;
  if (!volumes_ok) s << "; a domain's volume is " << 100 * max_volume_error << " % off its solid's";
  return s.str().substr(2);
}

void require_valid_mesh(const ConformityReport& report, const std::string& what) {
  if (!report.ok()) throw Error(ErrorCode::MeshingFailed, what + " is not a valid mesh: " + report.describe());
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

/// The tets on their own: exact orientation (inverted and flat ones counted), volume per
/// domain, and the `worst_reported` worst of them.
void check_tets(const TetMesh& m, const ConformityParams& params, ConformityReport& r) {
  std::vector<std::pair<double, int>> candidates;  // (sort key, tet): the worst so far
  const size_t keep = static_cast<size_t>(std::max(params.worst_reported, 0));
  for (int t = 0; t < m.T.rows(); ++t) {
    const Eigen::Vector3d a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)),
                          d = m.V.row(m.T(t, 3));
    const int o = predicates::orient3d(a.data(), b.data(), c.data(), d.data());
    const double rho = o > 0 ? radius_ratio(a, b, c, d) : 0;
    if (o < 0) ++r.inverted_tets;
    if (o == 0 || (o > 0 && rho < params.flat_below)) ++r.flat_tets;
    const int dom = m.domain.size() ? m.domain[t] : 0;
    if (dom >= 0 && dom < static_cast<int>(r.domain_volume.size())) r.domain_volume[dom] += signed_volume(m, t);
    const double key = o < 0 ? -2.0 : (o == 0 ? -1.0 : rho);
    if (candidates.size() < keep || (keep && key < candidates.back().first)) {
      candidates.insert(std::upper_bound(candidates.begin(), candidates.end(), std::make_pair(key, t)), {key, t});
      if (candidates.size() > keep) candidates.pop_back();
    }
  }
  for (const auto& [key, t] : candidates) {
    const Eigen::Vector3d a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)),
                          d = m.V.row(m.T(t, 3));
    TetDefect x;
    x.tet = t;
    x.centroid = (a + b + c + d) / 4.0;
    x.orientation = key == -2.0 ? -1 : (key == -1.0 ? 0 : 1);
    x.radius_ratio = radius_ratio(a, b, c, d);
    x.min_dihedral = dihedral_range(a, b, c, d).first;
    r.worst_tets.push_back(x);
  }
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
  check_tets(m, params, r);
  for (int t = 0; t < m.T.rows(); ++t) {
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
