// The job model: the documented format parsed into typed settings, and every mistake a user
// can make in a job file stopped before any work with a message that says what to fix.
#include "pipeline/job.h"

#include <gtest/gtest.h>

#include <functional>

#include "common/error.h"
#include "pipeline/result_files.h"

namespace topopt::pipeline {
namespace {

ErrorCode code_of(const std::string& text) {
  try {
    parse_job(text, "/tmp");
  } catch (const Error& e) {
    return e.code();
  }
  return ErrorCode::Internal;  // no error: tests expect one
}

/// parse_job(text) must throw `code` with every fragment in its message.
void expect_message(const std::string& text, ErrorCode code, const std::vector<std::string>& fragments) {
  try {
    parse_job(text, "/tmp");
    ADD_FAILURE() << "no error for " << text;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    for (const auto& f : fragments) EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
  }
}

TEST(Job, ParsesTheDocumentedFormat) {
  Job j = parse_job(R"({"part": "p.step", "nondesign": "/abs/nd.step", "mesh": {"size": 2.5, "wall_layers": 2},
    "material": {"E": 70000, "nu": 0.33},
    "supports": [{"type": "fixed", "faces": ["Face3", "NonDesign:Face2"]},
                 {"type": "components", "faces": ["Face5"], "fix": ["x", "z"]},
                 {"type": "symmetry", "faces": ["Face2"]}],
    "load_cases": [{"name": "pull", "weight": 2, "loads": [
        {"type": "force", "faces": ["Face7"], "vector": [0, -1000, 0]},
        {"type": "pressure", "faces": ["Face8"], "value": 1.5},
        {"type": "gravity", "vector": [0, 0, -9810]}]}],
    "optimization": {"volume_fraction": 0.3}})",
                    "/data/jobs");
  EXPECT_EQ(j.part, "/data/jobs/p.step");
  EXPECT_EQ(j.nondesign, "/abs/nd.step");
  EXPECT_EQ(j.mesh.size, 2.5);
  EXPECT_EQ(j.mesh.wall_layers, 2);
  EXPECT_EQ(j.mesh.mesher, Mesher::Auto);
  EXPECT_EQ(j.material.young, 70000);
  ASSERT_EQ(j.supports.size(), 3u);
  EXPECT_EQ(j.supports[0].faces, std::vector<int>{3});
  EXPECT_EQ(j.supports[0].nd_faces, std::vector<int>{2});
  EXPECT_TRUE(j.supports[1].fix[0] && !j.supports[1].fix[1] && j.supports[1].fix[2]);
  EXPECT_EQ(j.supports[2].kind, fem::SupportSpec::Kind::Symmetry);
  ASSERT_EQ(j.load_cases.size(), 1u);
  EXPECT_EQ(j.load_cases[0].weight, 2);
  EXPECT_EQ(j.load_cases[0].items.size(), 3u);
  EXPECT_EQ(j.load_cases[0].items[1].value, 1.5);
  EXPECT_EQ(j.optimization.simp.volume_fraction, 0.3);
  EXPECT_EQ(j.output.directory, "/data/jobs/out");
}

TEST(Job, OptimizationSectionIsTypedOnce) {
  Job j = parse_job(R"({"optimization": {"volume_fraction": 0.25, "penalty": 3.5, "filter": "cone",
    "filter_radius": 4, "heaviside": {"beta_max": 16, "every": 10}, "update": "mma", "solver": "direct",
    "solver_tolerance": 1e-6, "move": 0.1, "max_iterations": 40.0, "threshold": 0.4,
    "smoothing_iterations": 5}, "mesh": {"mesher": "gmsh", "file": "m.msh"}})",
                    "/d");
  const simp::SimpParams& p = j.optimization.simp;
  EXPECT_EQ(p.volume_fraction, 0.25);
  EXPECT_EQ(p.law.penalty, 3.5);
  EXPECT_EQ(p.filter.kind, simp::FilterKind::Cone);
  EXPECT_EQ(p.filter.radius, 4);
  EXPECT_TRUE(p.projection.enabled);
  EXPECT_EQ(p.projection.beta_max, 16);
  EXPECT_EQ(p.projection.max_iterations_per_beta, 10);
  EXPECT_EQ(p.update, simp::UpdateKind::MMA);
  EXPECT_EQ(p.solver.kind, fem::SolverKind::Direct);
  EXPECT_EQ(p.solver.tolerance, 1e-6);
  EXPECT_EQ(p.max_iterations, 40);  // a whole number written as 40.0
  EXPECT_EQ(j.optimization.threshold, 0.4);
  EXPECT_EQ(j.optimization.smooth.iterations, 5);
  EXPECT_EQ(j.mesh.mesher, Mesher::Gmsh);
  EXPECT_EQ(j.mesh.file, "/d/m.msh");
}

