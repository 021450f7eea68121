// topopt worker as the FreeCAD workbench drives it: JSON lines on stdout (and nothing else
// there), results in result.json and NPY files, the core's errors as a last error line naming
// the stage, and the test-only TOPOPT_FAULT ending or stalling the worker at a chosen stage.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <BRepAdaptor_Surface.hxx>
#include <BRepAlgoAPI_Cut.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <gp_Ax2.hxx>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "brep/shape_io.h"
#include "io/npy.h"
#include "pipeline/job.h"
#include "pipeline/optimize_job.h"
#include "result/overhang_lift.h"

namespace {
namespace fs = std::filesystem;
using json = nlohmann::json;

/// What one worker run printed: its exit status as the shell reports it (128 + N when signal
/// N ended it) and its stdout lines, each parsed as JSON.
struct WorkerRun {
  int status = -1;
  std::vector<json> lines;
  bool all_json = true;
  const json& last() const { return lines.back(); }
};

WorkerRun run_worker(const fs::path& request, const std::string& env = "", const std::string& wrapper = "") {
  const std::string cmd =
      env + " " + wrapper + " " + TOPOPT_CLI + " worker " + request.string() + " 2>/dev/null; echo \"status=$?\"";
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  size_t n;
  while (pipe && (n = fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), n);
  if (pipe) pclose(pipe);
  WorkerRun r;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("status=", 0) == 0) {
      r.status = std::stoi(line.substr(7));
      continue;
    }
    json j = json::parse(line, nullptr, false);
    r.all_json = r.all_json && j.is_object();
    r.lines.push_back(j);
  }
  return r;
}

/// Starts the worker with `env`, reads its stdout lines until one reports `stage` (or it ends,
/// or `deadline_s` passes), then kills it with SIGKILL: how a stalled worker is stopped, with
/// no fixed wait that a loaded machine could outlast before the stage is even reached.
WorkerRun run_worker_until_stage(const fs::path& request, const std::string& env, const std::string& stage,
                                 double deadline_s = 120) {
  int out[2];
  if (pipe(out) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(out[1], 1);
    close(out[0]);
    close(out[1]);
    const std::string cmd = env + " exec " + TOPOPT_CLI + " worker " + request.string() + " 2>/dev/null";
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  close(out[1]);
  FILE* f = fdopen(out[0], "r");
  WorkerRun r;
  const auto t0 = std::chrono::steady_clock::now();
  char* line = nullptr;
  size_t cap = 0;
  while (getline(&line, &cap, f) > 0) {
    json j = json::parse(line, nullptr, false);
    r.all_json = r.all_json && j.is_object();
    r.lines.push_back(j);
    if (j.is_object() && j.value("stage", "") == stage) break;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > deadline_s) break;
  }
  free(line);
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  fclose(f);
  r.status = WIFSIGNALED(status) ? 128 + WTERMSIG(status) : WEXITSTATUS(status);
  return r;
}

class CliWorker : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("topopt_cli_worker_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path request(const json& r) {
    const fs::path p = dir_ / "request.json";
    std::ofstream(p) << r.dump();
    return p;
  }

  /// A unit cube split into 6 positive tets, its arrays written as NPY files; densities all `rho`.
  json cube_arrays(int bad_node = -1) {
    topopt::MatX3d V(8, 3);
    for (int i = 0; i < 8; ++i) V.row(i) << (i & 1), (i >> 1) & 1, (i >> 2) & 1;
    topopt::MatX4i T(6, 4);
    T << 0, 1, 3, 7, 0, 1, 7, 5, 0, 5, 7, 4, 0, 3, 2, 7, 0, 2, 6, 7, 0, 6, 4, 7;
    if (bad_node >= 0) T(2, 1) = bad_node;
    topopt::io::write_npy((dir_ / "nodes.npy").string(), V);
    topopt::io::write_npy((dir_ / "tets.npy").string(), T);
    topopt::io::write_npy((dir_ / "densities.npy").string(), topopt::VecXd(topopt::VecXd::Ones(6)));
    return {{"nodes", "nodes.npy"}, {"tets", "tets.npy"}, {"densities", "densities.npy"}};
  }

  json extract_request(int bad_node = -1) {
    return {{"operation", "extract_surface"},
            {"arrays", cube_arrays(bad_node)},
            {"params", {{"threshold", 0.5}, {"smoothing_iterations", 0}}},
            {"output", "out"}};
  }

  /// Writes beam.brep, a 60 × 10 × 10 box, and returns the job of that beam fixed at x = 0
  /// (Face1) and pulled down by 100 N at x = 60 (Face2), meshed at size 4, with `optimization`.
  json beam_job(const json& optimization) {
    std::ofstream(dir_ / "beam.brep") << topopt::brep::write_brep_string(BRepPrimAPI_MakeBox(60, 10, 10).Shape());
    return {{"mesh", {{"size", 4.0}}},
            {"material", {{"E", 210000}, {"nu", 0.3}}},
            {"supports", {{{"type", "fixed"}, {"faces", {"Face1"}}}}},
            {"load_cases",
             {{{"name", "tip"}, {"loads", {{{"type", "force"}, {"faces", {"Face2"}}, {"vector", {0, 0, -100}}}}}}}},
            {"optimization", optimization}};
  }

  fs::path dir_;
};

