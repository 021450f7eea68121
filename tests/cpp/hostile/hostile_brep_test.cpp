// The hostile-input suite, command-line half: the rocker exported to BREP, damaged in 120
// deterministic ways (tests/cpp/hostile/fuzz_brep.h), each read by `topopt info` and a few
// meshed by `topopt mesh`. Every case must end within 30 s in a result or in an error that
// names the part in user words: no signal death, no internal error, no hang (the budget is
// set to 20 s so that a hang shows as a Timeout, which fails the test), no OCCT names.
// The Python half is tests/python/app/test_hostile_input.py.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>

#include "brep/shape_io.h"
#include "cli/run_cli.h"
#include "hostile/fuzz_brep.h"

namespace {
namespace fs = std::filesystem;
using topopt::testing::Damage;
using topopt::testing::run_cli;

constexpr int kCasesPerKind = 24;  // x 5 kinds = 120 damaged files

/// A private folder holding the rocker's BREP text (written once per process).
struct Workspace {
  fs::path dir;
  std::string rocker;
  Workspace() {
    dir = fs::temp_directory_path() / ("topopt_hostile_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    rocker = topopt::brep::write_brep_string(
        topopt::brep::read_shape_file(std::string(TOPOPT_SHARED_DATA) + "/examples/rocker.step"));
  }
  ~Workspace() { fs::remove_all(dir); }
};

Workspace& workspace() {
  static Workspace w;
  return w;
}

fs::path write_case(Damage kind, int seed) {
  fs::path p =
      workspace().dir / ("case_" + std::to_string(static_cast<int>(kind)) + "_" + std::to_string(seed) + ".brep");
  std::ofstream(p, std::ios::binary) << topopt::testing::damage_brep(workspace().rocker, kind, seed);
  return p;
}

/// What one run ended in: "result", or the error code printed ("Io", "Crashed", ...).
struct Outcome {
  std::string kind;
  double seconds = 0;
};

/// Checks the promises on one run of `command` (`mesh`: a mesh command) and names its outcome.
Outcome judge(const std::string& command, const topopt::testing::CliResult& r, double seconds, bool mesh) {
  const std::string where = command + "\n" + r.out;
  EXPECT_LT(seconds, 30.0) << where;
  EXPECT_TRUE(r.code == 0 || r.code == 1) << "exit " << r.code << " (-1: killed by a signal)\n" << where;
  for (const char* internal : {"internal error", "::", "Standard_", "NCollection", "TopoDS_", "BRepCheck", "Geom_"})
    EXPECT_EQ(r.out.find(internal), std::string::npos) << "'" << internal << "' in\n" << where;
  std::smatch m;
  if (std::regex_search(r.out, m, std::regex("error \\(([A-Za-z]+)\\): (.*)"))) {
    EXPECT_NE(m[1], "Timeout") << where;  // a hang cut off by the budget
    EXPECT_NE(m[1], "Internal") << where;
    // reading and checking errors name the input; the mesher's name a face or a solid
    if (!mesh) {
      EXPECT_NE(m[2].str().find("part"), std::string::npos) << "the message does not name the part\n" << where;
    }
    return {m[1], seconds};
  }
  if (!mesh) {
    EXPECT_EQ(r.code, 0) << where;  // (a mesh with defects is written and exits 1)
  }
  EXPECT_NE(r.out.find(mesh ? "wrote" : "part: 1 solid"), std::string::npos) << where;
  return {"result", seconds};
}

Outcome run_case(const std::string& args, bool mesh = false) {
  const auto t0 = std::chrono::steady_clock::now();
  const auto r = run_cli(args);
  return judge(args, r, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), mesh);
}

/// Runs `topopt info` on every case of one kind of damage and prints how they ended.
void info_cases(Damage kind, const char* name) {
  std::map<std::string, int> count;
  double slowest = 0;
  for (int seed = 1; seed <= kCasesPerKind; ++seed) {
    const Outcome o = run_case("info --time-budget 20 --part " + write_case(kind, seed).string());
    count[o.kind]++;
    slowest = std::max(slowest, o.seconds);
  }
  std::string summary;
  for (const auto& [k, n] : count) summary += " " + k + " " + std::to_string(n);
  std::cout << name << ":" << summary << "; slowest " << slowest << " s\n";
}

}  // namespace

TEST(HostileBrep, ByteFlips) { info_cases(Damage::Flip, "byte flips"); }
TEST(HostileBrep, Inserts) { info_cases(Damage::Insert, "inserts"); }
TEST(HostileBrep, Deletes) { info_cases(Damage::Delete, "deletes"); }
TEST(HostileBrep, Truncations) { info_cases(Damage::Truncate, "truncations"); }
TEST(HostileBrep, DigitChanges) { info_cases(Damage::Digit, "digit changes"); }

TEST(HostileBrep, MeshingDamagedPartsThatRead) {
  // The interesting ones for the mesher: damage that `info` accepts (a changed digit moves a
  // point or a radius and the part still checks). Four of them through `topopt mesh`.
  int meshed = 0;
  for (int seed = 1; seed <= 4 * kCasesPerKind && meshed < 4; ++seed) {
    const fs::path p = write_case(Damage::Digit, seed);
    if (run_cli("info --time-budget 20 --part " + p.string()).code != 0) continue;
    const fs::path out = workspace().dir / ("mesh_" + std::to_string(seed) + ".msh");
    const Outcome o =
        run_case("mesh --time-budget 20 --mesher native --part " + p.string() + " --out " + out.string(), true);
    std::cout << "mesh of digit case " << seed << ": " << o.kind << " in " << o.seconds << " s\n";
    ++meshed;
  }
  EXPECT_EQ(meshed, 4);
}

TEST(HostileBrep, NamedRegressionCasesThroughTheCli) {
  const std::string dir = std::string(TOPOPT_TEST_DATA) + "/hostile/";
  auto r = run_cli("info --part " + dir + "line_missing_a_number.brep");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("topopt info: error (Crashed): the part's file '" + dir +
                       "line_missing_a_number.brep' is damaged: OCCT crashed reading it (Segmentation fault, signal "
                       "11); re-export it from your CAD system"),
            std::string::npos)
      << r.out;
  r = run_cli("info --part " + std::string(TOPOPT_SHARED_DATA) + "/examples/rocker.step --non-design " + dir +
              "edge_without_curve.brep");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("topopt info: error (InvalidShape): the non-design input is damaged: Edge16 has no 3D curve"),
            std::string::npos)
      << r.out;
  r = run_cli("info --part " + dir + "plane_normal_damaged.brep");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.out.find("topopt info: error (InvalidShape): the part is damaged: Edge9 is not on Face8"),
            std::string::npos)
      << r.out;
}
