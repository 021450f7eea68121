// Distributed elasticity on PETSc (see dist_elasticity.h).
#include "dist/dist_elasticity.h"

#include <petscksp.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <vector>

#include "common/error.h"
#include "fem/solver_policy.h"
#include "fem/tet_element.h"

namespace topopt::dist {
namespace {

/// Puts `name value` in PETSc's options database unless PETSC_OPTIONS already gave `name`.
void option_unless_given(const char* name, const char* value) {
  PetscBool given = PETSC_FALSE;
  check_petsc(PetscOptionsHasName(nullptr, nullptr, name, &given), "PetscOptionsHasName");
  if (!given) check_petsc(PetscOptionsSetValue(nullptr, name, value), "PetscOptionsSetValue");
}

}  // namespace

Amg amg_named(const std::string& name) {
  if (name == "gamg") return Amg::GAMG;
  if (name == "boomeramg") return Amg::BoomerAMG;
  throw Error(ErrorCode::InvalidParameter,
              "--amg takes gamg (PETSc's smoothed aggregation) or boomeramg (hypre's), not '" + name + "'");
}

struct DistElasticity::Impl {
  const MpiSession& session;
  const DistMesh& mesh;
  DistSolverParams params;
  double lambda = 0, mu = 0, hold = 1;  // hold: the diagonal of a held dof, about K's own
  std::vector<double> grad, vol;        // per local tet: 12 gradients, volume
  VecXd scale;
  std::vector<PetscInt> dof;  // 3 × #local nodes: global dof, or -1 where held
  Mat K = nullptr;
  KSP ksp = nullptr;
  Vec b = nullptr;
  std::vector<Vec> x;  // one ghosted solution per load case (warm starts)
  bool dirty = true;
  bool safe_smoother = false;  // after a failed solve: the multigrid smooths with SOR (no eigenvalue estimate)
  int iterations = 0;
  fem::HierarchyReuse reuse;  // the serial multigrid's rule for keeping a preconditioner
  bool built = false;         // a preconditioner is set up (perhaps for an earlier matrix)
  bool kept = false;          // the preconditioner in use was set up for an earlier matrix
  int setups = 0;