/// The volume enclosed by a closed, outward triangle surface (divergence theorem).
double enclosed_volume(const topopt::io::RowMatXd& P, const topopt::io::RowMatXl& F) {
  double v = 0;
  for (long t = 0; t < F.rows(); ++t) {
    Eigen::Vector3d a = P.row(F(t, 0)), b = P.row(F(t, 1)), c = P.row(F(t, 2));
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

TEST_F(CliWorker, OptimizeStreamsProgressAndWritesItsResults) {
  // keep_loaded_faces off: the shape is then the volume fraction of the whole beam
  const json job = beam_job({{"volume_fraction", 0.4}, {"max_iterations", 3}, {"keep_loaded_faces", false}});
  const WorkerRun r =
      run_worker(request({{"operation", "optimize"}, {"job", job}, {"part", "beam.brep"}, {"output", "out"}}));
  ASSERT_EQ(r.status, 0);
  ASSERT_TRUE(r.all_json) << "stdout holds only protocol lines";
  EXPECT_EQ(r.last(), json({{"done", true}}));
  int iterations = 0;
  bool meshed = false;
  for (const auto& l : r.lines) {
    iterations += l.contains("iteration");
    meshed = meshed || l.value("stage", "") == "mesh";
  }
  EXPECT_TRUE(meshed);
  json result;
  std::ifstream(dir_ / "out" / "result.json") >> result;
  EXPECT_EQ(static_cast<int>(result["history"].size()), iterations);
  EXPECT_GE(iterations, 1);
  using namespace topopt::io;
  const RowMatXd V = npy_real(read_npy((dir_ / "out" / "nodes.npy").string()), 3, "nodes");
  const RowMatXl T = npy_integer(read_npy((dir_ / "out" / "tets.npy").string()), 4, "tets");
  EXPECT_LT(T.maxCoeff(), V.rows());
  EXPECT_EQ(read_npy((dir_ / "out" / "densities.npy").string()).rows(), T.rows());
  EXPECT_EQ(read_npy((dir_ / "out" / "domain.npy").string()).rows(), T.rows());
  const RowMatXd P = npy_real(read_npy((dir_ / "out" / "surface_points.npy").string()), 3, "points");
  const RowMatXl F = npy_integer(read_npy((dir_ / "out" / "surface_triangles.npy").string()), 3, "triangles");
  EXPECT_LT(F.maxCoeff(), P.rows());
  const double kept = enclosed_volume(P, F) / 6000.0;
  EXPECT_NEAR(kept, 0.4, 0.05);  // the result shape keeps the volume fraction
  for (const char* name :
       {"nodes", "tets", "domain", "boundary_triangles", "boundary_faces", "boundary_nondesign_faces", "densities",
        "surface_points", "surface_triangles", "surface_tags", "displacement", "von_mises"})
    EXPECT_NE(std::find(result["arrays"].begin(), result["arrays"].end(), name), result["arrays"].end()) << name;
  // the last iterate's analysis: held at x = 0, bent down at the loaded end x = 60
  const RowMatXd U = npy_real(read_npy((dir_ / "out" / "displacement.npy").string()), 3, "displacement");
  ASSERT_EQ(U.rows(), V.rows());
  EXPECT_EQ(read_npy((dir_ / "out" / "von_mises.npy").string()).rows(), T.rows());
  double tip = 0;
  int at_tip = 0;
  for (long i = 0; i < V.rows(); ++i) {
    if (V(i, 0) < 1e-9) {
      EXPECT_EQ(U.row(i).norm(), 0.0);
    }
    if (V(i, 0) > 60 - 1e-9) tip += U(i, 2), ++at_tip;
  }
  ASSERT_GT(at_tip, 0);
  EXPECT_LT(tip / at_tip, 0.0);
  // the result files the job's output asks for by default (output.step): written and listed
  // for the workbench to keep, each an existing file of the output folder
  ASSERT_TRUE(result["files"].is_array());
  const auto& files = result["files"];
  EXPECT_NE(std::find(files.begin(), files.end(), "result.step"), files.end());
  EXPECT_NE(std::find(files.begin(), files.end(), "verification.json"), files.end());
  for (const auto& name : files) EXPECT_GT(std::filesystem::file_size(dir_ / "out" / name.get<std::string>()), 0u);
}

/// The names in result.json's "files" (an array of strings), in order.
std::vector<std::string> file_names(const json& result) {
  std::vector<std::string> names;
  for (const auto& n : result.at("files")) names.push_back(n.get<std::string>());
  return names;
}

TEST_F(CliWorker, ResultFirstWritesTheStepThenAddsTheVerificationToTheSameReport) {
  // enough iterations for one piece joining the load to the support: the verification needs it
  json job = beam_job({{"volume_fraction", 0.5}, {"max_iterations", 20}});
  job["output"] = {{"step", true}, {"verification", true}};
  const WorkerRun r = run_worker(request({{"operation", "optimize"},
                                          {"job", job},
                                          {"part", "beam.brep"},
                                          {"params", {{"result_first", 1}}},
                                          {"output", "out"}}));
  ASSERT_EQ(r.status, 0);
  ASSERT_TRUE(r.all_json);
  EXPECT_EQ(r.last(), json({{"done", true}}));
  // the line saying the result is ready comes after the STEP and before the verification
  auto stage_at = [&](const std::string& stage) {
    for (size_t i = 0; i < r.lines.size(); ++i)
      if (r.lines[i].value("stage", "") == stage) return static_cast<long>(i);
    return -1L;
  };
  ASSERT_GE(stage_at("result"), 0);
  EXPECT_LT(stage_at("step"), stage_at("result"));
  EXPECT_GT(stage_at("verification"), stage_at("result"));
  json result, report;
  std::ifstream(dir_ / "out" / "result.json") >> result;
  std::ifstream(dir_ / "out" / "verification.json") >> report;
  // every file listed once, each one there
  const std::vector<std::string> names = file_names(result);
  for (const char* name : {"result.step", "verification.json", "verification.vtu"})
    EXPECT_EQ(std::count(names.begin(), names.end(), name), 1) << name;
  for (const auto& name : names) EXPECT_GT(fs::file_size(dir_ / "out" / name), 0u) << name;
  // one report holding the STEP's part and the verification's, nothing failed
  ASSERT_TRUE(report.contains("step"));
  EXPECT_TRUE(report["step"].value("valid", false));
  EXPECT_GT(report["step"].value("volume", 0.0), 0.0);
  EXPECT_GT(report.value("compliance_as_built", 0.0), 0.0);
  EXPECT_GT(report["crisp"].value("compliance", 0.0), 0.0);
  EXPECT_EQ(report["failed"], json::object()) << report.dump(2);
}

TEST_F(CliWorker, ExtractSurfaceOfAFullCubeIsTheCube) {
  const WorkerRun r = run_worker(request(extract_request()));
  ASSERT_EQ(r.status, 0);
  EXPECT_EQ(r.last(), json({{"done", true}}));
  using namespace topopt::io;
  const RowMatXd P = npy_real(read_npy((dir_ / "out" / "surface_points.npy").string()), 3, "points");
  const RowMatXl F = npy_integer(read_npy((dir_ / "out" / "surface_triangles.npy").string()), 3, "triangles");
  EXPECT_EQ(F.rows(), 12);
  EXPECT_NEAR(enclosed_volume(P, F), 1.0, 1e-12);
}

/// Radii of the cylindrical faces of the one shape in the STEP file at `path`.
std::vector<double> cylinder_radii(const fs::path& path) {
  std::vector<double> radii;
  for (TopExp_Explorer e(topopt::brep::read_shape_file(path.string(), "result"), TopAbs_FACE); e.More(); e.Next()) {
    const BRepAdaptor_Surface a(TopoDS::Face(e.Current()));
    if (a.GetType() == GeomAbs_Cylinder) radii.push_back(a.Cylinder().Radius());
  }
  return radii;
}

TEST_F(CliWorker, ExtractSurfaceStepWithThePartHasItsBoreAsCylinders) {
  // a 40 x 20 x 10 plate with a bore of radius 4 through it, meshed by the worker as the
  // workbench's run does; all its tets full, the slider's STEP is the plate again
  const TopoDS_Shape bore = BRepPrimAPI_MakeCylinder(gp_Ax2(gp_Pnt(20, 10, -1), gp::DZ()), 4, 12).Shape();
  const TopoDS_Shape plate = BRepAlgoAPI_Cut(BRepPrimAPI_MakeBox(40, 20, 10).Shape(), bore).Shape();
  std::ofstream(dir_ / "plate.brep") << topopt::brep::write_brep_string(plate);
  json job = beam_job(json::object());
  job["mesh"]["size"] = 2.5;
  WorkerRun r = run_worker(request({{"operation", "mesh"}, {"job", job}, {"part", "plate.brep"}, {"output", "mesh"}}));
  ASSERT_EQ(r.status, 0);
  const long tets = topopt::io::read_npy((dir_ / "mesh" / "tets.npy").string()).shape[0];
  topopt::io::write_npy((dir_ / "densities.npy").string(), topopt::VecXd(topopt::VecXd::Ones(tets)));
  json extract = {{"operation", "extract_surface"},
                  {"arrays",
                   {{"nodes", "mesh/nodes.npy"},
                    {"tets", "mesh/tets.npy"},
                    {"domain", "mesh/domain.npy"},
                    {"densities", "densities.npy"}}},
                  {"params", {{"threshold", 0.5}, {"step", 1}}},
                  {"output", "facets"}};
  r = run_worker(request(extract));  // without the part: the bore stays facets
  ASSERT_EQ(r.status, 0);
  EXPECT_TRUE(cylinder_radii(dir_ / "facets" / "result.step").empty());
  extract["part"] = "plate.brep", extract["output"] = "analytic";
  r = run_worker(request(extract));
  ASSERT_EQ(r.status, 0);
  const std::vector<double> radii = cylinder_radii(dir_ / "analytic" / "result.step");
  ASSERT_FALSE(radii.empty());
  for (double radius : radii) EXPECT_NEAR(radius, 4.0, 1e-6);
}

/// The surface a worker extract_surface wrote into DIR/`out`.
topopt::result::TriSurface extracted(const fs::path& out) {
  using namespace topopt::io;
  topopt::result::TriSurface s;
  s.V = npy_real(read_npy((out / "surface_points.npy").string()), 3, "points");
  s.F = npy_integer(read_npy((out / "surface_triangles.npy").string()), 3, "triangles").cast<int>();
  return s;
}

TEST_F(CliWorker, ExtractSurfaceTakesTheJobsOverhangLiftAsTheRunDoes) {
  // issue 22: the threshold slider's shape is the run's. The beam (60 x 10 x 10, meshed at 2 by
  // the worker) full above the plane z = 2 + x/4: a wedge whose underside rises 14 deg from the
  // plate z = 0, too flat for a 45 deg overhang control
  json job = beam_job({{"controls", {{"overhang", {{"direction", {0, 0, 1}}, {"angle", 45}}}}}});
  job["mesh"]["size"] = 2.0;
  WorkerRun r = run_worker(request({{"operation", "mesh"}, {"job", job}, {"part", "beam.brep"}, {"output", "mesh"}}));
  ASSERT_EQ(r.status, 0);
  using namespace topopt;
  TetMesh mesh;  // the stored mesh, as the workbench keeps it: no boundary face numbers
  mesh.V = io::npy_real(io::read_npy((dir_ / "mesh" / "nodes.npy").string()), 3, "nodes");
  mesh.T = io::npy_integer(io::read_npy((dir_ / "mesh" / "tets.npy").string()), 4, "tets").cast<int>();
  mesh.domain = VecXi::Zero(mesh.T.rows());
  VecXd density(mesh.T.rows());
  for (long t = 0; t < mesh.T.rows(); ++t) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 4; ++k) c += mesh.V.row(mesh.T(t, k)).transpose() / 4;
    density[t] = c.z() > 2 + c.x() / 4 ? 1.0 : 1e-3;
  }
  io::write_npy((dir_ / "densities.npy").string(), density);
  json extract = {{"operation", "extract_surface"},
                  {"arrays", {{"nodes", "mesh/nodes.npy"}, {"tets", "mesh/tets.npy"}, {"densities", "densities.npy"}}},
                  {"params", {{"threshold", 0.5}}},
                  {"output", "plain"}};
  r = run_worker(request(extract));  // no job: no control, the shape as before
  ASSERT_EQ(r.status, 0);
  extract["job"] = {{"optimization", job["optimization"]}}, extract["output"] = "lifted";
  r = run_worker(request(extract));
  ASSERT_EQ(r.status, 0);
  // the run's surface: its settings as optimize takes them from the job file
  const result::SmoothParams run_settings = pipeline::surface_settings(pipeline::parse_job(job.dump(), "").optimization, mesh);
  ASSERT_TRUE(run_settings.build.active());
  const result::TriSurface run = pipeline::result_surface(mesh, density, 0.5, -1, run_settings);
  const result::TriSurface plain = extracted(dir_ / "plain"), lifted = extracted(dir_ / "lifted");
  ASSERT_EQ(lifted.F, run.F);
  EXPECT_LE((lifted.V - run.V).cwiseAbs().maxCoeff(), 1e-12);
  const double flat_plain = result::too_flat_area(plain, run_settings.build, 45);
  const double flat_lifted = result::too_flat_area(lifted, run_settings.build, 45);
  EXPECT_NEAR(flat_lifted, result::too_flat_area(run, run_settings.build, 45), 1e-9);
  EXPECT_GT(flat_plain, 100);  // the wedge's underside, about 33 x 10 mm
  EXPECT_LT(flat_lifted, flat_plain - 1);
  // without the control: the surface of the default settings, not lifted
  const result::TriSurface before = pipeline::result_surface(mesh, density, 0.5, -1, result::SmoothParams());
  ASSERT_EQ(plain.F, before.F);
  EXPECT_LE((plain.V - before.V).cwiseAbs().maxCoeff(), 1e-12);
  std::cout << "too-flat area (mm2): without the control " << flat_plain << ", with it " << flat_lifted << "\n";
  // a control standing the part on a face: the stored mesh cannot place that plate, the shape
  // comes without the lift and the answer says so
  extract["job"]["optimization"]["controls"]["overhang"]["base_face"] = "Face5", extract["output"] = "based";
  r = run_worker(request(extract));
  ASSERT_EQ(r.status, 0);
  std::ifstream answer(dir_ / "based" / "result.json");
  const json based = json::parse(answer);
  const auto says_so = [](const json& w) { return w.get<std::string>().find("without the overhang lift") != std::string::npos; };
  EXPECT_EQ(std::count_if(based["warnings"].begin(), based["warnings"].end(), says_so), 1) << based.dump();
  EXPECT_EQ(extracted(dir_ / "based").V, plain.V);
}

