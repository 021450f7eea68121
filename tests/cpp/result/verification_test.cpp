// Verification by analysis: the result surface meshed by the code's volume mesher and solved
// with the study's supports and loads (on Ω's faces and on a non-design face), checked against
// an independent solve of the same tets and against the crisp design on the FE mesh.
#include "result/verification.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "fem/elasticity.h"
#include "simp/density_filter.h"
#include "testing/bar_field.h"

namespace topopt::result {
namespace {

struct Fixture {
  TetMesh mesh;
  VecXd density;
  TriSurface surface;
  VerificationProblem problem;
};

/// A 40x20x10 box with a non-design block at each end (x in [0, 6] and [36, 40]) joined by a
/// round bar of radius about 4 (a smooth density field); fixed at Ω's Face1 (x = 0), pulled down by 100 N on the second
/// block's end face (NonDesign:Face8, part of Ω's Face2).
Fixture bar_fixture() {
  testing::BarField bar = testing::bar_field(6, [](double) { return 4.0; });
  Fixture f;
  f.mesh = std::move(bar.mesh);
  f.density = std::move(bar.density);
  f.surface = extract_iso_surface(f.mesh, node_densities(f.mesh, f.density), 0.5);
  fem::SupportSpec fixed;
  fixed.faces = {1};
  fem::LoadSpec down;
  down.vector = {0, 0, -100};
  down.nd_faces = {8};
  f.problem.supports = {fixed};
  f.problem.load_cases = {{"down", {down}, 1.0}};
  return f;
}

TEST(Verification, TheResultMeshCarriesTheLoadsOnTheRightFaces) {
  const Fixture f = bar_fixture();
  const TetMesh m = verification_mesh(f.surface, f.mesh, {}, 0);
  EXPECT_GT(m.T.rows(), 200);
  // the non-design face 8 (x = 40 on the block) is found on the result: its area is the block's 8 x 6
  double area = 0;
  for (long q = 0; q < m.F.rows(); ++q)
    if (m.nd_face[q] == 8) {
      const Eigen::Vector3d a = m.V.row(m.F(q, 0)), b = m.V.row(m.F(q, 1)), cc = m.V.row(m.F(q, 2));
      area += (b - a).cross(cc - a).norm() / 2;
      EXPECT_NEAR(a.x(), 40, 1e-9);
    }
  EXPECT_NEAR(area, 48, 1e-6);
  const Eigen::MatrixXd loads = fem::make_loads(m, f.problem.material, f.problem.load_cases);
  double fz = 0;
  for (long i = 0; i < m.V.rows(); ++i) fz += loads(3 * i + 2, 0);
  EXPECT_NEAR(fz, -100, 1e-9);
}

TEST(Verification, AsBuiltComplianceMatchesAnIndependentSolveAndTheCrispDesign) {
  const Fixture f = bar_fixture();
  const Verification v = verify_result(f.surface, f.mesh, f.density, 0.5, f.problem);
  ASSERT_EQ(v.U.cols(), 1);
  EXPECT_EQ(v.as_built.tets, v.mesh.T.rows());
  // an independent solve of the same tets
  fem::Elasticity fe(v.mesh, f.problem.material, fem::make_supports(v.mesh, f.problem.supports));
  const Eigen::MatrixXd loads = fem::make_loads(v.mesh, f.problem.material, f.problem.load_cases);
  const double c = loads.col(0).dot(fe.solve(loads).col(0));
  EXPECT_NEAR(v.as_built.compliance, c, 1e-6 * c);
  // the same shape on two meshes: the result's smooth bar against the FE mesh's staircase
  EXPECT_GT(v.crisp.compliance, 0);
  EXPECT_NEAR(v.ratio(), 1.0, 0.15) << v.as_built.compliance << " vs crisp " << v.crisp.compliance;
  // a cantilever bar of radius 4 and length ~30 under 100 N: beam theory gives ~ F L^3 / (3 E I)
  const double I = M_PI * std::pow(4.0, 4) / 4, L = 30;
  const double beam = 100 * std::pow(L, 3) / (3 * f.problem.material.young * I);
  EXPECT_GT(v.as_built.max_displacement, 0.5 * beam);
  EXPECT_LT(v.as_built.max_displacement, 3 * beam);
  EXPECT_GT(v.as_built.max_von_mises, 0);
}

TEST(Verification, RunsWithinItsBudgetOrSaysWhichStepRanOut) {
  const Fixture f = bar_fixture();
  VerificationParams params;
  params.seconds = 1e-6;
  try {
    verify_result(f.surface, f.mesh, f.density, 0.5, f.problem, params);
    FAIL() << "a verification with no time finished";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Timeout);
    EXPECT_NE(std::string(e.what()).find("meshing the result solid"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace topopt::result
