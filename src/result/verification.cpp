// Verification of the result shape by analysis (see verification.h).
#include "result/verification.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <set>

#include <unordered_map>

#include "common/cpu_time.h"
#include "common/error.h"
#include "common/isolate.h"
#include "common/number_text.h"
#include "fem/elasticity.h"
#include "fem/kept_part.h"
#include "result/design_hygiene.h"

namespace topopt::result {
namespace {

/// v with 4 significant digits ("311.9", "1.234e+05"), as the other messages print figures.
std::string four_digits(double v) { return number_text(v, 4); }

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

Eigen::Vector3d corner(const MatX3d& V, const MatX3i& F, long q, int k) { return V.row(F(q, k)).transpose(); }

/// How far point p lies from triangle q of (V, F): its distance to the plane plus how far its
/// projection falls outside the triangle (barycentric coordinates below 0, scaled by size).
double off_triangle(const MatX3d& V, const MatX3i& F, long q, const Eigen::Vector3d& p) {
  const Eigen::Vector3d a = corner(V, F, q, 0), b = corner(V, F, q, 1), c = corner(V, F, q, 2);
  const Eigen::Vector3d n = (b - a).cross(c - a);
  const double area2 = n.squaredNorm();
  if (area2 <= 0) return 1e300;
  const double wa = (b - p).cross(c - p).dot(n) / area2, wb = (c - p).cross(a - p).dot(n) / area2;
  const double wc = 1 - wa - wb;
  const double outside = std::max({0.0, -wa, -wb, -wc}) * std::sqrt(std::sqrt(area2));
  return std::abs((p - a).dot(n)) / std::sqrt(area2) + outside;
}

/// FE boundary triangles binned by centroid on a grid of cells as large as the longest edge.
class BoundaryGrid {
 public:
  explicit BoundaryGrid(const TetMesh& fe) : fe_(fe) {
    for (long q = 0; q < fe.F.rows(); ++q)
      for (int k = 0; k < 3; ++k)
        cell_ = std::max(cell_, (corner(fe.V, fe.F, q, k) - corner(fe.V, fe.F, q, (k + 1) % 3)).norm());
    for (long q = 0; q < fe.F.rows(); ++q) bins_[key(centroid(fe.V, fe.F, q), 0, 0, 0)].push_back(q);
  }

  /// The boundary triangle of Ω's face `face` that p lies on (the nearest by off_triangle), -1 if none is near.
  long nearest(const Eigen::Vector3d& p, int face) const {
    long best = -1;
    double best_off = 1e300;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j)
        for (int k = -1; k <= 1; ++k) {
          const auto it = bins_.find(key(p, i, j, k));
          if (it == bins_.end()) continue;
          for (long q : it->second) {
            if (fe_.face.size() && fe_.face[q] != face) continue;
            const double off = off_triangle(fe_.V, fe_.F, q, p);
            if (off < best_off) best_off = off, best = q;
          }
        }
    return best;
  }

  static Eigen::Vector3d centroid(const MatX3d& V, const MatX3i& F, long q) {
    return (corner(V, F, q, 0) + corner(V, F, q, 1) + corner(V, F, q, 2)) / 3;
  }