/// The volume a closed, outward result surface encloses (mm3).
double surface_volume(const topopt::result::TriSurface& s) {
  double v = 0;
  for (long t = 0; t < s.F.rows(); ++t) {
    const Eigen::Vector3d a = s.V.row(s.F(t, 0)), b = s.V.row(s.F(t, 1)), c = s.V.row(s.F(t, 2));
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

TEST_F(CliWorker, ExtractSurfaceCleansTheResultAsTheRunDoes) {
  // issue 19: at the run's threshold the slider's shape is the run's. The beam (60 x 10 x 10 at 2,
  // Face1 x = 0 fixed, Face2 x = 60 loaded) solid in three pieces: x < 8 on the support, x > 52
  // under the load, and a larger one between them touching neither. The run keeps the anchored
  // pieces; cleaning without anchors keeps the largest, the loose middle one.
  json job = beam_job({{"fill_voids", false}});
  job["mesh"]["size"] = 2.0;
  WorkerRun r = run_worker(request({{"operation", "mesh"}, {"job", job}, {"part", "beam.brep"}, {"output", "mesh"}}));
  ASSERT_EQ(r.status, 0);
  using namespace topopt;
  const auto npy = [&](const char* name) { return io::read_npy((dir_ / "mesh" / name).string()); };
  TetMesh mesh;  // the run's mesh, its boundary numbered by the part's faces
  mesh.V = io::npy_real(npy("nodes.npy"), 3, "nodes");
  mesh.T = io::npy_integer(npy("tets.npy"), 4, "tets").cast<int>();
  mesh.domain = VecXi::Zero(mesh.T.rows());
  mesh.F = io::npy_integer(npy("boundary_triangles.npy"), 3, "triangles").cast<int>();
  mesh.face = io::npy_integer(npy("boundary_faces.npy"), 1, "faces").col(0).cast<int>();
  VecXd density(mesh.T.rows());
  const auto write_densities = [&](const std::function<bool(const Eigen::Vector3d&)>& solid) {
    for (long t = 0; t < mesh.T.rows(); ++t) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (int k = 0; k < 4; ++k) c += mesh.V.row(mesh.T(t, k)).transpose() / 4;
      density[t] = solid(c) ? 1.0 : 1e-3;
    }
    io::write_npy((dir_ / "densities.npy").string(), density);
  };
  const pipeline::Job parsed = pipeline::parse_job(job.dump(), "");
  const auto run_shape = [&] {  // optimize_job's own call: its anchors and hygiene from the job
    return pipeline::result_surface(mesh, density, 0.5, -1, pipeline::surface_settings(parsed.optimization, mesh),
                                    nullptr, pipeline::anchor_nodes(mesh, parsed),
                                    pipeline::hygiene_params(mesh, parsed.optimization));
  };
  json extract = {{"operation", "extract_surface"},
                  {"job", job},
                  {"arrays",
                   {{"nodes", "mesh/nodes.npy"},
                    {"tets", "mesh/tets.npy"},
                    {"densities", "densities.npy"},
                    {"boundary_triangles", "mesh/boundary_triangles.npy"},
                    {"boundary_faces", "mesh/boundary_faces.npy"}}},
                  {"params", {{"threshold", 0.5}}},
                  {"output", "anchored"}};
  const auto same = [](const result::TriSurface& a, const result::TriSurface& b) {
    ASSERT_EQ(a.F, b.F);
    EXPECT_LE((a.V - b.V).cwiseAbs().maxCoeff(), 1e-12);
  };
  write_densities([](const Eigen::Vector3d& c) { return c.x() < 8 || c.x() > 52 || (c.x() > 18 && c.x() < 44); });
  ASSERT_EQ(run_worker(request(extract)).status, 0);
  const result::TriSurface run = run_shape(), anchored = extracted(dir_ / "anchored");
  same(anchored, run);
  // without the run's boundary the anchors cannot be rebuilt: the largest piece, and a warning
  extract["arrays"].erase("boundary_triangles"), extract["arrays"].erase("boundary_faces");
  extract["output"] = "unanchored";
  ASSERT_EQ(run_worker(request(extract)).status, 0);
  const json answer = json::parse(std::ifstream(dir_ / "unanchored" / "result.json"));
  const auto says_so = [](const json& w) { return w.get<std::string>().find("may differ from the run's") != std::string::npos; };
  EXPECT_EQ(std::count_if(answer["warnings"].begin(), answer["warnings"].end(), says_so), 1) << answer.dump();
  const double v_run = surface_volume(run), v_largest = surface_volume(extracted(dir_ / "unanchored"));
  std::cout << "anchored (the run's) " << v_run << " mm3, largest piece " << v_largest << " mm3\n";
  EXPECT_NEAR(v_run, 1600, 200);      // the two end pieces, 8 x 10 x 10 each
  EXPECT_NEAR(v_largest, 2600, 300);  // the middle one, 26 x 10 x 10
  // fill_voids false: a closed void in a solid beam stays, as in the run
  write_densities([](const Eigen::Vector3d& c) {
    return !(c.x() > 20 && c.x() < 40 && c.y() > 2.5 && c.y() < 7.5 && c.z() > 2.5 && c.z() < 7.5);
  });
  extract = {{"operation", "extract_surface"}, {"job", job}, {"arrays", extract["arrays"]}, {"params", {{"threshold", 0.5}}}, {"output", "voided"}};
  extract["arrays"]["boundary_triangles"] = "mesh/boundary_triangles.npy";
  extract["arrays"]["boundary_faces"] = "mesh/boundary_faces.npy";
  ASSERT_EQ(run_worker(request(extract)).status, 0);
  const result::TriSurface voided_run = run_shape(), voided = extracted(dir_ / "voided");
  same(voided, voided_run);
  const double v_void = surface_volume(voided_run);
  std::cout << "fill_voids false: " << v_void << " mm3 of the beam's 6000\n";
  EXPECT_LT(v_void, 6000 - 100);  // the void (20 x 5 x 5 between the tets' centres) is there, as the run left it
  EXPECT_GT(v_void, 6000 - 1000);
}

TEST_F(CliWorker, ErrorsAreALastLineNamingCodeAndStage) {
  WorkerRun r = run_worker(request(extract_request(8)));  // a tet naming node 8 of 8
  EXPECT_EQ(r.status, 1);
  ASSERT_TRUE(r.last().contains("error"));
  EXPECT_EQ(r.last()["error"]["code"], "InvalidParameter");
  EXPECT_EQ(r.last()["error"]["stage"], "read");
  EXPECT_EQ(r.last()["error"]["message"], "tets: row 2 holds 8, outside the node numbers 0..7");
  r = run_worker(request({{"operation", "frobnicate"}, {"output", "out"}}));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.last()["error"]["message"].get<std::string>().find("unknown operation 'frobnicate'"), std::string::npos);
  r = run_worker(dir_ / "missing.json");
  EXPECT_EQ(r.last()["error"]["code"], "Io");
  r = run_worker(request(extract_request()), "TOPOPT_FAULT=surface:explode");
  EXPECT_NE(r.last()["error"]["message"].get<std::string>().find("expected STAGE[/WORD]:abort|segv|hang"),
            std::string::npos);
}