TEST(Job, TheWorkbenchsJobParses) {
  // what Mod/topopt/app/job.py's study_to_job writes
  Job j = parse_job(R"({"mesh": {"mesher": "auto", "size": 3.0, "wall_layers": 2},
    "material": {"E": 210000.0, "nu": 0.3, "density": 7.85e-09},
    "supports": [{"type": "fixed", "faces": ["Face9"]}],
    "load_cases": [{"name": "loads", "weight": 1.0, "loads": [
      {"type": "force", "faces": ["NonDesign:Face3"], "vector": [0.0, -1000.0, 0.0]}]}],
    "optimization": {"volume_fraction": 0.35, "penalty": 3.0, "filter": "gaussian", "update": "oc",
                     "max_iterations": 100, "filter_radius": 2.5, "threshold": 0.5}})",
                    "");
  EXPECT_EQ(j.optimization.simp.max_iterations, 100);
  EXPECT_EQ(j.load_cases[0].items[0].nd_faces, std::vector<int>{3});
}

TEST(Job, BadInputIsNamed) {
  EXPECT_EQ(code_of("{"), ErrorCode::Io);
  EXPECT_EQ(code_of(R"({"mesh": {"size": -1}})"), ErrorCode::InvalidParameter);
  EXPECT_EQ(code_of(R"({"mesh": {"wall_layers": 1.5}})"), ErrorCode::InvalidParameter);
  EXPECT_EQ(code_of(R"({"mesh": {"wall_layers": 9}})"), ErrorCode::InvalidParameter);
  EXPECT_EQ(code_of(R"({"part": "p", "supports": [{"faces": ["Fase3"]}]})"), ErrorCode::FaceNotFound);
  EXPECT_EQ(code_of(R"({"part": "p", "supports": [{"type": "glued", "faces": ["Face3"]}]})"),
            ErrorCode::InvalidParameter);
  EXPECT_EQ(code_of(R"({"part": "p", "material": {"nu": 0.5}})"), ErrorCode::InvalidParameter);
  EXPECT_EQ(code_of(R"({"part": "p", "load_cases": [{"loads": [{"faces": ["Face1"], "vector": [1, 2]}]}]})"),
            ErrorCode::InvalidParameter);
  Job j = parse_job(R"({"part": "p", "supports": [{"faces": ["Face12"]}]})", "");
  try {
    check_faces(j, 10, -1);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::FaceNotFound);
    EXPECT_NE(std::string(e.what()).find("only 10 faces"), std::string::npos) << e.what();
  }
}

TEST(Job, UnknownKeysNameTheKeyAndTheNearestKnownOne) {
  expect_message(R"({"optimization": {"volume_fracton": 0.2}})", ErrorCode::InvalidParameter,
                 {"unknown key 'optimization.volume_fracton': did you mean 'volume_fraction'?"});
  expect_message(R"({"suports": [{"faces": ["Face1"]}]})", ErrorCode::InvalidParameter,
                 {"unknown key 'suports': did you mean 'supports'?"});
  expect_message(R"({"load_cases": [{"loads": [{"faces": ["Face1"], "vectr": [0, 0, 1]}]}]})",
                 ErrorCode::InvalidParameter, {"'load_cases[0].loads[0].vectr'", "did you mean 'vector'?"});
  expect_message(R"({"mesh": {"colour": "red"}})", ErrorCode::InvalidParameter,
                 {"unknown key 'mesh.colour'", "'size'", "'min_size'", "'mesher'"});
  expect_message(R"({"optimization": {"heaviside": {"beta": 8}}})", ErrorCode::InvalidParameter,
                 {"'optimization.heaviside.beta'", "did you mean 'beta_max'?"});
  // a value out of a list of words is answered the same way
  expect_message(R"({"optimization": {"update": "occ"}})", ErrorCode::InvalidParameter,
                 {"'optimization.update'", "did you mean 'oc'?"});
  // keys that belong to another type of support or load
  expect_message(R"({"supports": [{"type": "fixed", "faces": ["Face1"], "fix": ["x"]}]})", ErrorCode::InvalidParameter,
                 {"'supports[0].fix'", "components"});
  expect_message(R"({"load_cases": [{"loads": [{"type": "gravity", "faces": ["Face1"], "vector": [0, 0, -9810]}]}]})",
                 ErrorCode::InvalidParameter, {"'load_cases[0].loads[0].faces'", "whole part"});
}