 private:
  long long key(const Eigen::Vector3d& p, int i, int j, int k) const {
    const double h = cell_ > 0 ? cell_ : 1;
    const long long x = static_cast<long long>(std::floor(p.x() / h)) + i,
                    y = static_cast<long long>(std::floor(p.y() / h)) + j,
                    z = static_cast<long long>(std::floor(p.z() / h)) + k;
    return (x & 0x1FFFFF) | ((y & 0x1FFFFF) << 21) | ((z & 0x1FFFFF) << 42);
  }
  const TetMesh& fe_;
  double cell_ = 0;
  std::unordered_map<long long, std::vector<long>> bins_;
};

/// #F of the result surface: the non-design face of the FE boundary triangle each triangle on
/// Ω's face lies on (0 elsewhere, and everywhere when the FE mesh has none).
VecXi nd_faces_of(const MatX3d& V, const MatX3i& F, const VecXi& face, const TetMesh& fe) {
  VecXi nd = VecXi::Zero(F.rows());
  if (fe.nd_face.size() != fe.F.rows() || (fe.nd_face.array() == 0).all()) return nd;
  const BoundaryGrid grid(fe);
  for (long q = 0; q < F.rows(); ++q) {
    if (face[q] <= 0) continue;
    const long on = grid.nearest(BoundaryGrid::centroid(V, F, q), face[q]);
    if (on >= 0) nd[q] = fe.nd_face[on];
  }
  return nd;
}

/// A Progress that answers "cancelled" once `deadline` has passed (or when `outer` says so).
Progress with_deadline(const Progress& outer, std::chrono::steady_clock::time_point deadline, bool limited) {
  Progress p = outer;
  p.cancelled = [outer, deadline, limited]() {
    return (limited && std::chrono::steady_clock::now() > deadline) || (outer.cancelled && outer.cancelled());
  };
  return p;
}

/// The bytes of a fill's nodes and tets (row counts, then the raw arrays), and back.
std::string pack(const mesh::VolumeFillResult& r) {
  const long nv = r.V.rows(), nt = r.T.rows();
  std::string b(2 * sizeof(long) + nv * 3 * sizeof(double) + nt * 4 * sizeof(int), '\0');
  char* p = b.data();
  std::memcpy(p, &nv, sizeof nv), std::memcpy(p + sizeof nv, &nt, sizeof nt);
  std::memcpy(p + 2 * sizeof(long), r.V.data(), nv * 3 * sizeof(double));
  std::memcpy(p + 2 * sizeof(long) + nv * 3 * sizeof(double), r.T.data(), nt * 4 * sizeof(int));
  return b;
}

mesh::VolumeFillResult unpack(const std::string& b) {
  long nv = 0, nt = 0;
  if (b.size() < 2 * sizeof(long)) throw Error(ErrorCode::Internal, "the result's volume mesh came back cut short");
  std::memcpy(&nv, b.data(), sizeof nv), std::memcpy(&nt, b.data() + sizeof nv, sizeof nt);
  if (nv < 0 || nt < 0 || b.size() != 2 * sizeof(long) + nv * 3 * sizeof(double) + nt * 4 * sizeof(int))
    throw Error(ErrorCode::Internal, "the result's volume mesh came back cut short");
  mesh::VolumeFillResult r;
  r.V.resize(nv, 3), r.T.resize(nt, 4);
  std::memcpy(r.V.data(), b.data() + 2 * sizeof(long), nv * 3 * sizeof(double));
  std::memcpy(r.T.data(), b.data() + 2 * sizeof(long) + nv * 3 * sizeof(double), nt * 4 * sizeof(int));
  return r;
}

/// Throws Error(FaceNotFound) naming the first face of Ω that a support or a face load of
/// `problem` acts on and that the result solid `m` has no triangle of: the design removed the
/// material there, so the load or support has nothing to act on.
void check_faces_kept(const TetMesh& m, const VerificationProblem& problem) {
  std::vector<char> present;
  for (long q = 0; q < m.face.size(); ++q) {
    if (m.face[q] >= static_cast<long>(present.size())) present.resize(m.face[q] + 1, 0);
    if (m.face[q] > 0) present[m.face[q]] = 1;
  }
  const auto gone = [&](int f) { return f <= 0 || f >= static_cast<int>(present.size()) || !present[f]; };
  const std::string fix =
      ": keep \"optimization.keep_loaded_faces\" on (the default keeps a layer of material on every loaded or "
      "supported face), add a non-design solid (a load pad) there, or lower the threshold";
  for (const fem::LoadCase& lc : problem.load_cases)
    for (const fem::LoadSpec& l : lc.items)
      for (int f : l.faces)
        if (l.kind != fem::LoadSpec::Kind::Gravity && gone(f))
          throw Error(ErrorCode::FaceNotFound, "the design removed the material under the load on Face" +
                                                   std::to_string(f) + " (load case \"" + lc.name +
                                                   "\"): the result solid has none of that face" + fix);
  for (const fem::SupportSpec& sp : problem.supports)
    for (int f : sp.faces)
      if (gone(f))
        throw Error(ErrorCode::FaceNotFound, "the design removed the material on the supported Face" +
                                                 std::to_string(f) + ": the result solid has none of that face" + fix);
}

/// Keeps in `m` only the pieces (tets sharing nodes) that carry the loads by the hygiene's rule
/// (piece_fates, as for the density field and the finished surface): a piece touches a support
/// where it holds a fixed dof of `problem`'s supports, a load where a load of it acts on a node,
/// and holds non-design material where a triangle of it has a negative tag in `tag` (#F of m,
/// the result surface's tags). Returns the volumes of the pieces left out. Throws
/// Error(NoSupport) naming a piece with a load on it that is left out or that no support holds.
std::vector<double> drop_unheld_pieces(TetMesh& m, const VecXi& tag, const VerificationProblem& problem) {
  int count = 0;
  const VecXi piece = node_components(m, std::vector<char>(m.T.rows(), 1), count);
  if (count <= 1) return {};
  std::vector<PieceFacts> facts(count);
  std::vector<int> piece_of_node(m.V.rows(), -1);
  for (long t = 0; t < m.T.rows(); ++t)
    for (int k = 0; k < 4; ++k) piece_of_node[m.T(t, k)] = piece[t];
  for (int d : fem::make_supports(m, problem.supports).dofs)
    if (piece_of_node[d / 3] >= 0) facts[piece_of_node[d / 3]].touch |= kAnchorSupport;
  const Eigen::MatrixXd loads = fem::make_loads(m, problem.material, problem.load_cases);
  for (long i = 0; i < m.V.rows(); ++i)
    if (piece_of_node[i] >= 0 && loads.middleRows(3 * i, 3).cwiseAbs().maxCoeff() > 0)
      facts[piece_of_node[i]].touch |= kAnchorLoad;
  for (long q = 0; q < std::min<long>(tag.size(), m.F.rows()); ++q)
    if (tag[q] < 0 && piece_of_node[m.F(q, 0)] >= 0) facts[piece_of_node[m.F(q, 0)]].nondesign = true;
  std::vector<Eigen::Vector3d> centre(count, Eigen::Vector3d::Zero());
  for (long t = 0; t < m.T.rows(); ++t) {
    const Eigen::Vector3d a = m.V.row(m.T(t, 0)), b = m.V.row(m.T(t, 1)), c = m.V.row(m.T(t, 2)),
                          d = m.V.row(m.T(t, 3));
    const double v = (b - a).dot((c - a).cross(d - a)) / 6;
    facts[piece[t]].volume += v, centre[piece[t]] += v * (a + b + c + d) / 4;
  }
  const std::vector<PieceFate> fate = piece_fates(facts);
  std::vector<double> dropped;
  for (int k = 0; k < count; ++k) {
    const bool kept = fate[k] == PieceFate::Carries;
    if (facts[k].touch & kAnchorLoad && (!kept || !(facts[k].touch & kAnchorSupport))) {
      const Eigen::Vector3d c = centre[k] / std::max(facts[k].volume, 1e-300);
      throw Error(ErrorCode::NoSupport, "a load acts on a piece of the result (" +
                                            std::to_string(static_cast<long>(facts[k].volume)) + " mm³ around (" +
                                            std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " +
                                            std::to_string(c.z()) +
                                            ")) that no support holds: the design does not carry it; give more volume "
                                            "(\"optimization.volume_fraction\") or a lower threshold");
    }
    if (!kept) dropped.push_back(facts[k].volume);
  }
  if (dropped.empty()) return {};
  std::vector<char> keep(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) keep[t] = fate[piece[t]] == PieceFate::Carries;
  m = fem::kept_part(m, keep, fem::KeptNodes::Compact);
  return dropped;
}

/// `problem` with each support cut to the faces (Ω's and non-design) that `m` still has: the
/// pieces drop_unheld_pieces left out take the faces only they held with them (a bolt boss
/// that carries no load); a support left with no face is dropped.
VerificationProblem on_kept_faces(const TetMesh& m, const VerificationProblem& problem) {
  std::set<int> faces, nd_faces;
  for (long q = 0; q < m.face.size(); ++q) faces.insert(m.face[q]);
  for (long q = 0; q < m.nd_face.size(); ++q) nd_faces.insert(m.nd_face[q]);
  VerificationProblem kept = problem;
  kept.supports.clear();
  for (fem::SupportSpec sp : problem.supports) {
    const auto gone = [](const std::set<int>& have) { return [&have](int f) { return have.count(f) == 0; }; };
    sp.faces.erase(std::remove_if(sp.faces.begin(), sp.faces.end(), gone(faces)), sp.faces.end());
    sp.nd_faces.erase(std::remove_if(sp.nd_faces.begin(), sp.nd_faces.end(), gone(nd_faces)), sp.nd_faces.end());
    if (!sp.faces.empty() || !sp.nd_faces.empty()) kept.supports.push_back(sp);
  }
  return kept;
}

/// Warns through progress when the result solid's largest von Mises stress (v.as_built) exceeds
/// problem.stress_limit, naming the load case and the place of the tet that carries it and the
/// crisp design's largest stress on the FE mesh. SIMP holds the limit on the relaxed stresses of
/// its element densities; the result cut from the node densities and smoothed can hold thinner
/// members (the cantilever on junction24's cut: as built 415 MPa under a limit of 290, 468 on a
/// 2 mm mesh, 294 at threshold 0.36 instead of 0.42; BENCHMARKS.md, branch stress25).
void warn_over_stress_limit(const Verification& v, const VerificationProblem& problem, const Progress& progress) {
  const double limit = problem.stress_limit;
  if (!(limit > 0) || !(v.as_built.max_von_mises > limit)) return;
  long case_at = 0, tet_at = 0;
  for (size_t c = 0; c < v.von_mises.size(); ++c)
    for (long t = 0; t < v.von_mises[c].size(); ++t)
      if (v.von_mises[c][t] > v.von_mises[case_at][tet_at]) case_at = static_cast<long>(c), tet_at = t;
  const Eigen::Vector3d at = tet_centre(v.mesh, tet_at);
  const std::string name =
      case_at < static_cast<long>(problem.load_cases.size()) ? problem.load_cases[case_at].name : "";
  progress.warn("verification: the result solid's largest von Mises stress, " + four_digits(v.as_built.max_von_mises) +
                " MPa (load case \"" + name + "\", at (" + four_digits(at.x()) + ", " + four_digits(at.y()) + ", " +
                four_digits(at.z()) + ") mm), exceeds the stress limit of " + four_digits(limit) + " MPa by " +
                four_digits(100 * (v.as_built.max_von_mises / limit - 1)) +
                " %; the crisp design of the same cut on the FE mesh reaches " + four_digits(v.crisp.max_von_mises) +
                " MPa. The optimisation holds the limit on the relaxed stresses of its element densities; the result, "
                "cut from node densities and smoothed, holds thinner members. A lower threshold (more material) "
                "lowers the stress");
}

}  // namespace

