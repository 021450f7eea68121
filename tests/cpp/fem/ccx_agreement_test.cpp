// The same mesh, supports and loads solved by CalculiX (ccx, C3D4) and by us must give the
// same displacements to solver precision: both assemble the same linear tet stiffness.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "fem/boundary_conditions.h"
#include "fem/elasticity.h"
#include "io/inp.h"
#include "mesh/core/structured_box.h"

namespace topopt::fem {
namespace {
namespace fs = std::filesystem;

TEST(CalculixAgreement, DisplacementsAgreeWithCcx) {
  if (std::system("command -v ccx > /dev/null 2>&1") != 0) GTEST_SKIP() << "ccx is not installed";
  mesh::StructuredBoxParams p;
  p.size = {30, 6, 4};
  p.cells = {10, 3, 2};
  p.nondesign = {{27, 0, 0, 30, 6, 4}};
  TetMesh m = mesh::structured_box_mesh(p);
  // distort the interior a little so that the elements are not all alike
  for (long i = 0; i < m.V.rows(); ++i)
    if (m.V(i, 0) > 1e-9 && m.V(i, 0) < 30 - 1e-9) m.V(i, 1) += 0.05 * std::sin(m.V(i, 0));
  Material mat{70000, 0.33, 2.7e-9};
  Supports s = make_supports(m, {support_on(SupportSpec::Kind::Fixed, {1}),
                                 SupportSpec{SupportSpec::Kind::Components, {3}, {false, true, false}, {}}});
  LoadCase lc{"mixed",
              {LoadSpec{LoadSpec::Kind::Force, {2}, {10, -20, -150}, 0, {}},
               LoadSpec{LoadSpec::Kind::Pressure, {6}, {0, 0, 0}, 0.8, {}}},
              1};
  Eigen::MatrixXd F = make_loads(m, mat, {lc});
  // a non-uniform stiffness field, as in SIMP (written as one material per factor)
  VecXd scale(m.T.rows());
  for (long t = 0; t < m.T.rows(); ++t) scale[t] = t % 3 == 0 ? 0.5 : 1.0;
  Elasticity fe(m, mat, s);
  fe.set_scale(scale);
  Eigen::MatrixXd U = fe.solve(F);

  fs::path dir = fs::temp_directory_path() / ("topopt_ccx_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  io::write_inp((dir / "job.inp").string(), m, mat, s, F, 0, scale);
  std::string cmd = "cd '" + dir.string() + "' && OMP_NUM_THREADS=1 ccx job > ccx.log 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "ccx failed; see " << dir / "ccx.log";
  MatX3d Uc = io::read_ccx_displacements((dir / "job.dat").string(), static_cast<int>(m.V.rows()));
  double diff = 0, norm = 0;
  for (long i = 0; i < m.V.rows(); ++i)
    for (int c = 0; c < 3; ++c) {
      diff += std::pow(U(3 * i + c, 0) - Uc(i, c), 2);
      norm += std::pow(Uc(i, c), 2);
    }
  // ccx prints 7 significant digits; the rest is solver round-off.
  EXPECT_LT(std::sqrt(diff / norm), 1e-6) << "relative difference to ccx";
  EXPECT_GT(norm, 0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace topopt::fem