TEST(Job, CrispDefaultsAndTheirKeys) {
  // projection on and voids filled unless the job says otherwise
  const Job plain = parse_job(R"({"optimization": {}})", "/d");
  EXPECT_TRUE(plain.optimization.simp.projection.enabled);
  EXPECT_TRUE(plain.optimization.hygiene.fill_voids);
  const Job off = parse_job(R"({"optimization": {"heaviside": false, "fill_voids": false}})", "/d");
  EXPECT_FALSE(off.optimization.simp.projection.enabled);
  EXPECT_FALSE(off.optimization.hygiene.fill_voids);
  const Job set = parse_job(
      R"({"optimization": {"heaviside": {"beta_start": 2, "beta_max": 64, "factor": 1.5, "every": 25, "settle": 1e-3}}})",
      "/d");
  const simp::ProjectionParams& p = set.optimization.simp.projection;
  EXPECT_TRUE(p.enabled);
  EXPECT_EQ(p.beta_start, 2);
  EXPECT_EQ(p.beta_max, 64);
  EXPECT_EQ(p.beta_factor, 1.5);
  EXPECT_EQ(p.max_iterations_per_beta, 25);
  EXPECT_EQ(p.settle_tolerance, 1e-3);
  expect_message(R"({"optimization": {"heaviside": {"factor": 1}}})", ErrorCode::InvalidParameter,
                 {"'optimization.heaviside.factor'", "(1, 10]"});
  expect_message(R"({"optimization": {"heaviside": {"beta_start": 64, "beta_max": 32}}})", ErrorCode::InvalidParameter,
                 {"'optimization.heaviside.beta_max'", "[beta_start, 1000]"});
  expect_message(R"({"optimization": {"heaviside": {"settle": 0}}})", ErrorCode::InvalidParameter,
                 {"'optimization.heaviside.settle'", "(0, 1)"});
  expect_message(R"({"optimization": {"fill_voids": "no"}})", ErrorCode::InvalidParameter,
                 {"'optimization.fill_voids' must be true or false"});
}

TEST(Job, DuplicatedKeysAreErrors) {
  // the second "optimization" would have replaced the whole first section
  expect_message(R"({"optimization": {"volume_fraction": 0.2}, "optimization": {"penalty": 3}})",
                 ErrorCode::InvalidParameter, {"'optimization' appears twice"});
  expect_message(R"({"load_cases": [{"loads": [{"faces": ["Face1"], "vector": [0, 0, 1], "vector": [1, 0, 0]}]}]})",
                 ErrorCode::InvalidParameter, {"'vector' appears twice in 'load_cases[0].loads[0]'"});
}

TEST(Job, ResultResolutionIsOneOrTwoAndNamedWhenWrong) {
  EXPECT_EQ(parse_job(R"({"result": {"resolution": 2}})", "/d").optimization.smooth.resolution, 2);
  EXPECT_EQ(parse_job(R"({"result": {"resolution": 1}})", "/d").optimization.smooth.resolution, 1);
  expect_message(R"({"result": {"resolution": 3}})", ErrorCode::InvalidParameter,
                 {"'result.resolution' must be a whole number from 1 to 2, not 3"});
  expect_message(R"({"result": {"resolution": 1.5}})", ErrorCode::InvalidParameter, {"'result.resolution'"});
  expect_message(R"({"result": {"resolutoin": 2}})", ErrorCode::InvalidParameter, {"resolutoin"});
}

TEST(Job, JoiningNonDesignSolidsIsOnUnlessTheResultSaysFalse) {
  EXPECT_TRUE(parse_job(R"({})", "/d").optimization.hygiene.join_non_design);
  EXPECT_TRUE(parse_job(R"({"result": {"join_non_design": true}})", "/d").optimization.hygiene.join_non_design);
  EXPECT_FALSE(parse_job(R"({"result": {"join_non_design": false}})", "/d").optimization.hygiene.join_non_design);
  expect_message(R"({"result": {"join_non_design": 1}})", ErrorCode::InvalidParameter, {"'result.join_non_design'"});
}

TEST(Job, TheStepTriangleBudgetReachesTheExport) {
  // absent: the export's own budget; set: that number; 0: no budget
  const long own = result::StepExportParams{}.max_triangles;
  EXPECT_EQ(pipeline::step_params(parse_job(R"({"output": {}})", "/d")).max_triangles, own);
  EXPECT_EQ(pipeline::step_params(parse_job(R"({"output": {"step_max_triangles": 250000}})", "/d")).max_triangles,
            250000);
  EXPECT_EQ(pipeline::step_params(parse_job(R"({"output": {"step_max_triangles": 0}})", "/d")).max_triangles, 0);
  expect_message(R"({"output": {"step_max_triangles": -1}})", ErrorCode::InvalidParameter,
                 {"'output.step_max_triangles' must be a whole number from 0"});
}