TEST_F(CliWorker, FaultInjectionEndsOrStallsTheWorkerAtTheStage) {
  // abort and access violation: the worker dies by the signal right after reporting the stage
  for (const auto& [kind, signal] : {std::pair<std::string, int>{"abort", 6}, {"segv", 11}}) {
    const WorkerRun r = run_worker(request(extract_request()), "TOPOPT_FAULT=surface:" + kind);
    EXPECT_EQ(r.status, 128 + signal) << kind;
    ASSERT_FALSE(r.lines.empty());
    EXPECT_EQ(r.last().value("stage", ""), "surface") << kind << ": the stage's line comes out before the fault";
    EXPECT_FALSE(fs::exists(dir_ / "out" / "result.json"));
  }
  // a word narrows the stage to one message: "read/reading the densities" fires, "read/x" never does
  EXPECT_EQ(run_worker(request(extract_request()), "TOPOPT_FAULT='read/reading the:abort'").status, 134);
  EXPECT_EQ(run_worker(request(extract_request()), "TOPOPT_FAULT=read/x:abort").status, 0);
  // hang: alive and silent after reporting the stage, until killed (as the workbench does)
  const WorkerRun r = run_worker_until_stage(request(extract_request()), "TOPOPT_FAULT=surface:hang", "surface");
  EXPECT_EQ(r.status, 128 + 9) << "the worker ended by itself instead of hanging";
  ASSERT_FALSE(r.lines.empty());
  EXPECT_EQ(r.last().value("stage", ""), "surface");
}

TEST_F(CliWorker, InfoReportsTheRocker) {
  const std::string ex = std::string(TOPOPT_SHARED_DATA) + "/examples/";
  const WorkerRun r = run_worker(request({{"operation", "info"},
                                          {"part", ex + "rocker.step"},
                                          {"nondesign", ex + "rocker_nondesign.step"},
                                          {"output", "out"}}));
  ASSERT_EQ(r.status, 0);
  json result;
  std::ifstream(dir_ / "out" / "result.json") >> result;
  EXPECT_EQ(result["report"]["nondesign"]["solids"].size(), 3u);
  EXPECT_EQ(result["arrays"], json::array());
}

}  // namespace