TetMesh verification_mesh(const TriSurface& s, const TetMesh& fe, const mesh::VolumeFillParams& fill, double seconds,
                          const Progress& progress) {
  std::vector<int> index(s.V.rows(), -1);
  int used = 0;
  for (long q = 0; q < s.F.rows(); ++q)
    for (int k = 0; k < 3; ++k)
      if (index[s.F(q, k)] < 0) index[s.F(q, k)] = used++;
  MatX3d V(used, 3);
  for (long i = 0; i < s.V.rows(); ++i)
    if (index[i] >= 0) V.row(index[i]) = s.V.row(i);
  MatX3i F(s.F.rows(), 3);
  for (long q = 0; q < s.F.rows(); ++q)
    for (int k = 0; k < 3; ++k) F(q, k) = index[s.F(q, k)];
  // in a child with a hard deadline: the front's inner loops do not all look at the clock
  const mesh::VolumeFillResult filled = unpack(run_isolated(
      "meshing the result solid", seconds,
      [&]() {
        Progress quiet;  // the child says nothing (the worker's stdout is its protocol)
        quiet.cancelled = progress.cancelled;
        return pack(mesh::fill_volume(V, F, MatX4i(0, 4), fill, quiet));
      },
      progress));
  TetMesh m;
  m.V = filled.V;
  m.T = filled.T;
  m.domain = VecXi::Zero(m.T.rows());
  m.F = F;
  m.face = s.tag.cwiseMax(0);
  m.nd_face = nd_faces_of(V, F, m.face, fe);
  return m;
}

