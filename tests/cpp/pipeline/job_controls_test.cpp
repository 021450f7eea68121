// The "controls" object of a job's optimization section (docs/optimization.md): parsed into
// simp::ControlsParams, and every mistake named by its key with what to give.
#include <gtest/gtest.h>

#include "common/error.h"
#include "pipeline/job.h"
#include "simp/controls/overhang_filter.h"

namespace topopt::pipeline {
namespace {

std::string with_controls(const std::string& controls) { return R"({"optimization": {"controls": )" + controls + "}}"; }

/// parse_job must throw InvalidParameter with every fragment in its message.
void expect_refused(const std::string& controls, const std::vector<std::string>& fragments) {
  try {
    parse_job(with_controls(controls), "/tmp");
    ADD_FAILURE() << "no error for " << controls;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidParameter) << e.what();
    for (const auto& f : fragments) EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
  }
}

TEST(JobControls, EveryControlIsParsed) {
  const Job job = parse_job(with_controls(R"({
    "symmetry_planes": [{"point": [1, 2, 3], "normal": [0, 1, -1]}, {"point": [0, 0, 0], "normal": [1, 0, 0]}],
    "cyclic": [{"point": [0, 0, 0], "axis": [0, 0, 2], "sectors": 6}],
    "patterns": [{"direction": [1, 0, 0], "pitch": 12.5, "count": 4}],
    "extrusion": [0, 0, 1],
    "tolerance": 1.5})"),
                            "/tmp");
  const simp::ControlsParams& c = job.optimization.simp.controls;
  ASSERT_EQ(c.mirrors.size(), 2u);
  EXPECT_EQ(c.mirrors[0].point, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(c.mirrors[0].normal, Eigen::Vector3d(0, 1, -1));
  ASSERT_EQ(c.cyclic.size(), 1u);
  EXPECT_EQ(c.cyclic[0].sectors, 6);
  EXPECT_EQ(c.cyclic[0].axis, Eigen::Vector3d(0, 0, 2));
  ASSERT_EQ(c.patterns.size(), 1u);
  EXPECT_EQ(c.patterns[0].pitch, 12.5);
  EXPECT_EQ(c.patterns[0].count, 4);
  EXPECT_TRUE(c.extrude);
  EXPECT_EQ(c.extrusion, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(c.tolerance, 1.5);
  EXPECT_TRUE(c.any());
  EXPECT_FALSE(parse_job("{}", "/tmp").optimization.simp.controls.any());
}

TEST(JobControls, MistakesNameTheKeyAndWhatToGive) {
  expect_refused(R"({"symetry_planes": []})",
                 {"'optimization.controls.symetry_planes'", "did you mean 'symmetry_planes'?"});
  expect_refused(R"({"symmetry_planes": {"point": [0, 0, 0]}})", {"'optimization.controls.symmetry_planes'", "list"});
  expect_refused(R"({"symmetry_planes": [{"point": [0, 0, 0], "normal": [0, 0, 0]}]})",
                 {"'optimization.controls.symmetry_planes[0].normal'", "[0, 0, 0]"});
  expect_refused(R"({"symmetry_planes": [{"normal": [0, 0, 1]}]})",
                 {"'optimization.controls.symmetry_planes[0].point'"});
  expect_refused(R"({"cyclic": [{"point": [0, 0, 0], "axis": [0, 0, 1], "sectors": 1}]})",
                 {"'optimization.controls.cyclic[0].sectors'"});
  expect_refused(R"({"patterns": [{"direction": [1, 0, 0], "pitch": 0, "count": 3}]})",
                 {"'optimization.controls.patterns[0].pitch'", "above 0"});
  expect_refused(R"({"patterns": [{"direction": [1, 0, 0], "pitch": 5, "count": 2.5}]})",
                 {"'optimization.controls.patterns[0].count'"});
  expect_refused(R"({"draw": {"direction": [0, 0, 1]}})", {"'optimization.controls.draw'"});
  expect_refused(R"({"tolerance": -1})", {"'optimization.controls.tolerance'"});
  try {
    parse_job(R"({"optimization": {"sensitivity_filter": true, "controls": {"extrusion": [0, 0, 1]}}})", "/tmp");
    ADD_FAILURE() << "sensitivity filter with controls accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'optimization.sensitivity_filter'"), std::string::npos) << e.what();
  }
}

