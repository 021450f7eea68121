// Linear elasticity: patch test, rigid-body null space, beam theory, symmetry, singular
// systems, warm-started PCG against the direct solver.
#include "fem/elasticity.h"

#include <gtest/gtest.h>

#include <random>

#include "common/error.h"
#include "fem/boundary_conditions.h"
#include "io/msh.h"
#include "mesh/core/structured_box.h"

namespace topopt::fem {
namespace {

TetMesh box(std::array<double, 3> size, std::array<int, 3> cells) {
  mesh::StructuredBoxParams p;
  p.size = size;
  p.cells = cells;
  return mesh::structured_box_mesh(p);
}

/// Moves interior nodes randomly by up to `amount` of the cell size (keeps tets positive).
void distort(TetMesh& m, double h, double amount, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amount * h, amount * h);
  Eigen::RowVector3d lo = m.V.colwise().minCoeff(), hi = m.V.colwise().maxCoeff();
  for (long i = 0; i < m.V.rows(); ++i) {
    bool boundary = false;
    for (int c = 0; c < 3; ++c) boundary |= std::abs(m.V(i, c) - lo[c]) < 1e-12 || std::abs(m.V(i, c) - hi[c]) < 1e-12;
    if (!boundary)
      for (int c = 0; c < 3; ++c) m.V(i, c) += u(rng);
  }
}

TEST(Elasticity, PatchTestReproducesLinearFieldOnDistortedMesh) {
  TetMesh m = box({4, 3, 2}, {4, 3, 2});
  distort(m, 1.0, 0.2, 7);
  Eigen::Matrix3d A;
  A << 1e-3, 2e-4, -3e-4, 5e-4, -2e-3, 1e-4, -4e-4, 3e-4, 1.5e-3;
  Eigen::Vector3d b(0.01, -0.02, 0.005);
  // All boundary nodes prescribed to u = A x + b; the interior must follow exactly.
  Supports s;
  std::vector<char> on(m.V.rows(), 0);
  for (long t = 0; t < m.F.rows(); ++t)
    for (int k = 0; k < 3; ++k) on[m.F(t, k)] = 1;
  int interior = 0;
  for (long i = 0; i < m.V.rows(); ++i) {
    if (!on[i]) {
      ++interior;
      continue;
    }
    Eigen::Vector3d u = A * m.V.row(i).transpose() + b;
    for (int c = 0; c < 3; ++c) s.dofs.push_back(static_cast<int>(3 * i + c)), s.values.push_back(u[c]);
  }
  ASSERT_GT(interior, 5);
  Elasticity fe(m, Material{}, s);
  Eigen::MatrixXd U = fe.solve(Eigen::MatrixXd::Zero(fe.num_dofs(), 1));
  double err = 0, ref = 0;
  for (long i = 0; i < m.V.rows(); ++i) {
    Eigen::Vector3d u = A * m.V.row(i).transpose() + b;
    for (int c = 0; c < 3; ++c)
      err = std::max(err, std::abs(U(3 * i + c, 0) - u[c])), ref = std::max(ref, std::abs(u[c]));
  }
  EXPECT_LT(err / ref, 1e-10);
  // Constant strain: every element carries the same von Mises stress.
  VecXd vm = fe.von_mises(U.col(0));
  EXPECT_LT((vm.array() - vm[0]).abs().maxCoeff(), 1e-8 * vm[0]);
}

TEST(Elasticity, RigidBodyModesCarryNoEnergy) {
  TetMesh m = box({3, 2, 1}, {3, 2, 2});
  distort(m, 0.5, 0.2, 3);
  Supports s{{0, 1, 2, 4, 5, 8}, {0, 0, 0, 0, 0, 0}};
  Elasticity fe(m, Material{}, s);
  Eigen::Vector3d c(1.5, 1.0, 0.5);
  for (int mode = 0; mode < 6; ++mode) {
    VecXd r(fe.num_dofs());
    for (long i = 0; i < m.V.rows(); ++i) {
      Eigen::Vector3d x = m.V.row(i).transpose() - c;
      Eigen::Vector3d v = mode < 3 ? Eigen::Vector3d(Eigen::Vector3d::Unit(mode))
                                   : Eigen::Vector3d(Eigen::Vector3d::Unit(mode - 3).cross(x));
      r.segment<3>(3 * i) = v;
    }
    VecXd e = fe.element_energy(r);
    EXPECT_LT(e.cwiseAbs().maxCoeff(), 1e-9 * Material{}.young) << "mode " << mode;
  }
  // A stretch is not a rigid motion: positive energy in every element.
  VecXd u(fe.num_dofs());
  for (long i = 0; i < m.V.rows(); ++i) u.segment<3>(3 * i) << 1e-3 * m.V(i, 0), 0, 0;
  EXPECT_GT(fe.element_energy(u).minCoeff(), 0);
}

/// Cantilever of length L, square section a×a, clamped at x = 0, a total shear force P (-z)
/// on the end face; the end deflection against Timoshenko's beam theory.
double cantilever_tip(std::array<int, 3> cells, double L, double a, double P, const Material& mat,
                      SolverKind kind = SolverKind::Auto) {
  TetMesh m = box({L, a, a}, cells);
  Supports s = make_supports(m, {support_on(SupportSpec::Kind::Fixed, {1})});
  LoadSpec load;
  load.kind = LoadSpec::Kind::Force;
  load.faces = {2};
  load.vector = {0, 0, -P};
  Eigen::MatrixXd F = make_loads(m, mat, {LoadCase{"tip", {load}, 1.0}});
  SolverParams sp;
  sp.kind = kind;
  sp.tolerance = 1e-10;
  Elasticity fe(m, mat, s, sp);
  Eigen::MatrixXd U = fe.solve(F);
  // Mean vertical displacement of the end face (the beam-theory deflection of the axis).
  double sum = 0;
  int n = 0;
  for (long i = 0; i < m.V.rows(); ++i)
    if (std::abs(m.V(i, 0) - L) < 1e-9) sum += U(3 * i + 2, 0), ++n;
  return -sum / n;
}

TEST(Elasticity, CantileverMatchesBeamTheory) {
  const double L = 100, a = 10, P = 100;
  Material mat;
  mat.young = 200000;
  mat.poisson = 0.3;
  const double I = a * a * a * a / 12, A = a * a, G = mat.young / (2 * (1 + mat.poisson));
  const double kappa = 10 * (1 + mat.poisson) / (12 + 11 * mat.poisson);
  const double theory = P * L * L * L / (3 * mat.young * I) + P * L / (kappa * G * A);
  // Three meshes halving h: linear tets are stiff in bending and converge from below; the
  // observed order and the Richardson extrapolation from the finest two must agree with the
  // theory, and the finest mesh alone comes within 4 % (2.4 % at 160x16x16, see the note).
  double d1 = cantilever_tip({30, 3, 3}, L, a, P, mat);
  double d2 = cantilever_tip({60, 6, 6}, L, a, P, mat);
  double d3 = cantilever_tip({120, 12, 12}, L, a, P, mat);
  EXPECT_LT(d1, d2);
  EXPECT_LT(d2, d3);
  EXPECT_LT(d3, theory * 1.001);
  double order = std::log2((d2 - d1) / (d3 - d2));
  EXPECT_GT(order, 1.0);
  EXPECT_LT(order, 2.2);
  double extrapolated = d3 + (d3 - d2) / (std::pow(2.0, order) - 1);
  EXPECT_LT(std::abs(extrapolated - theory) / theory, 0.02) << "extrapolated " << extrapolated << " theory " << theory;
  EXPECT_LT(std::abs(d3 - theory) / theory, 0.04) << "finest " << d3 << " theory " << theory;
}

TEST(Elasticity, CantileverWithinTwoPercentOnAFineMesh) {
  // The literal criterion: a fine mesh (200 x 20 x 20 cells, 480 k tets, 266 k
  // unknowns) solved by the multigrid comes within 2 % of Timoshenko's deflection.
  const double L = 100, a = 10, P = 100;
  Material mat;
  mat.young = 200000;
  mat.poisson = 0.3;
  const double I = a * a * a * a / 12, A = a * a, G = mat.young / (2 * (1 + mat.poisson));
  const double kappa = 10 * (1 + mat.poisson) / (12 + 11 * mat.poisson);
  const double theory = P * L * L * L / (3 * mat.young * I) + P * L / (kappa * G * A);
  const double d = cantilever_tip({200, 20, 20}, L, a, P, mat, SolverKind::Iterative);
  EXPECT_LT(d, theory * 1.001);
  EXPECT_LT(std::abs(d - theory) / theory, 0.02) << "deflection " << d << " theory " << theory;
}

TEST(Elasticity, IterativeSolverAgreesWithDirectAndWarmStarts) {
  const double L = 40, a = 8, P = 50;
  Material mat;
  double direct = cantilever_tip({10, 2, 2}, L, a, P, mat, SolverKind::Direct);
  double iterative = cantilever_tip({10, 2, 2}, L, a, P, mat, SolverKind::Iterative);
  EXPECT_NEAR(iterative, direct, 1e-7 * direct);
}

TEST(Elasticity, ScaleRefillsTheMatrix) {
  // Scaling every element by s divides the displacements by s exactly.
  TetMesh m = box({10, 2, 2}, {5, 1, 1});
  Supports s = make_supports(m, {support_on(SupportSpec::Kind::Fixed, {1})});
  LoadSpec load{LoadSpec::Kind::Force, {2}, {0, 10, 0}, 0, {}};
  Eigen::MatrixXd F = make_loads(m, Material{}, {LoadCase{"c", {load}, 1}});
  Elasticity fe(m, Material{}, s);
  Eigen::MatrixXd U1 = fe.solve(F);
  fe.set_scale(VecXd::Constant(m.T.rows(), 0.25));
  Eigen::MatrixXd U2 = fe.solve(F);
  EXPECT_LT((U2 - 4 * U1).norm(), 1e-10 * U2.norm());
  // and element energies scale back: u^T K0 u is unscaled.
  EXPECT_NEAR(fe.element_energy(U2.col(0)).sum(), 16 * fe.element_energy(U1.col(0)).sum(),
              1e-8 * fe.element_energy(U2.col(0)).sum());
  // Compliance F·U equals the sum of scaled element energies.
  EXPECT_NEAR(F.col(0).dot(U2.col(0)), 0.25 * fe.element_energy(U2.col(0)).sum(), 1e-9 * F.col(0).dot(U2.col(0)));
}

TEST(Elasticity, SymmetricHalfEqualsFullModel) {
  // Half beam y in [0, 2]; the full beam is its mirror image about y = 2, so the two meshes
  // agree node for node on the half.
  const double L = 12, a = 2;
  TetMesh half = box({L, a, 2 * a}, {6, 2, 2});
  // mirror
  const long nv = half.V.rows();
  std::vector<int> twin(nv);
  std::vector<Eigen::RowVector3d> extra;
  for (long i = 0; i < nv; ++i) {
    if (std::abs(half.V(i, 1) - a) < 1e-12) {
      twin[i] = static_cast<int>(i);
    } else {
      twin[i] = static_cast<int>(nv + extra.size());
      Eigen::RowVector3d p = half.V.row(i);
      p[1] = 2 * a - p[1];
      extra.push_back(p);
    }
  }
  TetMesh full;
  full.V.resize(nv + extra.size(), 3);
  full.V.topRows(nv) = half.V;
  for (size_t k = 0; k < extra.size(); ++k) full.V.row(nv + k) = extra[k];
  full.T.resize(2 * half.T.rows(), 4);
  full.T.topRows(half.T.rows()) = half.T;
  for (long t = 0; t < half.T.rows(); ++t)  // mirror flips orientation: swap two nodes
    full.T.row(half.T.rows() + t) << twin[half.T(t, 0)], twin[half.T(t, 1)], twin[half.T(t, 3)], twin[half.T(t, 2)];
  full.domain = VecXi::Zero(full.T.rows());
  full.F = io::boundary_triangles(full.T);
  full.face.resize(full.F.rows());
  for (long t = 0; t < full.F.rows(); ++t) {
    Eigen::RowVector3d c = (full.V.row(full.F(t, 0)) + full.V.row(full.F(t, 1)) + full.V.row(full.F(t, 2))) / 3;
    full.face[t] = std::abs(c[0]) < 1e-9 ? 1 : std::abs(c[0] - L) < 1e-9 ? 2 : 3;
  }
  Material mat;
  LoadSpec load{LoadSpec::Kind::Force, {2}, {0, 0, -100}, 0, {}};
  LoadSpec half_load = load;
  half_load.vector = {0, 0, -50};
  Eigen::MatrixXd Ff = make_loads(full, mat, {LoadCase{"f", {load}, 1}});
  Eigen::MatrixXd Fh = make_loads(half, mat, {LoadCase{"h", {half_load}, 1}});
  Elasticity ff(full, mat, make_supports(full, {support_on(SupportSpec::Kind::Fixed, {1})}));
  Elasticity fh(
      half, mat,
      make_supports(half, {support_on(SupportSpec::Kind::Fixed, {1}), support_on(SupportSpec::Kind::Symmetry, {4})}));
  Eigen::MatrixXd Uf = ff.solve(Ff), Uh = fh.solve(Fh);
  double err = (Uf.topRows(3 * nv) - Uh).cwiseAbs().maxCoeff();
  EXPECT_LT(err, 1e-9 * Uh.cwiseAbs().maxCoeff());
  EXPECT_GT(Uh.cwiseAbs().maxCoeff(), 0);
}

TEST(Elasticity, SolidVonMisesAndItsGradient) {
  // a uniaxial strain field: von Mises of σ = λ tr ε I + 2μ ε by hand, unscaled by set_scale
  TetMesh m = box({3, 2, 2}, {3, 2, 2});
  distort(m, 1.0, 0.2, 5);
  const Material mat;
  Elasticity fe(m, mat, Supports{});
  fe.set_scale(VecXd::Constant(m.T.rows(), 0.25));
  VecXd u(3 * m.V.rows());
  for (long n = 0; n < m.V.rows(); ++n) u.segment<3>(3 * n) = Eigen::Vector3d(1e-3 * m.V(n, 0), 0, 0);
  const double lambda = mat.young * mat.poisson / ((1 + mat.poisson) * (1 - 2 * mat.poisson));
  const double mu = mat.young / (2 * (1 + mat.poisson));
  const double sx = (lambda + 2 * mu) * 1e-3, sy = lambda * 1e-3;  // σ_yy = σ_zz
  const VecXd vm = fe.solid_von_mises(u);
  for (long t = 0; t < m.T.rows(); ++t) EXPECT_NEAR(vm[t], std::abs(sx - sy), 1e-9 * std::abs(sx - sy));
  EXPECT_NEAR(fe.von_mises(u)[0], 0.25 * vm[0], 1e-12 * vm[0]);
  // the gradient of Σ w_e vm_e against central differences at a random field
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> r(-1e-3, 1e-3);
  for (long i = 0; i < u.size(); ++i) u[i] = r(rng);
  VecXd w(m.T.rows());
  for (long t = 0; t < w.size(); ++t) w[t] = 1 + std::abs(r(rng)) * 1e3;
  const VecXd g = fe.solid_von_mises_gradient(u, w);
  const double h = 1e-8;  // u ~ 1e-3: truncation ~ (h/u)² against round-off ~ 1e-16 u / h
  for (long i : {0L, 7L, static_cast<long>(u.size() / 2), static_cast<long>(u.size() - 1)}) {
    VecXd up = u, um = u;
    up[i] += h, um[i] -= h;
    const double fd = (w.dot(fe.solid_von_mises(up)) - w.dot(fe.solid_von_mises(um))) / (2 * h);
    EXPECT_NEAR(g[i], fd, 1e-5 * std::abs(fd)) << "dof " << i;
  }
}

TEST(Elasticity, SingularSystemsAreReportedNotSolved) {
  TetMesh m = box({4, 2, 2}, {2, 1, 1});
  Material mat;
  // Only the normal component on one face: the part can still slide and spin.
  SupportSpec roller{SupportSpec::Kind::Components, {5}, {false, false, true}, {}};
  Elasticity fe(m, mat, make_supports(m, {roller}));
  try {
    fe.solve(Eigen::MatrixXd::Zero(fe.num_dofs(), 1));
    FAIL() << "expected NoSupport";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NoSupport);
    EXPECT_NE(std::string(e.what()).find("3 rigid-body motion(s) not held"), std::string::npos) << e.what();
  }
  // No support at all is refused when building the supports.
  try {
    make_supports(m, {});
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NoSupport);
  }
  // Two disjoint pieces, one held: the other one is named.
  TetMesh two = m;
  two.V.conservativeResize(2 * m.V.rows(), 3);
  two.V.bottomRows(m.V.rows()) = m.V.rowwise() + Eigen::RowVector3d(10, 0, 0);
  two.T.conservativeResize(2 * m.T.rows(), 4);
  two.T.bottomRows(m.T.rows()) = m.T.array() + static_cast<int>(m.V.rows());
  two.domain = VecXi::Zero(two.T.rows());
  Supports s = make_supports(m, {support_on(SupportSpec::Kind::Fixed, {1})});
  Elasticity f2(two, mat, s);
  try {
    f2.solve(Eigen::MatrixXd::Zero(f2.num_dofs(), 1));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NoSupport);
    EXPECT_NE(std::string(e.what()).find("no support at all"), std::string::npos) << e.what();
  }
}