AnalysisFigures analyse(const TetMesh& mesh, const TetMesh& loaded, const VerificationProblem& problem,
                        const VecXd& scale, const fem::SolverParams& solver, const Progress& progress,
                        Eigen::MatrixXd* U, std::vector<VecXd>* von_mises) {
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = process_cpu_seconds();
  const fem::Supports supports = fem::make_supports(mesh, problem.supports);
  const Eigen::MatrixXd loads = fem::make_loads(loaded, problem.material, problem.load_cases);
  fem::Elasticity fe(mesh, problem.material, supports, solver);
  if (scale.size()) fe.set_scale(scale);
  const Eigen::MatrixXd u = fe.solve(loads, progress);
  AnalysisFigures a;
  std::vector<char> node_used(mesh.V.rows(), 0);
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (!scale.size() || scale[t] >= 1)
      for (int k = 0; k < 4; ++k) node_used[mesh.T(t, k)] = 1;
  for (long c = 0; c < loads.cols(); ++c) {
    a.compliance += problem.load_cases[c].weight * loads.col(c).dot(u.col(c));
    for (long i = 0; i < mesh.V.rows(); ++i)
      if (node_used[i]) a.max_displacement = std::max(a.max_displacement, u.col(c).segment<3>(3 * i).norm());
    const VecXd vm = fe.von_mises(u.col(c));
    for (long t = 0; t < mesh.T.rows(); ++t)
      if (!scale.size() || scale[t] >= 1) a.max_von_mises = std::max(a.max_von_mises, vm[t]);
    if (von_mises) von_mises->push_back(vm);
  }
  a.nodes = std::count(node_used.begin(), node_used.end(), 1);
  a.tets = scale.size() ? (scale.array() >= 1).count() : mesh.T.rows();
  a.seconds = seconds_since(t0);
  a.cpu_seconds = process_cpu_seconds() - cpu0;
  if (U) *U = u;
  return a;
}

