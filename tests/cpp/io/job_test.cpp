// Job files: parsing, face names, and messages that say what to fix.
#include "io/job.h"

#include <gtest/gtest.h>

#include "common/error.h"

namespace topopt::io {
namespace {

ErrorCode code_of(const std::string& text) {
  try {
    parse_job(text, "/tmp");
  } catch (const Error& e) {
    return e.code();
  }
  return ErrorCode::Internal;  // no error: tests expect one
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
  EXPECT_EQ(j.mesh_size, 2.5);
  EXPECT_EQ(j.mesh_wall_layers, 2);
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
  EXPECT_EQ(j.raw["optimization"]["volume_fraction"], 0.3);
  EXPECT_EQ(j.output_dir, "/data/jobs/out");
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

}  // namespace
}  // namespace topopt::io
