// `topopt result`: a finished run's shape at the threshold the user chooses, as STEP (and STL),
// without optimising again; mistakes are named with what to do.
#include <gtest/gtest.h>
#include <unistd.h>

#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp_Explorer.hxx>
#include <filesystem>
#include <fstream>

#include "cli/run_cli.h"
#include "io/msh.h"
#include "mesh/core/structured_box.h"
#include "result/step_export.h"

namespace {
namespace fs = std::filesystem;
using topopt::testing::run_cli;

/// A 20 x 6 x 6 mm beam (beam.msh), fixed at x = 0 and loaded at x = 20, optimised for a few
/// iterations into DIR/out (no verification), once for all the tests.
class CliResultCommand : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("topopt_cli_result_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    topopt::mesh::StructuredBoxParams p;
    p.size = {20, 6, 6};
    p.cells = {20, 6, 6};
    topopt::io::write_msh((dir_ / "beam.msh").string(), topopt::mesh::structured_box_mesh(p));
    std::ofstream(dir_ / "job.json")
        << R"({"mesh": {"file": "beam.msh"}, "supports": [{"type": "fixed", "faces": ["Face1"]}],
              "load_cases": [{"name": "tip", "loads": [{"type": "force", "faces": ["Face2"], "vector": [0, 0, -100]}]}],
              "optimization": {"volume_fraction": 0.4, "max_iterations": 15},
              "output": {"step": false, "verification": false}})";
    optimized_ = run_cli("optimize " + job() + " --quiet");
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static std::string job() { return (dir_ / "job.json").string(); }

  /// The STEP file at `path` read back by OCCT.
  static topopt::result::StepExportReport read_back(const fs::path& path) {
    STEPControl_Reader reader;
    if (reader.ReadFile(path.string().c_str()) != IFSelect_RetDone) return {};
    reader.TransferRoots();
    return topopt::result::describe_solid(reader.OneShape());
  }

  static inline fs::path dir_;
  static inline topopt::testing::CliResult optimized_;
};

TEST_F(CliResultCommand, TheShapeAtEachThresholdAsOneValidSolid) {
  ASSERT_EQ(optimized_.code, 0) << optimized_.out;
  const auto low = run_cli("result " + job() + " --threshold 0.3 --step " + (dir_ / "low.step").string() + " --stl " +
                           (dir_ / "low.stl").string() + " --quiet");
  ASSERT_EQ(low.code, 0) << low.out;
  EXPECT_GT(fs::file_size(dir_ / "low.stl"), 84u);
  const auto high = run_cli("result " + job() + " --threshold 0.7 --quiet");  // default name in the run's folder
  ASSERT_EQ(high.code, 0) << high.out;
  const auto a = read_back(dir_ / "low.step"), b = read_back(dir_ / "out" / "result_0.70.step");
  EXPECT_TRUE(a.valid);
  EXPECT_TRUE(b.valid);
  EXPECT_EQ(a.solids, 1);
  EXPECT_GE(b.solids, 1);  // at 0.7 the short run's beam may come apart: a solid per body
  // less material at the higher threshold; the run's densities were read, not made up
  EXPECT_GT(a.volume, 1.1 * b.volume);
  EXPECT_GT(b.volume, 0);
  EXPECT_LT(a.volume, 20.0 * 6 * 6);
}

TEST_F(CliResultCommand, MistakesAreNamed) {
  auto r = run_cli("result " + job() + " --threshold 1.5");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--threshold takes a density in (0, 1)"), std::string::npos) << r.out;
  r = run_cli("result " + job() + " --threshold 0.5 --out-dir " + (dir_ / "never_run").string());
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("run 'topopt optimize' on the job first"), std::string::npos) << r.out;
  // a density.vtu of another mesh
  fs::create_directories(dir_ / "other");
  std::ofstream(dir_ / "other" / "density.vtu")
      << R"(<Piece NumberOfPoints="4" NumberOfCells="1"><CellData><DataArray Name="density">0.5</DataArray>)";
  r = run_cli("result " + job() + " --threshold 0.5 --out-dir " + (dir_ / "other").string());
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("changed since that run"), std::string::npos) << r.out;
}

}  // namespace
