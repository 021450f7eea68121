// The job path from the shell: every mistake the issue lists stops before any work with a
// message that says what to change, results never follow a symlink, and sizes are checked
// against the part by `surface` as by `mesh`.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli/run_cli.h"
#include "io/msh.h"
#include "mesh/core/structured_box.h"

namespace {
namespace fs = std::filesystem;
using topopt::testing::CliResult;
using topopt::testing::run_cli;

/// A folder with beam.msh: a 20 x 4 x 4 mm box, Face1 at x = 0, Face2 at x = 20.
class CliJob : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("topopt_cli_job_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    topopt::mesh::StructuredBoxParams p;
    p.size = {20, 4, 4};
    p.cells = {10, 2, 2};
    topopt::io::write_msh((dir_ / "beam.msh").string(), topopt::mesh::structured_box_mesh(p));
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Writes job.json with the given sections around beam.msh and runs `command` on it.
  CliResult run(const std::string& command, const std::string& supports, const std::string& loads,
                const std::string& extra = "") {
    std::ofstream(dir_ / "job.json") << "{\"mesh\": {\"file\": \"beam.msh\"}, \"supports\": " << supports
                                     << ", \"load_cases\": [{\"name\": \"tip\", \"loads\": " << loads << "}]" << extra
                                     << "}";
    return run_cli(command + " " + (dir_ / "job.json").string());
  }
  CliResult optimize(const std::string& extra, const std::string& loads = kTip) {
    return run("optimize", kFixed, loads, extra);
  }

  static constexpr const char* kFixed = R"([{"type": "fixed", "faces": ["Face1"]}])";
  static constexpr const char* kTip = R"([{"type": "force", "faces": ["Face2"], "vector": [0, 0, -100]}])";
  fs::path dir_;
};

/// r failed with `code` and printed every fragment, and did no work (no mesh was read).
void expect_refused(const CliResult& r, int code, const std::vector<std::string>& fragments) {
  EXPECT_EQ(r.code, code) << r.out;
  for (const auto& f : fragments) EXPECT_NE(r.out.find(f), std::string::npos) << r.out;
}

TEST_F(CliJob, MisspeltDuplicatedAndFractionalKeysStopBeforeAnyWork) {
  CliResult r = optimize(R"(, "optimization": {"volume_fracton": 0.2})");
  expect_refused(r, 2, {"unknown key 'optimization.volume_fracton': did you mean 'volume_fraction'?"});
  EXPECT_EQ(r.out.find("[mesh]"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  std::ofstream(dir_ / "typo.json") << R"({"mesh": {"file": "beam.msh"}, "suports": [{"faces": ["Face1"]}]})";
  expect_refused(run_cli("solve " + (dir_ / "typo.json").string()), 2,
                 {"unknown key 'suports': did you mean 'supports'?"});
  expect_refused(optimize(R"(, "optimization": {"volume_fraction": 0.2}, "optimization": {"penalty": 3})"), 2,
                 {"'optimization' appears twice"});
  expect_refused(optimize(R"(, "optimization": {"max_iterations": 2.5})"), 2,
                 {"'optimization.max_iterations' must be a whole number from 1 to 10000, not 2.5"});
}

TEST_F(CliJob, LoadsThatCannotWorkAreNamed) {
  expect_refused(optimize("", R"([{"faces": ["Face2"], "vector": [0, 0, 0]}])"), 2,
                 {"load case \"tip\" puts no force on the part"});
  expect_refused(run("optimize", R"([{"faces": ["Face1", "Face2", "Face3", "Face4", "Face5", "Face6"]}])", kTip), 2,
                 {"load case \"tip\" acts only where the supports hold the part"});
  expect_refused(optimize("", R"([{"faces": ["Face2"], "vector": [0, 0, 1e308]}])"), 2,
                 {"'load_cases[0].loads[0].vector' has a magnitude of 1e+308 N"});
  expect_refused(run("solve", kFixed, R"([{"faces": ["Face2"], "vector": [0, 0, 1e308]}])"), 2, {"magnitude"});
  expect_refused(optimize(R"(, "optimization": {"filter_radius": 1000})"), 2,
                 {"'optimization.filter_radius' (1000 mm) is larger than the part"});
}

TEST_F(CliJob, AnOutputFolderThatCannotBeMadeIsFoundBeforeMeshing) {
  std::ofstream(dir_ / "a_file") << "x";
  const CliResult r = optimize(R"(, "output": {"directory": "a_file/out"})");
  expect_refused(r, 1, {"cannot create the output folder", "'output.directory' (or --out-dir)"});
  EXPECT_EQ(r.out.find("[mesh]"), std::string::npos) << r.out;
  const CliResult s = run("solve", kFixed, kTip, R"(, "output": {"directory": "a_file/out"})");
  expect_refused(s, 1, {"cannot create the output folder"});
  EXPECT_EQ(s.out.find("mesh:"), std::string::npos) << s.out;
}

TEST_F(CliJob, ResultsReplaceASymlinkAndLeaveItsTargetAlone) {
  fs::create_directories(dir_ / "out");
  std::ofstream(dir_ / "precious.stl") << "not yours";
  fs::create_symlink(dir_ / "precious.stl", dir_ / "out" / "result.stl");
  const CliResult r = optimize(R"(, "optimization": {"max_iterations": 2})");
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(dir_ / "precious.stl");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "not yours");
  EXPECT_FALSE(fs::is_symlink(dir_ / "out" / "result.stl"));
  EXPECT_GT(fs::file_size(dir_ / "out" / "result.stl"), 84u);  // a binary STL with triangles
  for (const auto& e : fs::directory_iterator(dir_ / "out"))   // no temporary left behind
    EXPECT_NE(e.path().filename().string()[0], '.') << e.path();
}

TEST_F(CliJob, AMeshFileErrorNeverShowsTheFilesText) {
  std::ofstream(dir_ / "notes.txt") << "password=hunter2 keep this private\n";
  std::ofstream(dir_ / "job.json") << R"({"mesh": {"file": "notes.txt"}, "supports": [{"faces": ["Face1"]}],
    "load_cases": [{"loads": [{"faces": ["Face2"], "vector": [0, 0, -1]}]}]})";
  const CliResult r = run_cli("solve " + (dir_ / "job.json").string());
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("expected a Gmsh MSH 4.1 ASCII file"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("hunter2"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("password"), std::string::npos) << r.out;
}

TEST(CliSizes, SurfaceChecksTheSizeAgainstThePartAsMeshDoes) {
  const std::string rocker = std::string(TOPOPT_SHARED_DATA) + "/examples/rocker.step";
  // larger than the part (diagonal 138.6 mm): clamped with a warning (it ran away before)
  CliResult r = run_cli("surface --part " + rocker + " --size 3000");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("warning: the mesh size 3000 mm is larger than the part"), std::string::npos) << r.out;
  // far too fine: refused at once, by surface as by mesh
  for (const std::string command : {"surface", "mesh"}) {
    r = run_cli(command + " --part " + rocker + " --size 1e-4" + (command == "mesh" ? " --out /tmp/never.msh" : ""));
    EXPECT_EQ(r.code, 1) << r.out;
    EXPECT_NE(r.out.find("error (TooLarge)"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("use a mesh size of at least"), std::string::npos) << r.out;
  }
  r = run_cli("surface --part " + rocker + " --size 2 --min-size 3");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--min-size (3 mm) is larger than --size (2 mm)"), std::string::npos) << r.out;
}

}  // namespace