TEST(JobControls, OverhangIsParsedAndItsMistakesNamed) {
  const Job job = parse_job(with_controls(R"({"overhang": {"direction": [1, 0, 0], "angle": 50, "base_face": "Face1",
                                                           "cell": 2, "margin": 8}})"),
                            "/tmp");
  const simp::OverhangControl& o = job.optimization.simp.controls.overhang;
  EXPECT_TRUE(o.enabled);
  EXPECT_TRUE(job.optimization.simp.controls.any());
  EXPECT_EQ(o.direction, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(o.angle, 50);
  EXPECT_EQ(o.base_face, 1);
  EXPECT_EQ(o.cell, 2);
  EXPECT_EQ(o.margin, 8);
  const simp::OverhangControl plain =
      parse_job(with_controls(R"({"overhang": {"direction": [0, 0, 1]}})"), "/tmp").optimization.simp.controls.overhang;
  EXPECT_EQ(plain.angle, 45);
  EXPECT_EQ(plain.base_face, 0);
  EXPECT_EQ(plain.margin, simp::OverhangControl{}.margin);
  // the default margin fits a steep angle: 80 + 5 = 85, not refused
  const simp::OverhangControl steep =
      parse_job(with_controls(R"({"overhang": {"direction": [0, 0, 1], "angle": 80}})"), "/tmp")
          .optimization.simp.controls.overhang;
  EXPECT_EQ(steep.margin, 5);
  expect_refused(R"({"overhang": {"direction": [0, 0, 1], "angle": 80, "margin": 10}})",
                 {"'optimization.controls.overhang.margin'", "angle + margin <= 85"});
  // one place decides the ranges: the parser reports the filter's own words under the key's path
  simp::OverhangControl wide;
  wide.margin = 25;
  const simp::OverhangProblem problem = simp::overhang_problem(wide);
  EXPECT_EQ(problem.key, "margin");
  expect_refused(R"({"overhang": {"direction": [0, 0, 1], "margin": 25}})",
                 {"'optimization.controls.overhang.margin'", problem.what});
  wide = simp::OverhangControl{};
  wide.angle = 85;
  wide.margin = 0;
  EXPECT_EQ(simp::overhang_problem(wide).key, "angle");
  expect_refused(R"({"overhang": {"direction": [0, 0, 1], "angle": 85}})",
                 {"'optimization.controls.overhang.angle'", simp::overhang_problem(wide).what});
  EXPECT_TRUE(simp::overhang_problem(simp::OverhangControl{}).key.empty());
  EXPECT_FALSE(parse_job("{}", "/tmp").optimization.simp.controls.overhang.enabled);
  expect_refused(R"({"overhang": {"angle": 45}})", {"'optimization.controls.overhang.direction'"});
  expect_refused(R"({"overhang": {"direction": [0, 0, 0]}})",
                 {"'optimization.controls.overhang.direction'", "[0, 0, 0]"});
  expect_refused(R"({"overhang": {"direction": [0, 0, 1], "angle": 5}})",
                 {"'optimization.controls.overhang.angle'", "[10, 80] degrees"});
  expect_refused(R"({"overhang": {"direction": [0, 0, 1], "base_face": 3}})",
                 {"'optimization.controls.overhang.base_face'", "\"Face5\""});
  expect_refused(R"({"overhang": {"direction": [0, 0, 1], "base_face": "NonDesign:Face2"}})",
                 {"'optimization.controls.overhang.base_face'", "not of a non-design solid"});
  expect_refused(R"({"overhang": {"direction": [0, 0, 1], "xi0": 1}})", {"'optimization.controls.overhang.xi0'"});
  expect_refused(R"({"overhang": {"direction": [0, 0, 1], "exponent": 2}})",
                 {"'optimization.controls.overhang.exponent'"});
  expect_refused(R"({"overhang": {"direction": [0, 0, 1], "angel": 40}})",
                 {"'optimization.controls.overhang.angel'", "did you mean 'angle'?"});
  const Job far = parse_job(with_controls(R"({"overhang": {"direction": [0, 0, 1], "base_face": "Face9"}})"), "/tmp");
  try {
    check_faces(far, 6, -1);
    ADD_FAILURE() << "Face9 of a 6-face part accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::FaceNotFound);
    EXPECT_NE(
        std::string(e.what()).find("optimization.controls.overhang.base_face names Face9, but the part has only 6"),
        std::string::npos)
        << e.what();
  }
}

TEST(JobControls, MemberSizesSetTheRadiusAndTheUpdate) {
  const Job job = parse_job(with_controls(R"({"min_member_size": 4, "max_member_size": 12})"), "/tmp");
  const simp::SimpParams& p = job.optimization.simp;
  EXPECT_EQ(p.controls.member.min_size, 4);
  EXPECT_EQ(p.controls.member.max_size, 12);
  EXPECT_TRUE(p.controls.any());
  // the radius the size asks for (Gaussian filter, thresholds 0.5 ± 0.25), and MMA for the maximum size
  EXPECT_NEAR(p.filter.radius,
              simp::robust_filter_radius(4, simp::FilterKind::Gaussian, simp::robust_thresholds(0.5, 0.25)), 1e-12);
  EXPECT_GT(p.filter.radius, 4);
  EXPECT_EQ(p.update, simp::UpdateKind::MMA);
  expect_refused(R"({"min_member_size": -2})", {"'optimization.controls.min_member_size'", "positive size in mm"});
  expect_refused(R"({"min_member_size": 6, "max_member_size": 5})",
                 {"'optimization.controls.max_member_size'", "larger than min_member_size"});
  expect_refused(R"({"max_member_size": 5, "max_member_solid": 1.2})", {"'optimization.controls.max_member_solid'"});
  for (const std::string& other :
       {std::string(R"("filter_radius": 3)"), std::string(R"("heaviside": false)"), std::string(R"("update": "oc")")}) {
    const std::string key = other.substr(1, other.find('"', 1) - 1);
    const std::string controls = key == "update" ? R"({"max_member_size": 8})" : R"({"min_member_size": 4})";
    try {
      parse_job(R"({"optimization": {)" + other + R"(, "controls": )" + controls + "}}", "/tmp");
      ADD_FAILURE() << "no error for " << other;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("'optimization." + key + "'"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("member_size"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace topopt::pipeline
