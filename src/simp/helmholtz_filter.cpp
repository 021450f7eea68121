// The PDE (Helmholtz) density filter: assembly on the design nodes and the solves (see
// helmholtz_filter.h).
#include "simp/helmholtz_filter.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_set>

#include "common/error.h"
#include "common/face_key.h"
#include "common/parallel.h"
#include "common/tet_boundary.h"
#include "fem/pcg.h"

namespace topopt::simp {
namespace {

/// z = D⁻¹ r: the diagonal of ℓ²K + M is within a small factor of its row sums (a mass matrix
/// plus a Laplacian of modest weight), so Jacobi is all the preconditioning it needs.
class JacobiPreconditioner final : public fem::Preconditioner {
 public:
  explicit JacobiPreconditioner(const VecXd& inverse_diagonal) : inverse_diagonal_(inverse_diagonal) {}
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const override { z = r.cwiseProduct(inverse_diagonal_); }

 private:
  const VecXd& inverse_diagonal_;
};

}  // namespace

Eigen::Matrix4d helmholtz_element_matrix(const Eigen::Matrix<double, 4, 3>& p, double length) {
  Eigen::Matrix3d J;
  for (int k = 0; k < 3; ++k) J.row(k) = p.row(k + 1) - p.row(0);
  const double volume = std::abs(J.determinant()) / 6.0;
  Eigen::Matrix<double, 3, 4> G;
  G.rightCols<3>() = J.inverse();  // column k: the gradient of ξ_k = N_(k+1)
  G.col(0) = -G.rightCols<3>().rowwise().sum();
  Eigen::Matrix4d A = (length * length * volume) * (G.transpose() * G);
  A += (volume / 20.0) * (Eigen::Matrix4d::Ones() + Eigen::Matrix4d::Identity());
  return A;
}

// Measured (bench/simp/filters.py --helmholtz-solvers, cantilever 181 k tets, 8 iterations,
// 1 thread), CPU Jacobi / multigrid: 0.78 at ℓ/h = 0.99, 0.84 at 1.98, 1.37 at 3.30; the ratio
// crosses 1 near ℓ/h = 2.45, (ℓ/h)² = 6. Below, a V-cycle costs more than the Jacobi
// iterations it saves; above, Jacobi-CG's iterations grow with ℓ/h and multigrid's do not.
double helmholtz_multigrid_above() { return 6.0; }

bool helmholtz_uses_multigrid(HelmholtzSolver solver, double length, double edge) {
  if (solver != HelmholtzSolver::Auto) return solver == HelmholtzSolver::Multigrid;
  return edge > 0 && (length / edge) * (length / edge) > helmholtz_multigrid_above();
}

HelmholtzFilter::HelmholtzFilter(const TetMesh& mesh, const std::vector<int>& design, const VecXd& volume,
                                 const FilterParams& params, const Progress& progress, const std::vector<char>& held)
    : length_(helmholtz_length(params.radius, params.like_gaussian)),
      threads_(thread_count(params.threads)),
      progress_(progress) {
  if (!(params.radius > 0) || !std::isfinite(params.radius))
    throw Error(ErrorCode::InvalidParameter, "the Helmholtz filter needs a positive, finite radius (mm)");
  volume_.resize(static_cast<long>(design.size()));
  for (size_t i = 0; i < design.size(); ++i) volume_[static_cast<long>(i)] = volume[design[i]];
  assemble(mesh, design);
  pad_weight_ = params.pad_weight;
  if (params.pad_free_faces) pad_free_faces(mesh, design, held, params.pad_weight);
  mean_edge_ = mean_edge_length(mesh, design);
  if (helmholtz_uses_multigrid(params.helmholtz_solver, length_, mean_edge_)) set_up_multigrid();
}

void HelmholtzFilter::set_up_multigrid() {
  // one row per node, and the constant as the one mode the Laplacian leaves unstrained
  std::vector<int> node_ptr(A_.rows + 1);
  for (int i = 0; i <= A_.rows; ++i) node_ptr[i] = i;
  fem::AmgParams p;
  p.threads = threads_;
  amg_ = std::make_unique<fem::SmoothedAggregationAmg>();
  amg_->setup(A_, node_ptr, std::vector<double>(A_.rows, 1.0), p);
}

void HelmholtzFilter::assemble(const TetMesh& mesh, const std::vector<int>& design) {
  // the design elements' nodes, numbered in the order of the mesh's nodes
  std::vector<int> local(static_cast<size_t>(mesh.V.rows()), -1);
  for (int t : design)
    for (int a = 0; a < 4; ++a) local[mesh.T(t, a)] = 0;
  int n = 0;
  for (int& l : local)
    if (l == 0) l = n++;
  element_nodes_.resize(4 * design.size());
  for (size_t i = 0; i < design.size(); ++i)
    for (int a = 0; a < 4; ++a) element_nodes_[4 * i + a] = local[mesh.T(design[i], a)];
  // the pattern: every (row, col) pair of an element, sorted once
  std::vector<std::uint64_t> keys;
  keys.reserve(16 * design.size());
  for (size_t i = 0; i < design.size(); ++i)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        keys.push_back(static_cast<std::uint64_t>(element_nodes_[4 * i + a]) * n + element_nodes_[4 * i + b]);
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
  A_ = fem::CsrMatrix();
  A_.rows = A_.cols = n;
  A_.ptr.assign(n + 1, 0);
  A_.col.resize(keys.size());
  for (size_t k = 0; k < keys.size(); ++k) {
    ++A_.ptr[keys[k] / n + 1];
    A_.col[k] = static_cast<int>(keys[k] % n);
  }
  for (int r = 0; r < n; ++r) A_.ptr[r + 1] += A_.ptr[r];
  keys = {};
  A_.val.assign(A_.col.size(), 0.0);
  for (size_t i = 0; i < design.size(); ++i) {
    Eigen::Matrix<double, 4, 3> p;
    for (int a = 0; a < 4; ++a) p.row(a) = mesh.V.row(mesh.T(design[i], a));
    const Eigen::Matrix4d Ae = helmholtz_element_matrix(p, length_);
    for (int a = 0; a < 4; ++a) {
      const int row = element_nodes_[4 * i + a];
      const int* begin = A_.col.data() + A_.ptr[row];
      const int* end = A_.col.data() + A_.ptr[row + 1];
      for (int b = 0; b < 4; ++b)
        A_.val[std::lower_bound(begin, end, element_nodes_[4 * i + b]) - A_.col.data()] += Ae(a, b);
    }
  }
  inverse_diagonal_.resize(n);
  for (int r = 0; r < n; ++r)
    for (int k = A_.ptr[r]; k < A_.ptr[r + 1]; ++k)
      if (A_.col[k] == r) inverse_diagonal_[r] = 1.0 / A_.val[k];
}

void HelmholtzFilter::pad_free_faces(const TetMesh& mesh, const std::vector<int>& design,
                                     const std::vector<char>& held, double weight) {
  // the design nodes' local numbers (assemble's: the mesh's order) and the faces of non-design tets
  std::vector<int> local(static_cast<size_t>(mesh.V.rows()), -1);
  std::vector<char> is_design(static_cast<size_t>(mesh.T.rows()), 0);
  for (size_t i = 0; i < design.size(); ++i) {
    is_design[design[i]] = 1;
    for (int a = 0; a < 4; ++a) local[mesh.T(design[i], a)] = element_nodes_[4 * i + a];
  }
  std::unordered_set<FaceKey, FaceKeyHash> fixed;
  for (long t = 0; t < mesh.T.rows(); ++t)
    if (!is_design[t])
      for (int a = 0; a < 4; ++a)
        fixed.insert(face_key(mesh.T(t, (a + 1) % 4), mesh.T(t, (a + 2) % 4), mesh.T(t, (a + 3) % 4)));
  // κ ℓ ∫_Γ ρ̃ v on each free face: its triangle's mass matrix area/12 (1 + δ_ab), times κ ℓ
  const MatX3i faces = boundary_triangles(mesh.T);
  for (long f = 0; f < faces.rows(); ++f) {
    const int n[3] = {faces(f, 0), faces(f, 1), faces(f, 2)};
    if (fixed.count(face_key(n[0], n[1], n[2])) || local[n[0]] < 0 || local[n[1]] < 0 || local[n[2]] < 0) continue;
    if (!held.empty() && held[n[0]] && held[n[1]] && held[n[2]]) continue;
    const double area = 0.5 * (mesh.V.row(n[1]) - mesh.V.row(n[0])).cross(mesh.V.row(n[2]) - mesh.V.row(n[0])).norm();
    for (int a = 0; a < 3; ++a) {
      const int row = local[n[a]];
      const int* begin = A_.col.data() + A_.ptr[row];
      const int* end = A_.col.data() + A_.ptr[row + 1];
      for (int b = 0; b < 3; ++b)
        A_.val[std::lower_bound(begin, end, local[n[b]]) - A_.col.data()] += weight * length_ * area / 12.0 * (a == b ? 2 : 1);
    }
    ++padded_faces_;
  }
  for (int r = 0; r < A_.rows; ++r)
    for (int k = A_.ptr[r]; k < A_.ptr[r + 1]; ++k)
      if (A_.col[k] == r) inverse_diagonal_[r] = 1.0 / A_.val[k];
}

VecXd HelmholtzFilter::nodal_load(const VecXd& per_element) const {
  VecXd b = VecXd::Zero(A_.rows);
  for (long i = 0; i < per_element.size(); ++i)
    for (int a = 0; a < 4; ++a) b[element_nodes_[4 * i + a]] += 0.25 * per_element[i];
  return b;
}

VecXd HelmholtzFilter::element_mean(const VecXd& nodal) const {
  VecXd e(volume_.size());
  for (long i = 0; i < e.size(); ++i)
    e[i] = 0.25 * (nodal[element_nodes_[4 * i]] + nodal[element_nodes_[4 * i + 1]] + nodal[element_nodes_[4 * i + 2]] +
                   nodal[element_nodes_[4 * i + 3]]);
  return e;
}

VecXd HelmholtzFilter::solve(const VecXd& b, VecXd& warm) const {
  if (warm.size() != b.size()) warm = VecXd::Zero(b.size());
  if (!b.allFinite())  // not the mesh's fault: say so rather than blame degenerate tets below
    throw Error(ErrorCode::Internal,
                "the Helmholtz density filter was given a field that is not finite (an internal fault of the "
                "optimiser, not of the part or the mesh; please report it with the job)");
  fem::PcgParams pcg;
  pcg.tolerance = 1e-12;  // near round-off: the gradients (Fᵀ) must match the filter (F) closely
  pcg.max_iterations = 2000;
  const fem::CsrOperator op(A_, threads_);
  const fem::PcgResult r = amg_ ? fem::pcg(op, *amg_, b, warm, pcg, progress_)
                                : fem::pcg(op, JacobiPreconditioner(inverse_diagonal_), b, warm, pcg, progress_);
  last_iterations_ = r.iterations;
  if (!r.converged) {
    std::ostringstream s;
    s << "the Helmholtz density filter did not converge in " << r.iterations << " iterations (relative residual "
      << r.relative_residual << "): the mesh holds degenerate design tets; use \"filter\": \"gaussian\"";
    throw Error(ErrorCode::Internal, s.str());
  }
  return warm;
}

VecXd HelmholtzFilter::apply(const VecXd& x) const {
  return element_mean(solve(nodal_load(x.cwiseProduct(volume_)), forward_));
}

VecXd HelmholtzFilter::apply_transpose(const VecXd& g) const {
  // (R A⁻¹ T)ᵀ = Tᵀ A⁻¹ Rᵀ: Rᵀ g spreads g/4 to the nodes, Tᵀ takes V_e/4 of each node's value
  return element_mean(solve(nodal_load(g), backward_)).cwiseProduct(volume_);
}

VecXd HelmholtzFilter::filter_sensitivity(const VecXd& x, const VecXd& g) const {
  return apply(x.cwiseProduct(g)).cwiseQuotient(x.cwiseMax(1e-3));
}

std::string HelmholtzFilter::describe() const {
  std::ostringstream s;
  s << "Helmholtz (PDE) filter, length " << length_ << " mm (" << length_ / std::max(mean_edge_, 1e-300)
    << " mean edges), " << A_.rows << " nodes, " << static_cast<double>(A_.nonzeros()) / std::max(1, A_.rows)
    << " entries per row, CG preconditioned by "
    << (amg_ ? "multigrid (" + std::to_string(amg_->levels()) + " levels)" : std::string("Jacobi"));
  if (padded_faces_ > 0)
    s << ", the part's free faces padded (" << padded_faces_ << " triangles, weight " << pad_weight_ << ")";
  return s.str();
}

}  // namespace topopt::simp