TEST(BoundaryConditions, LoadTotalsAndFaceErrors) {
  TetMesh m = box({3, 2, 1}, {3, 2, 2});
  Material mat;
  LoadSpec force{LoadSpec::Kind::Force, {2, 4}, {3, -7, 11}, 0, {}};
  LoadSpec pressure{LoadSpec::Kind::Pressure, {6}, {0, 0, 0}, 2.5, {}};
  LoadSpec gravity{LoadSpec::Kind::Gravity, {}, {0, 0, -9810}, 0, {}};
  Eigen::MatrixXd F =
      make_loads(m, mat, {LoadCase{"f", {force}, 1}, LoadCase{"p", {pressure}, 1}, LoadCase{"g", {gravity}, 1}});
  auto total = [&](int c) {
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    for (long i = 0; i < m.V.rows(); ++i) s += F.block<3, 1>(3 * i, c);
    return s;
  };
  EXPECT_LT((total(0) - Eigen::Vector3d(3, -7, 11)).norm(), 1e-12);
  // 2.5 MPa on the top face (3 x 2 mm, outward +z) pushes down with 15 N.
  EXPECT_LT((total(1) - Eigen::Vector3d(0, 0, -15)).norm(), 1e-12);
  EXPECT_NEAR(total(2)[2], -mat.density * 6 * 9810, 1e-15);
  try {
    make_loads(m, mat, {LoadCase{"x", {LoadSpec{LoadSpec::Kind::Force, {9}, {1, 0, 0}, 0, {}}}, 1}});
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::FaceNotFound);
    EXPECT_NE(std::string(e.what()).find("Face9"), std::string::npos);
  }
  // A symmetry plane that is not planar is refused.
  try {
    make_supports(m, {support_on(SupportSpec::Kind::Symmetry, {1, 3})});
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidParameter);
  }
}

TEST(BoundaryConditions, LoadsOnNonDesignPads) {
  mesh::StructuredBoxParams p;
  p.size = {6, 2, 2};
  p.cells = {6, 2, 2};
  p.nondesign = {{5, 0, 0, 6, 2, 2}};  // an end block: its face x=max is box face 2 → nd face 2
  TetMesh m = mesh::structured_box_mesh(p);
  LoadSpec pad{LoadSpec::Kind::Force, {}, {0, 0, -4}, 0, {2}};
  Eigen::MatrixXd F = make_loads(m, Material{}, {LoadCase{"pad", {pad}, 1}});
  double fz = 0;
  for (long i = 0; i < m.V.rows(); ++i) {
    fz += F(3 * i + 2, 0);
    if (F(3 * i + 2, 0) != 0) {
      EXPECT_NEAR(m.V(i, 0), 6.0, 1e-12);
    }
  }
  EXPECT_NEAR(fz, -4, 1e-12);
}

}  // namespace
}  // namespace topopt::fem
