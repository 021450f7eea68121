// The linear-tet elasticity kernels, written once: the shape-function gradients of a tet, the
// Lamé parameters and the 12 by 12 element stiffness. Elasticity (serial) and dist's PETSc
// assembly (distributed) both build their matrices from these.
#pragma once
#include <Eigen/Dense>
#include <cmath>

#include "common/types.h"
#include "fem/elasticity.h"

namespace topopt::fem {

/// Lamé parameters λ and μ (MPa) of an isotropic material.
inline void lame(const Material& m, double& lambda, double& mu) {
  lambda = m.young * m.poisson / ((1 + m.poisson) * (1 - 2 * m.poisson));
  mu = m.young / (2 * (1 + m.poisson));
}

/// Shape-function gradients of tet t of `mesh` into g (4 by 3, row-major: g[3a + c] = ∂N_a/∂x_c).
/// Returns det J = 6 × the signed volume (> 0 for a positively oriented tet); g is left
/// untouched when it is not positive.
inline double tet_gradients(const TetMesh& mesh, long t, double* g) {
  Eigen::Matrix3d J;
  for (int k = 0; k < 3; ++k) J.col(k) = (mesh.V.row(mesh.T(t, k + 1)) - mesh.V.row(mesh.T(t, 0))).transpose();
  const double det = J.determinant();
  if (!(det > 0)) return det;
  const Eigen::Matrix3d Ji = J.inverse();  // row k: gradient of reference coordinate ξ_k
  for (int c = 0; c < 3; ++c) {
    g[c] = -(Ji(0, c) + Ji(1, c) + Ji(2, c));
    for (int k = 0; k < 3; ++k) g[3 * (k + 1) + c] = Ji(k, c);
  }
  return det;
}

/// The 12 by 12 element stiffness K (row-major, dof 3a + i) of a linear tet with gradients g
/// (4 by 3, row-major) and volume vol: K_ab,ij = vol (λ g_a,i g_b,j + μ g_a,j g_b,i + μ δ_ij g_a·g_b).
inline void element_stiffness(const double* g, double vol, double lambda, double mu, double* K) {
  for (int a = 0; a < 4; ++a)
    for (int b = 0; b < 4; ++b) {
      const double* ga = g + 3 * a;
      const double* gb = g + 3 * b;
      double dot = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          K[(3 * a + i) * 12 + 3 * b + j] =
              vol * (lambda * ga[i] * gb[j] + mu * ga[j] * gb[i] + (i == j ? mu * dot : 0.0));
    }
}

/// The upper triangle of element_stiffness: the 78 entries K_IJ with I <= J, row by row (I = 0,
/// J = 0..11, then I = 1, J = 1..11, ...), each computed as element_stiffness computes it (the
/// same values to the bit) without the 66 entries below the diagonal that assembly never reads.
/// g: 4 by 3 gradients (row-major); K: 78 values.
inline void element_stiffness_upper(const double* g, double vol, double lambda, double mu, double* K) {
  double dot[4][4];
  for (int a = 0; a < 4; ++a)
    for (int b = a; b < 4; ++b)
      dot[a][b] = g[3 * a] * g[3 * b] + g[3 * a + 1] * g[3 * b + 1] + g[3 * a + 2] * g[3 * b + 2];
  int k = 0;
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) {
      const double* ga = g + 3 * a;
      for (int b = a; b < 4; ++b) {
        const double* gb = g + 3 * b;
        for (int j = b == a ? i : 0; j < 3; ++j)
          K[k++] = vol * (lambda * ga[i] * gb[j] + mu * ga[j] * gb[i] + (i == j ? mu * dot[a][b] : 0.0));
      }
    }
}