TEST(Job, IntegersAreWholeAndNumbersFinite) {
  expect_message(R"({"optimization": {"max_iterations": 2.5}})", ErrorCode::InvalidParameter,
                 {"'optimization.max_iterations' must be a whole number from 1 to 10000, not 2.5"});
  expect_message(R"({"optimization": {"smoothing_iterations": 1.5}})", ErrorCode::InvalidParameter,
                 {"'optimization.smoothing_iterations'", "whole number"});
  expect_message(R"({"optimization": {"heaviside": {"every": 0.5}}})", ErrorCode::InvalidParameter,
                 {"'optimization.heaviside.every'", "whole number"});
  expect_message(R"({"mesh": {"size": 1e400}})", ErrorCode::Io, {"number too large", "1e400"});
  expect_message(R"({"optimization": {"move": "0.2"}})", ErrorCode::InvalidParameter,
                 {"'optimization.move' must be a number"});
  expect_message(R"({"output": {"vtu": "yes"}})", ErrorCode::InvalidParameter, {"'output.vtu' must be true or false"});
  expect_message(R"({"part": 3})", ErrorCode::InvalidParameter, {"'part' must be a string"});
}

TEST(Job, EveryRangeIsCheckedWithWhatToGive) {
  expect_message(R"({"mesh": {"size": 1, "min_size": 2}})", ErrorCode::InvalidParameter,
                 {"'mesh.min_size'", "larger than 'mesh.size'"});
  expect_message(R"({"optimization": {"volume_fraction": 1.2}})", ErrorCode::InvalidParameter,
                 {"'optimization.volume_fraction' must lie strictly between 0 and 1"});
  expect_message(R"({"optimization": {"threshold": 0}})", ErrorCode::InvalidParameter, {"'optimization.threshold'"});
  expect_message(R"({"optimization": {"tol_change": -1}})", ErrorCode::InvalidParameter, {"'optimization.tol_change'"});
  expect_message(R"({"load_cases": [{"weight": 0, "loads": [{"faces": ["Face1"], "vector": [0, 0, 1]}]}]})",
                 ErrorCode::InvalidParameter, {"'load_cases[0].weight' must be positive"});
  expect_message(R"({"load_cases": [{"name": "a", "loads": [{"faces": ["Face1"], "vector": [0, 0, 1]}]},
                                    {"name": "a", "loads": [{"faces": ["Face1"], "vector": [0, 0, 2]}]}]})",
                 ErrorCode::InvalidParameter, {"'load_cases[1].name' repeats the name \"a\""});
  expect_message(R"({"load_cases": [{"loads": [{"type": "pressure", "faces": ["Face1"]}]}]})",
                 ErrorCode::InvalidParameter, {"'load_cases[0].loads[0].value'", "MPa"});
}

