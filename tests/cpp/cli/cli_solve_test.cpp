// topopt solve from the shell: a job with a mesh file, its printed compliance against the
// library's, its files, and bad input with a clear message and a non-zero exit.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>

#include "cli/run_cli.h"
#include "fem/boundary_conditions.h"
#include "fem/elasticity.h"
#include "io/msh.h"
#include "mesh/core/structured_box.h"

namespace {
namespace fs = std::filesystem;
using topopt::testing::run_cli;

TEST(CliSolve, SolvesAJobWithAMeshFile) {
  fs::path dir = fs::temp_directory_path() / ("topopt_cli_solve_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  topopt::mesh::StructuredBoxParams p;
  p.size = {20, 4, 4};
  p.cells = {10, 2, 2};
  topopt::TetMesh m = topopt::mesh::structured_box_mesh(p);
  topopt::io::write_msh((dir / "beam.msh").string(), m);
  std::ofstream(dir / "job.json") << R"({"mesh": {"file": "beam.msh"},
     "material": {"E": 200000, "nu": 0.3},
     "supports": [{"type": "fixed", "faces": ["Face1"]}],
     "load_cases": [{"name": "tip", "loads": [{"type": "force", "faces": ["Face2"], "vector": [0, 0, -100]}]}]})";
  auto r = run_cli("solve " + (dir / "job.json").string() + " --inp " + (dir / "beam.inp").string());
  ASSERT_EQ(r.code, 0) << r.out;
  std::smatch sm;
  ASSERT_TRUE(std::regex_search(r.out, sm, std::regex("compliance ([0-9.eE+-]+)"))) << r.out;
  double printed = std::stod(sm[1]);
  using namespace topopt::fem;
  Material mat{200000, 0.3};
  Supports s = make_supports(m, {support_on(SupportSpec::Kind::Fixed, {1})});
  Eigen::MatrixXd F =
      make_loads(m, mat, {LoadCase{"tip", {LoadSpec{LoadSpec::Kind::Force, {2}, {0, 0, -100}, 0, {}}}, 1}});
  Elasticity fe(m, mat, s);
  double compliance = F.col(0).dot(fe.solve(F).col(0));
  EXPECT_NEAR(printed, compliance, 1e-5 * compliance);
  EXPECT_TRUE(fs::exists(dir / "out" / "result.vtu"));
  EXPECT_TRUE(fs::exists(dir / "beam.inp"));
  // a face the mesh does not have
  std::ofstream(dir / "bad.json") << R"({"mesh": {"file": "beam.msh"},
     "supports": [{"faces": ["Face9"]}],
     "load_cases": [{"loads": [{"faces": ["Face2"], "vector": [0, 0, -1]}]}]})";
  r = run_cli("solve " + (dir / "bad.json").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("FaceNotFound"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Face9"), std::string::npos) << r.out;
  // no support
  std::ofstream(dir / "free.json") << R"({"mesh": {"file": "beam.msh"},
     "supports": [{"type": "components", "faces": ["Face1"], "fix": ["x"]}],
     "load_cases": [{"loads": [{"faces": ["Face2"], "vector": [0, 0, -1]}]}]})";
  r = run_cli("solve " + (dir / "free.json").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("NoSupport"), std::string::npos) << r.out;
  r = run_cli("solve " + (dir / "missing.json").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("cannot open the job file"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

}  // namespace