/// Adds a tet's element matrix, given as its upper triangle Ke (78 values, element_stiffness_upper's
/// order), into the values `val` of a matrix in full compressed rows whose rows come in node blocks
/// sharing their columns (Elasticity's K). Entry (I, J) and its mirror (J, I) both take Ke's value,
/// so the matrix is symmetric to the bit. dof: the row of each of the 12 local dofs (-1: a fixed dof,
/// no row); first: each node's first row (-1: none); len: the length of each node's rows; at: for
/// nodes a, b (entry 4a + b) the position in val of the entry (first[a], first[b]) (-1: no such).
inline void add_element_upper(const int* dof, const int* first, const int* len, const int* at, const double* Ke,
                              double* val) {
  int p = 0;
  for (int I = 0; I < 12; ++I)
    for (int J = I; J < 12; ++J, ++p) {
      if (dof[I] < 0 || dof[J] < 0) continue;
      const int a = I / 3, b = J / 3, i = dof[I] - first[a], j = dof[J] - first[b];
      val[at[4 * a + b] + i * len[a] + j] += Ke[p];
      if (I != J) val[at[4 * b + a] + j * len[b] + i] += Ke[p];
    }
}

/// add_element_upper for a tet whose four nodes have all three dofs as rows (most tets): the same
/// values into the same entries, block by block, without a test per entry (its assembly's
/// scatter costs about half). len, at: as add_element_upper's.
inline void add_free_element_upper(const int* len, const int* at, const double* Ke, double* val) {
  int p = 0;  // Ke's order: row I = 3a + i, its columns J >= I
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i) {
      // the diagonal block (a, a) from its diagonal on, and its mirror below the diagonal
      double* diagonal = val + at[5 * a];
      diagonal[i * len[a] + i] += Ke[p++];
      for (int j = i + 1; j < 3; ++j, ++p) {
        diagonal[i * len[a] + j] += Ke[p];
        diagonal[j * len[a] + i] += Ke[p];
      }
      // the blocks (a, b > a), their row i, and the mirrors (b, a), their column i
      for (int b = a + 1; b < 4; ++b) {
        double* upper = val + at[4 * a + b] + i * len[a];
        double* lower = val + at[4 * b + a] + i;
        for (int j = 0; j < 3; ++j, ++p) {
          upper[j] += Ke[p];
          lower[j * len[b]] += Ke[p];
        }
      }
    }
}

/// The strain ε = sym(∇u) of a linear tet with gradients g (4 by 3, row-major) under the
/// corner displacements u (12: 3a + component), ∇u = Σ_a u_a ⊗ g_a.
inline Eigen::Matrix3d element_strain(const double* g, const double* u) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 4; ++a)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) H(i, j) += u[3 * a + i] * g[3 * a + j];
  return 0.5 * (H + H.transpose());
}

/// u_eᵀ K0_e u_e of a linear tet of volume vol with strain eps: vol (λ (tr ε)² + 2μ ε:ε), twice
/// its strain energy at unit stiffness factor.
inline double element_energy_of_strain(const Eigen::Matrix3d& eps, double vol, double lambda, double mu) {
  const double tr = eps.trace();
  return vol * (lambda * tr * tr + 2 * mu * eps.cwiseAbs2().sum());
}

/// The stress λ tr(ε) I + 2μ ε of strain eps (MPa for mm and N).
inline Eigen::Matrix3d stress_of_strain(const Eigen::Matrix3d& eps, double lambda, double mu) {
  return lambda * eps.trace() * Eigen::Matrix3d::Identity() + 2 * mu * eps;
}

/// von Mises of a stress tensor: √(3/2 s:s), s its deviator.
inline double von_mises_of_stress(const Eigen::Matrix3d& sigma) {
  const Eigen::Matrix3d dev = sigma - sigma.trace() / 3 * Eigen::Matrix3d::Identity();
  return std::sqrt(1.5 * dev.cwiseAbs2().sum());
}

/// von Mises of the stress of strain eps scaled by `scale` >= 0 (a SIMP element's stiffness factor).
inline double von_mises_of_strain(const Eigen::Matrix3d& eps, double lambda, double mu, double scale) {
  return scale * von_mises_of_stress(stress_of_strain(eps, lambda, mu));
}

}  // namespace topopt::fem