TEST(Job, ObjectivesAndLimitsAreTypedAndChecked) {
  const Job j = parse_job(R"({"optimization": {"objective": "mass", "compliance_limit": 250,
      "displacement_limits": [{"faces": ["Face7", "NonDesign:Face2"], "direction": [0, 0, -2], "limit": 0.5}]}})",
                          "/tmp");
  const simp::ResponseParams& r = j.optimization.simp.responses;
  EXPECT_EQ(r.objective, simp::Objective::Mass);
  EXPECT_EQ(r.compliance_limit, 250);
  EXPECT_EQ(j.optimization.simp.update, simp::UpdateKind::MMA);  // the default with a mass objective
  ASSERT_EQ(j.optimization.displacement_limits.size(), 1u);
  const DisplacementSpec& d = j.optimization.displacement_limits[0];
  EXPECT_EQ(d.unit.faces, std::vector<int>{7});
  EXPECT_EQ(d.unit.nd_faces, std::vector<int>{2});
  EXPECT_DOUBLE_EQ(d.unit.vector[2], -1);  // normalised: a force of 1 N
  EXPECT_EQ(d.limit, 0.5);
  // the default stays compliance under the volume fraction, with OC
  const Job plain = parse_job(R"({"optimization": {}})", "/tmp");
  EXPECT_EQ(plain.optimization.simp.responses.objective, simp::Objective::Compliance);
  EXPECT_EQ(plain.optimization.simp.update, simp::UpdateKind::OC);
  expect_message(R"({"optimization": {"objective": "mass"}})", ErrorCode::InvalidParameter,
                 {"'optimization.objective'", "compliance_limit", "displacement_limits"});
  const Job fr = parse_job(R"({"optimization": {"objective": "frequency", "stress_limit": 200, "stress_pnorm": 12,
      "stress_relaxation": 0.6}})",
                           "/tmp");
  EXPECT_EQ(fr.optimization.simp.responses.objective, simp::Objective::Frequency);
  EXPECT_EQ(fr.optimization.simp.responses.stress_limit, 200);
  EXPECT_EQ(fr.optimization.simp.responses.stress_pnorm, 12);
  EXPECT_EQ(fr.optimization.simp.responses.stress_relaxation, 0.6);
  EXPECT_EQ(fr.optimization.simp.update, simp::UpdateKind::MMA);
  expect_message(R"({"optimization": {"stress_limit": 0}})", ErrorCode::InvalidParameter,
                 {"'optimization.stress_limit' must be a positive von Mises stress in MPa"});
  expect_message(R"({"optimization": {"stress_pnorm": 1}})", ErrorCode::InvalidParameter,
                 {"'optimization.stress_pnorm' must lie in [2, 64]"});
  expect_message(R"({"optimization": {"stress_relaxation": 0}})", ErrorCode::InvalidParameter,
                 {"'optimization.stress_relaxation' must lie in (0, 1]"});
  expect_message(R"({"optimization": {"objective": "weight"}})", ErrorCode::InvalidParameter,
                 {"'optimization.objective'"});
  expect_message(R"({"optimization": {"compliance_limit": 10}})", ErrorCode::InvalidParameter,
                 {"'optimization.compliance_limit'", "\"objective\": \"mass\""});
  expect_message(R"({"optimization": {"objective": "mass", "compliance_limit": -1}})", ErrorCode::InvalidParameter,
                 {"'optimization.compliance_limit' must be a positive compliance"});
  expect_message(R"({"optimization": {"objective": "mass", "compliance_limit": 1, "update": "oc"}})",
                 ErrorCode::InvalidParameter, {"'optimization.update' must be \"mma\""});
  expect_message(R"({"optimization": {"displacement_limits": [{"faces": ["Face1"], "direction": [0, 0, 0],
                 "limit": 1}]}})",
                 ErrorCode::InvalidParameter, {"'optimization.displacement_limits[0].direction' must not be zero"});
  expect_message(R"({"optimization": {"displacement_limits": [{"faces": ["Face1"], "direction": [0, 0, 1]}]}})",
                 ErrorCode::InvalidParameter, {"'optimization.displacement_limits[0].limit' is missing"});
  expect_message(R"({"optimization": {"displacement_limits": [{"faces": [], "direction": [0, 0, 1], "limit": 1}]}})",
                 ErrorCode::InvalidParameter, {"'optimization.displacement_limits[0].faces'"});
  expect_message(R"({"optimization": {"displacement_limits": [{"face": ["Face1"]}]}})", ErrorCode::InvalidParameter,
                 {"'optimization.displacement_limits[0].face'", "faces"});
}

TEST(Job, AForceNoPartCanCarryIsRefusedBeforeTheSolver) {
  // 1e308 N would overflow the solver's products and come back as "the structure is not held"
  expect_message(R"({"load_cases": [{"loads": [{"faces": ["Face1"], "vector": [0, 0, 1e308]}]}]})",
                 ErrorCode::InvalidParameter, {"'load_cases[0].loads[0].vector' has a magnitude of 1e+308 N"});
  expect_message(R"({"load_cases": [{"loads": [{"type": "pressure", "faces": ["Face1"], "value": -1e300}]}]})",
                 ErrorCode::InvalidParameter, {"'load_cases[0].loads[0].value'", "MPa"});
}

TEST(Job, SyntaxErrorsSayWhere) {
  expect_message("{\n  \"mesh\": {\"size\": 2,}\n}", ErrorCode::Io, {"job file is not valid JSON at line 2"});
  expect_message("{\"optimization\": {\"volume_fraction\": NaN}}", ErrorCode::Io, {"not valid JSON at line 1"});
}

TEST(Job, NeedsSupportsAndLoadsToRun) {
  const Job none = parse_job("{}", "/d");
  try {
    require_supports_and_loads(none);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NoSupport);
    EXPECT_NE(std::string(e.what()).find("add \"supports\""), std::string::npos) << e.what();
  }
  const Job no_loads = parse_job(R"({"supports": [{"faces": ["Face1"]}]})", "/d");
  EXPECT_THROW(require_supports_and_loads(no_loads), Error);
}

}  // namespace
}  // namespace topopt::pipeline