Verification verify_result(const TriSurface& s, const TetMesh& fe, const VecXd& design, double threshold,
                           const VerificationProblem& problem, const VerificationParams& params,
                           const Progress& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto deadline = t0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                 std::chrono::duration<double>(std::max(0.0, params.seconds)));
  const Progress timed = with_deadline(progress, deadline, params.seconds > 0);
  const auto out_of_time = [&](const std::string& step) {
    if (progress.cancelled && progress.cancelled()) throw Error(ErrorCode::Cancelled, "cancelled during " + step);
    throw Error(ErrorCode::Timeout, step + " ran past the verification's time budget of " +
                                        std::to_string(static_cast<int>(params.seconds)) +
                                        " s; the result files are written, only the verification is missing");
  };
  Verification v;
  const double child_cpu0 = children_cpu_seconds(), cpu0 = process_cpu_seconds();
  try {
    v.mesh = verification_mesh(s, fe, params.fill, params.seconds, timed);
  } catch (const Error& e) {
    if (e.code() == ErrorCode::Cancelled || e.code() == ErrorCode::Timeout) out_of_time("meshing the result solid");
    throw;
  }
  check_faces_kept(v.mesh, problem);
  v.unheld_volumes = drop_unheld_pieces(v.mesh, s.tag, problem);
  for (double vol : v.unheld_volumes)
    progress.warn("verification: a piece of the result of " + std::to_string(static_cast<long>(vol)) +
                  " mm³ that carries no load (a detached non-design solid?) is left out");
  const double seconds_mesh = seconds_since(t0);
  const double cpu_mesh = children_cpu_seconds() - child_cpu0 + process_cpu_seconds() - cpu0;
  // the crisp design on the FE mesh: removed tets keep void_stiffness, only kept tets weigh
  const std::vector<char> kept = crisp_tets(fe, node_densities(fe, design), threshold);
  VecXd scale(fe.T.rows());
  for (long t = 0; t < fe.T.rows(); ++t) scale[t] = kept[t] ? 1.0 : params.void_stiffness;
  // loads on the kept tets and their boundary triangles only: a load face the design keeps only
  // in part is loaded where material is, as on the result solid, and no force lands on nodes
  // held by removed tets alone (their void stiffness made the compliance ~10^7 times the
  // as-built one on a top-loaded box)
  const TetMesh loaded = fem::kept_part(fe, kept);
  try {
    const VerificationProblem held = v.unheld_volumes.empty() ? problem : on_kept_faces(v.mesh, problem);
    v.as_built = analyse(v.mesh, v.mesh, held, VecXd(), params.solver, timed, &v.U, &v.von_mises);
    v.as_built.seconds += seconds_mesh;
    v.as_built.cpu_seconds += cpu_mesh;
    v.crisp = analyse(fe, loaded, problem, scale, params.solver, timed);
  } catch (const Error& e) {
    if (e.code() == ErrorCode::Cancelled) out_of_time("solving the verification");
    throw;
  }
  if (!v.crisp_carries_load())
    progress.warn(
        "verification: the crisp design on the FE mesh (the tets whose mean density reaches the threshold) "
        "does not carry the load (compliance " +
        four_digits(v.crisp.compliance) + " N·mm against the result solid's " + four_digits(v.as_built.compliance) +
        "): members of the result are thinner than one FE tet, as in a design that has not converged. "
        "Raise optimization.max_iterations (MaxIterations in the study) or refine mesh.size");
  warn_over_stress_limit(v, problem, progress);
  return v;
}

}  // namespace topopt::result