  Impl(const MpiSession& s, const DistMesh& m, const DistSolverParams& p)
      : session(s), mesh(m), params(p), reuse(p.reuse) {}
  ~Impl() {
    for (Vec& v : x) VecDestroy(&v);
    VecDestroy(&b);
    KSPDestroy(&ksp);
    MatDestroy(&K);
  }
  void geometry(const fem::Material& material);
  void insert(Mat A, bool values) const;
  void create_matrix();
  void create_solver();
  void use_safe_smoother();
  void set_operators(bool keep);
  void refresh_finest_smoother();
  KSPConvergedReason run_solver(long k, PetscInt& its);
  KSPConvergedReason run_kept_solver(long k, PetscInt& its, bool& rebuilt);
  Vec ghosted_vector() const;
  bool solve_case(const Eigen::MatrixXd& loads, long k, Eigen::MatrixXd& U);
  template <class F>
  VecXd per_element(const VecXd& u, const F& f) const;
};

void DistElasticity::Impl::geometry(const fem::Material& material) {
  fem::lame(material, lambda, mu);
  const long nt = mesh.local.T.rows();
  grad.assign(12 * nt, 0.0);
  vol.assign(nt, 0.0);
  double sum = 0;
  long bad = -1;  // the serial number of a tet without positive volume
  for (long t = 0; t < nt; ++t) {
    const double det = fem::tet_gradients(mesh.local, t, &grad[12 * t]);
    if (!(det > 0)) bad = std::max(bad, mesh.tet_serial[t]);
    vol[t] = det / 6.0;
    sum += vol[t];
  }
  // every rank learns of a bad tet, so that all of them throw together
  MPI_Allreduce(MPI_IN_PLACE, &bad, 1, MPI_LONG, MPI_MAX, session.comm());
  if (bad >= 0)
    throw Error(ErrorCode::InvalidParameter,
                "tet " + std::to_string(bad) + " has no positive volume; the mesh must have positively oriented tets");
  double total[2] = {sum, static_cast<double>(nt)};
  MPI_Allreduce(MPI_IN_PLACE, total, 2, MPI_DOUBLE, MPI_SUM, session.comm());
  hold = material.young * std::cbrt(total[0] / std::max(1.0, total[1]));
  scale = VecXd::Ones(nt);
  const long nl = mesh.local.V.rows();
  dof.assign(3 * nl, -1);
  for (long i = 0; i < nl; ++i)
    for (int c = 0; c < 3; ++c)
      if (!mesh.fixed[3 * i + c]) dof[3 * i + c] = static_cast<PetscInt>(3 * mesh.node_global[i] + c);
}

void DistElasticity::Impl::insert(Mat A, bool values) const {
  double Ke[144] = {0};
  PetscInt idx[12];
  for (long t = 0; t < mesh.local.T.rows(); ++t) {
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) idx[3 * a + c] = dof[3 * mesh.local.T(t, a) + c];
    if (values) fem::element_stiffness(&grad[12 * t], vol[t] * scale[t], lambda, mu, Ke);
    check_petsc(MatSetValues(A, 12, idx, 12, idx, Ke, ADD_VALUES), "MatSetValues");
  }
  for (long i = 0; i < 3L * mesh.owned_nodes; ++i)
    if (dof[i] < 0) {
      const PetscInt g = static_cast<PetscInt>(3 * mesh.node_global[i / 3] + i % 3);
      check_petsc(MatSetValue(A, g, g, values ? hold : 0.0, ADD_VALUES), "MatSetValue");
    }
  check_petsc(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
}

void DistElasticity::Impl::create_matrix() {
  const PetscInt n = 3 * mesh.owned_nodes, N = static_cast<PetscInt>(3 * mesh.total_nodes);
  Mat pre;
  check_petsc(MatCreate(session.comm(), &pre), "MatCreate");
  check_petsc(MatSetType(pre, MATPREALLOCATOR), "MatSetType");
  check_petsc(MatSetSizes(pre, n, n, N, N), "MatSetSizes");
  check_petsc(MatSetBlockSize(pre, 3), "MatSetBlockSize");
  check_petsc(MatSetUp(pre), "MatSetUp");
  insert(pre, false);
  check_petsc(MatCreate(session.comm(), &K), "MatCreate");
  check_petsc(MatSetType(K, MATAIJ), "MatSetType");
  check_petsc(MatSetSizes(K, n, n, N, N), "MatSetSizes");
  check_petsc(MatSetBlockSize(K, 3), "MatSetBlockSize");
  check_petsc(MatPreallocatorPreallocate(pre, PETSC_TRUE, K), "MatPreallocatorPreallocate");
  MatDestroy(&pre);
  check_petsc(MatSetOption(K, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_TRUE), "MatSetOption");
  // the near-null space: the six rigid-body modes at the owned nodes
  Vec coords;
  check_petsc(VecCreateMPI(session.comm(), n, N, &coords), "VecCreateMPI");
  check_petsc(VecSetBlockSize(coords, 3), "VecSetBlockSize");
  PetscScalar* c = nullptr;
  VecGetArray(coords, &c);
  for (long i = 0; i < mesh.owned_nodes; ++i)
    for (int k = 0; k < 3; ++k) c[3 * i + k] = mesh.local.V(i, k);
  VecRestoreArray(coords, &c);
  MatNullSpace modes;
  check_petsc(MatNullSpaceCreateRigidBody(coords, &modes), "MatNullSpaceCreateRigidBody");
  check_petsc(MatSetNearNullSpace(K, modes), "MatSetNearNullSpace");
  MatNullSpaceDestroy(&modes);
  VecDestroy(&coords);
  check_petsc(MatCreateVecs(K, nullptr, &b), "MatCreateVecs");
}

void DistElasticity::Impl::create_solver() {
  check_petsc(KSPCreate(session.comm(), &ksp), "KSPCreate");
  check_petsc(KSPSetType(ksp, KSPCG), "KSPSetType");
  PC pc;
  KSPGetPC(ksp, &pc);
  if (params.amg == Amg::BoomerAMG) {
    // nodal coarsening (the block of a node's 3 dofs, by the Frobenius norm) and interpolation
    // that keeps the nodes' dofs together: hypre's settings for elasticity systems
    check_petsc(PCSetType(pc, PCHYPRE), "PCSetType");
    check_petsc(PCHYPRESetType(pc, "boomeramg"), "PCHYPRESetType");
    option_unless_given("-pc_hypre_boomeramg_nodal_coarsen", "6");
    option_unless_given("-pc_hypre_boomeramg_vec_interp_variant", "3");
  } else {
    check_petsc(PCSetType(pc, PCGAMG), "PCSetType");
    // Chebyshev smoothing aims at 1.3 × the estimated largest eigenvalue, not PETSc's 1.1: under
    // SIMP's stiffness contrast the estimate falls short often enough that the V-cycle stopped
    // being positive definite (CG: "indefinite preconditioner") by SIMP iteration 5 on a 100 k-tet
    // cantilever with 3 of 6 option sets tried (a looser filter tolerance, a GAMG threshold, more
    // smoothing steps); at 1.3 those 3 and the defaults ran, the defaults with 8 % more CG iterations
    // (BENCHMARKS.md, "The distributed solve's smoother").
    option_unless_given("-mg_levels_ksp_chebyshev_esteig", "0,0.1,0,1.3");
    // ... and at 1.3 × an estimate of its own level operator (a few CG steps, which approach the
    // largest eigenvalue from below quickly), not GAMG's from its prolongator smoothing: with
    // GAMG's, the whole cantilever study (98 k tets, default job) still broke down at SIMP
    // iteration 8 (CG "indefinite preconditioner", and the SOR retry failed too); with its own it
    // ran on (BENCHMARKS.md, "The distributed path's cost per tet"). A kept hierarchy's finest
    // smoother re-estimates for the new matrix.
    option_unless_given("-pc_gamg_use_sa_esteig", "false");
    option_unless_given("-mg_levels_esteig_ksp_type", "cg");
  }
  check_petsc(KSPSetTolerances(ksp, params.tolerance, 1e-300, 1e300, params.max_iterations), "KSPSetTolerances");
  check_petsc(KSPSetNormType(ksp, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
  check_petsc(KSPSetInitialGuessNonzero(ksp, PETSC_TRUE), "KSPSetInitialGuessNonzero");
  check_petsc(KSPSetFromOptions(ksp), "KSPSetFromOptions");
}

Vec DistElasticity::Impl::ghosted_vector() const {
  std::vector<PetscInt> ghosts(mesh.node_global.begin() + mesh.owned_nodes, mesh.node_global.end());
  Vec v;
  check_petsc(VecCreateGhostBlock(session.comm(), 3, 3 * mesh.owned_nodes, static_cast<PetscInt>(3 * mesh.total_nodes),
                                  static_cast<PetscInt>(ghosts.size()), ghosts.data(), &v),
              "VecCreateGhostBlock");
  VecSet(v, 0.0);
  return v;
}

/// Switches the multigrid to smoothing by symmetric SOR sweeps, which need no eigenvalue
/// estimate and keep the V-cycle positive definite for any SPD matrix (slower than Chebyshev).
void DistElasticity::Impl::use_safe_smoother() {
  KSPDestroy(&ksp);
  params.amg = Amg::GAMG;
  check_petsc(PetscOptionsSetValue(nullptr, "-mg_levels_ksp_type", "richardson"), "PetscOptionsSetValue");
  check_petsc(PetscOptionsSetValue(nullptr, "-mg_levels_pc_type", "sor"), "PetscOptionsSetValue");
  create_solver();
  safe_smoother = true;
  set_operators(false);
}

/// Hands K's current values to the solver: on the preconditioner set up for an earlier matrix
/// (keep: CG runs on the new K, the multigrid stays the old one's but for the finest smoother)
/// or on a new set-up at the next solve. Counts the set-ups; the reuse rule's bookkeeping is the
/// caller's.
void DistElasticity::Impl::set_operators(bool keep) {
  check_petsc(KSPSetReusePreconditioner(ksp, keep ? PETSC_TRUE : PETSC_FALSE), "KSPSetReusePreconditioner");
  check_petsc(KSPSetOperators(ksp, K, K), "KSPSetOperators");
  if (keep) {
    refresh_finest_smoother();
  } else {
    ++setups;
    built = true;
  }
  kept = keep;
}

/// A kept GAMG hierarchy for a new K: the finest level's smoother is given K anew, so that its
/// Jacobi diagonal and Chebyshev's eigenvalue estimate follow the new values (the coarse levels
/// stay the old matrix's Galerkin products), as the serial multigrid refreshes its finest level.
void DistElasticity::Impl::refresh_finest_smoother() {
  PC pc;
  KSPGetPC(ksp, &pc);
  PetscBool mg = PETSC_FALSE;
  check_petsc(PetscObjectTypeCompare(reinterpret_cast<PetscObject>(pc), PCGAMG, &mg), "PetscObjectTypeCompare");
  if (!mg) return;
  PetscInt levels = 0;
  check_petsc(PCMGGetLevels(pc, &levels), "PCMGGetLevels");
  if (levels < 1) return;
  KSP smoother;
  check_petsc(PCMGGetSmoother(pc, levels - 1, &smoother), "PCMGGetSmoother");
  check_petsc(KSPSetOperators(smoother, K, K), "KSPSetOperators");
}

KSPConvergedReason DistElasticity::Impl::run_solver(long k, PetscInt& its) {
  check_petsc(KSPSolve(ksp, b, x[k]), "KSPSolve");
  KSPConvergedReason reason;
  KSPGetConvergedReason(ksp, &reason);
  KSPGetIterationNumber(ksp, &its);
  return reason;
}

/// Solves load case k; on a kept preconditioner CG may take the reuse rule's patience only: a
/// solve that reaches it (the old hierarchy no longer fits) is finished from where it stopped on
/// a new set-up, and one that fails on it (a stale smoother can make the V-cycle indefinite) is
/// run again from zero on a new set-up. `rebuilt` is set when either happened; its counts
/// include the iterations on the kept preconditioner.
KSPConvergedReason DistElasticity::Impl::run_kept_solver(long k, PetscInt& its, bool& rebuilt) {
  if (!kept) return run_solver(k, its);
  const PetscInt patience = reuse.patience(params.max_iterations);
  check_petsc(KSPSetTolerances(ksp, params.tolerance, 1e-300, 1e300, patience), "KSPSetTolerances");
  KSPConvergedReason reason = run_solver(k, its);
  check_petsc(KSPSetTolerances(ksp, params.tolerance, 1e-300, 1e300, params.max_iterations), "KSPSetTolerances");
  if (reason >= 0) return reason;
  const PetscInt on_kept = its;
  reuse.cut();
  if (reason != KSP_DIVERGED_ITS) VecSet(x[k], 0.0);  // from where CG stopped, unless it broke down
  set_operators(false);
  rebuilt = true;
  reason = run_solver(k, its);
  its += on_kept;
  return reason;
}

/// Solves load case k; a solve that fails is run once more from zero with the safe smoother
/// before the failure is the user's (then most likely a part the supports do not hold).
/// Returns true when the preconditioner was set up anew during the solve.
bool DistElasticity::Impl::solve_case(const Eigen::MatrixXd& loads, long k, Eigen::MatrixXd& U) {
  PetscScalar* f = nullptr;
  VecGetArray(b, &f);
  for (long i = 0; i < 3L * mesh.owned_nodes; ++i) f[i] = dof[i] >= 0 ? loads(i, k) : 0.0;
  VecRestoreArray(b, &f);
  while (static_cast<long>(x.size()) <= k) x.push_back(ghosted_vector());
  PetscInt its = 0;
  bool rebuilt = false;
  KSPConvergedReason reason = run_kept_solver(k, its, rebuilt);
  if (reason < 0 && !safe_smoother) {
    if (session.rank() == 0)
      std::cerr << "[dist] the multigrid solve failed (PETSc reason " << static_cast<int>(reason) << " after " << its
                << " iterations); solving again with SOR smoothing" << std::endl;
    reuse.set_up();
    use_safe_smoother();
    rebuilt = true;
    VecSet(x[k], 0.0);
    reason = run_solver(k, its);
  }
  iterations = std::max(iterations, static_cast<int>(its));
  if (reason < 0)
    throw Error(ErrorCode::NoSupport,
                "the distributed solver (CG with algebraic multigrid) did not converge (PETSc reason " +
                    std::to_string(static_cast<int>(reason)) + ", " + std::to_string(its) +
                    " iterations, also with SOR smoothing): check that the supports hold every piece of the part");
  VecGhostUpdateBegin(x[k], INSERT_VALUES, SCATTER_FORWARD);
  VecGhostUpdateEnd(x[k], INSERT_VALUES, SCATTER_FORWARD);
  Vec local;
  VecGhostGetLocalForm(x[k], &local);
  const PetscScalar* u = nullptr;
  VecGetArrayRead(local, &u);
  for (long i = 0; i < U.rows(); ++i) U(i, k) = dof[i] >= 0 ? u[i] : 0.0;
  VecRestoreArrayRead(local, &u);
  VecGhostRestoreLocalForm(x[k], &local);
  return rebuilt;
}

DistElasticity::DistElasticity(const MpiSession& session, const DistMesh& mesh, const fem::Material& material,
                               const DistSolverParams& params)
    : impl_(std::make_unique<Impl>(session, mesh, params)) {
  impl_->geometry(material);
  impl_->create_matrix();
  impl_->create_solver();
}

DistElasticity::~DistElasticity() = default;

void DistElasticity::set_scale(const VecXd& scale) {
  if (scale.size() != impl_->mesh.local.T.rows())
    throw Error(ErrorCode::Internal, "DistElasticity::set_scale: one factor per local tet expected");
  impl_->scale = scale;
  impl_->dirty = true;
}

Eigen::MatrixXd DistElasticity::solve(const Eigen::MatrixXd& loads) {
  Impl& m = *impl_;
  if (m.dirty) {
    check_petsc(MatZeroEntries(m.K), "MatZeroEntries");
    m.insert(m.K, true);
    // the serial multigrid's rule (fem::HierarchyReuse): keep the preconditioner while the
    // iterations its staleness costs stay below a refresh's; a refresh of the coarse matrices
    // is, on PETSc, a new set-up (the Galerkin products are most of GAMG's set-up)
    bool keep = m.reuse.keep(m.built);
    if (keep && m.reuse.refresh_coarse_on_update()) {
      keep = false;
    } else if (!keep) {
      m.reuse.set_up();
    }
    m.set_operators(keep);
    m.dirty = false;
  }
  m.iterations = 0;
  bool rebuilt = false;
  Eigen::MatrixXd U(3 * m.mesh.local.V.rows(), loads.cols());
  for (long k = 0; k < loads.cols(); ++k) rebuilt = m.solve_case(loads, k, U) || rebuilt;
  if (!rebuilt) m.reuse.record(m.iterations);
  return U;
}

void DistElasticity::set_tolerance(double tolerance) {
  Impl& m = *impl_;
  if (tolerance == m.params.tolerance) return;
  m.reuse.rebaseline(m.params.tolerance, tolerance);
  m.params.tolerance = tolerance;  // iteration counts at another tolerance say nothing of a stale preconditioner
  check_petsc(KSPSetTolerances(m.ksp, tolerance, 1e-300, 1e300, m.params.max_iterations), "KSPSetTolerances");
}

int DistElasticity::setups() const { return impl_->setups; }

/// f(t, ε_t) for each local tet t, ε_t its strain under the local displacements u.
template <class F>
VecXd DistElasticity::Impl::per_element(const VecXd& u, const F& f) const {
  const long nt = mesh.local.T.rows();
  VecXd out(nt);
  double ue[12];
  for (long t = 0; t < nt; ++t) {
    for (int a = 0; a < 4; ++a)
      for (int c = 0; c < 3; ++c) ue[3 * a + c] = u[3 * mesh.local.T(t, a) + c];
    out[t] = f(t, fem::element_strain(&grad[12 * t], ue));
  }
  return out;
}

VecXd DistElasticity::element_energy(const VecXd& u) const {
  const Impl& m = *impl_;
  return m.per_element(u, [&m](long t, const Eigen::Matrix3d& eps) {
    return fem::element_energy_of_strain(eps, m.vol[t], m.lambda, m.mu);
  });
}

VecXd DistElasticity::von_mises(const VecXd& u) const {
  const Impl& m = *impl_;
  return m.per_element(u, [&m](long t, const Eigen::Matrix3d& eps) {
    return fem::von_mises_of_strain(eps, m.lambda, m.mu, m.scale[t]);
  });
}

int DistElasticity::last_iterations() const { return impl_->iterations; }

}  // namespace topopt::dist
