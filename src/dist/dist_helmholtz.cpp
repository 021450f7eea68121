// The distributed Helmholtz filter (see dist_helmholtz.h).
#include "dist/dist_helmholtz.h"

#include <petscksp.h>

#include <cmath>
#include <sstream>

#include "common/error.h"
#include "simp/helmholtz_filter.h"

namespace topopt::dist {

struct DistHelmholtz::Impl {
  const MpiSession& session;
  const DistMesh& mesh;
  std::vector<int> design;
  double length;
  VecXd volume;  // #D local
  Mat A = nullptr;
  KSP ksp = nullptr;
  Vec b = nullptr;
  mutable Vec forward = nullptr, backward = nullptr;  // ghosted; warm starts as in the serial filter
  mutable int iterations = 0;

  Impl(const MpiSession& s, const DistMesh& m, const std::vector<int>& d, double l)
      : session(s), mesh(m), design(d), length(l) {}
  ~Impl() {
    VecDestroy(&forward);
    VecDestroy(&backward);
    VecDestroy(&b);
    KSPDestroy(&ksp);
    MatDestroy(&A);
  }
  PetscInt global(int local_node) const { return static_cast<PetscInt>(mesh.node_global[local_node]); }
  void insert(Mat M, bool values);
  void assemble();
  Vec ghosted() const;
  VecXd solve_mean(const VecXd& per_element, Vec warm) const;
};

void DistHelmholtz::Impl::insert(Mat M, bool values) {
  volume.resize(static_cast<long>(design.size()));
  for (size_t i = 0; i < design.size(); ++i) {
    Eigen::Matrix<double, 4, 3> p;
    PetscInt idx[4];
    for (int a = 0; a < 4; ++a) {
      p.row(a) = mesh.local.V.row(mesh.local.T(design[i], a));
      idx[a] = global(mesh.local.T(design[i], a));
    }
    Eigen::Matrix<double, 4, 4, Eigen::RowMajor> Ae = simp::helmholtz_element_matrix(p, length);
    if (!values) Ae.setZero();
    check_petsc(MatSetValues(M, 4, idx, 4, idx, Ae.data(), ADD_VALUES), "MatSetValues");
    Eigen::Matrix3d J;
    for (int k = 0; k < 3; ++k) J.row(k) = p.row(k + 1) - p.row(0);
    volume[static_cast<long>(i)] = std::abs(J.determinant()) / 6.0;
  }
  for (int i = 0; i < mesh.owned_nodes; ++i)
    check_petsc(MatSetValue(M, global(i), global(i), 0.0, ADD_VALUES), "MatSetValue");
  check_petsc(MatAssemblyBegin(M, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(M, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
}

void DistHelmholtz::Impl::assemble() {
  const PetscInt n = mesh.owned_nodes, N = static_cast<PetscInt>(mesh.total_nodes);
  Mat pre;
  check_petsc(MatCreate(session.comm(), &pre), "MatCreate");
  check_petsc(MatSetType(pre, MATPREALLOCATOR), "MatSetType");
  check_petsc(MatSetSizes(pre, n, n, N, N), "MatSetSizes");
  check_petsc(MatSetUp(pre), "MatSetUp");
  insert(pre, false);
  check_petsc(MatCreate(session.comm(), &A), "MatCreate");
  check_petsc(MatSetType(A, MATAIJ), "MatSetType");
  check_petsc(MatSetSizes(A, n, n, N, N), "MatSetSizes");
  check_petsc(MatPreallocatorPreallocate(pre, PETSC_TRUE, A), "MatPreallocatorPreallocate");
  MatDestroy(&pre);
  insert(A, true);
  // nodes of no design tet: a diagonal alone (their value stays 0)
  check_petsc(MatCreateVecs(A, nullptr, &b), "MatCreateVecs");
  check_petsc(MatGetDiagonal(A, b), "MatGetDiagonal");
  const PetscScalar* d = nullptr;
  VecGetArrayRead(b, &d);
  for (int i = 0; i < n; ++i)
    if (d[i] == 0) check_petsc(MatSetValue(A, global(i), global(i), 1.0, INSERT_VALUES), "MatSetValue");
  VecRestoreArrayRead(b, &d);
  check_petsc(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  check_petsc(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  check_petsc(KSPCreate(session.comm(), &ksp), "KSPCreate");
  check_petsc(KSPSetOptionsPrefix(ksp, "filter_"), "KSPSetOptionsPrefix");
  check_petsc(KSPSetOperators(ksp, A, A), "KSPSetOperators");
  check_petsc(KSPSetType(ksp, KSPCG), "KSPSetType");
  PC pc;
  KSPGetPC(ksp, &pc);
  check_petsc(PCSetType(pc, PCJACOBI), "PCSetType");
  // near round-off, as the serial filter: the gradients (Fᵀ) must match the filter (F) closely.
  // No divergence test: a warm start from a field of another scale (Fᵀ of the volume after Fᵀ
  // of the compliance) starts with a residual far above ‖b‖, which PETSc's default calls divergence.
  check_petsc(KSPSetTolerances(ksp, 1e-12, 1e-300, 1e300, 2000), "KSPSetTolerances");
  check_petsc(KSPSetNormType(ksp, KSP_NORM_UNPRECONDITIONED), "KSPSetNormType");
  check_petsc(KSPSetInitialGuessNonzero(ksp, PETSC_TRUE), "KSPSetInitialGuessNonzero");
  check_petsc(KSPSetFromOptions(ksp), "KSPSetFromOptions");
  forward = ghosted();
  backward = ghosted();
}

Vec DistHelmholtz::Impl::ghosted() const {
  std::vector<PetscInt> ghosts(mesh.node_global.begin() + mesh.owned_nodes, mesh.node_global.end());
  Vec v;
  check_petsc(VecCreateGhost(session.comm(), mesh.owned_nodes, static_cast<PetscInt>(mesh.total_nodes),
                             static_cast<PetscInt>(ghosts.size()), ghosts.data(), &v),
              "VecCreateGhost");
  VecSet(v, 0.0);
  return v;
}

/// Spreads a quarter of each element's value to its nodes, solves into `warm` (the previous
/// solution on entry) and returns each element's mean of its four nodes.
VecXd DistHelmholtz::Impl::solve_mean(const VecXd& per_element, Vec warm) const {
  VecSet(b, 0.0);
  for (size_t i = 0; i < design.size(); ++i) {
    PetscInt idx[4];
    PetscScalar v[4];
    for (int a = 0; a < 4; ++a) idx[a] = global(mesh.local.T(design[i], a)), v[a] = 0.25 * per_element[i];
    check_petsc(VecSetValues(b, 4, idx, v, ADD_VALUES), "VecSetValues");
  }
  VecAssemblyBegin(b);
  VecAssemblyEnd(b);
  check_petsc(KSPSolve(ksp, b, warm), "KSPSolve");
  KSPConvergedReason reason;
  KSPGetConvergedReason(ksp, &reason);
  PetscInt its = 0;
  KSPGetIterationNumber(ksp, &its);
  iterations = static_cast<int>(its);
  if (reason < 0) {
    std::ostringstream s;
    s << "the Helmholtz density filter did not converge in " << its
      << " iterations: the mesh holds degenerate design tets; run without mpirun with \"filter\": \"gaussian\"";
    throw Error(ErrorCode::Internal, s.str());
  }
  VecGhostUpdateBegin(warm, INSERT_VALUES, SCATTER_FORWARD);
  VecGhostUpdateEnd(warm, INSERT_VALUES, SCATTER_FORWARD);
  Vec local;
  VecGhostGetLocalForm(warm, &local);
  const PetscScalar* u = nullptr;
  VecGetArrayRead(local, &u);
  VecXd mean(static_cast<long>(design.size()));
  for (size_t i = 0; i < design.size(); ++i) {
    double s = 0;
    for (int a = 0; a < 4; ++a) s += u[mesh.local.T(design[i], a)];
    mean[static_cast<long>(i)] = 0.25 * s;
  }
  VecRestoreArrayRead(local, &u);
  VecGhostRestoreLocalForm(warm, &local);
  return mean;
}

DistHelmholtz::DistHelmholtz(const MpiSession& session, const DistMesh& mesh, const std::vector<int>& design,
                             double length)
    : impl_(std::make_unique<Impl>(session, mesh, design, length)) {
  impl_->assemble();
}

DistHelmholtz::~DistHelmholtz() = default;

VecXd DistHelmholtz::apply(const VecXd& x) const {
  return impl_->solve_mean(x.cwiseProduct(impl_->volume), impl_->forward);
}

VecXd DistHelmholtz::apply_transpose(const VecXd& g) const {
  // (R A⁻¹ T)ᵀ = Tᵀ A⁻¹ Rᵀ, as in the serial filter
  return impl_->solve_mean(g, impl_->backward).cwiseProduct(impl_->volume);
}

int DistHelmholtz::last_iterations() const { return impl_->iterations; }

}  // namespace topopt::dist
