// Mesh settings decided once: the defaults, the clamp of a size larger than the part, the
// element budget, the checks, what the meshers receive, and a mesh's trip through bytes.
#include "pipeline/mesh_settings.h"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.h"
#include "mesh/core/structured_box.h"
#include "pipeline/mesh_bytes.h"
#include "testing/expect_error.h"

namespace topopt::pipeline {
namespace {

using topopt::testing::expect_error;

TEST(MeshSettings, DefaultsComeFromThePart) {
  const MeshSizes s = resolve_mesh_sizes({}, 100, 1000);
  EXPECT_DOUBLE_EQ(s.size, 2.0);      // diagonal / 50
  EXPECT_DOUBLE_EQ(s.min_size, 0.2);  // size / 10
  EXPECT_DOUBLE_EQ(s.growth, 0.3);
  EXPECT_NEAR(s.estimated_tets, 6.0 * 1000 / 8 * 1.2, 1e-9);
  MeshSettings given;
  given.size = 5, given.min_size = 1;
  const MeshSizes g = resolve_mesh_sizes(given, 100, 1000);
  EXPECT_EQ(g.size, 5);
  EXPECT_EQ(g.min_size, 1);
}

TEST(MeshSettings, ASizeLargerThanThePartIsClampedWithAWarning) {
  // a user typing 1e6 for a 138 mm part: the surface front would run away at such a size
  std::vector<std::string> warnings;
  Progress p;
  p.log = [&](LogLevel level, const std::string& m) {
    if (level == LogLevel::Warning) warnings.push_back(m);
  };
  MeshSettings s;
  s.size = 1e6;
  s.min_size = 5e5;
  const MeshSizes r = resolve_mesh_sizes(s, 138.6, 27000, p);
  EXPECT_DOUBLE_EQ(r.size, 138.6);
  EXPECT_DOUBLE_EQ(r.min_size, 13.86);  // follows the clamped size
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("larger than the part"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("meshing at 138.6 mm"), std::string::npos) << warnings[0];
}

TEST(MeshSettings, ASizeAskingForTooManyElementsIsRefusedWithASizeToUse) {
  MeshSettings s;
  s.size = 1e-4;
  expect_error([&] { resolve_mesh_sizes(s, 138.6, 27159); }, ErrorCode::TooLarge, {"use a mesh size of at least"});
  // the size it names is accepted
  try {
    resolve_mesh_sizes(s, 138.6, 27159);
  } catch (const Error& e) {
    const std::string m = e.what();
    const size_t at = m.find("at least ") + 9;
    s.size = std::stod(m.substr(at)) * 1.001;
    EXPECT_NO_THROW(resolve_mesh_sizes(s, 138.6, 27159));
  }
}

TEST(MeshSettings, TheElementBudgetFollowsTheMachinesMemory) {
  // a 100 mm cube: about 7.2e6 / h³ tets estimated
  MeshSettings s;
  s.size = 1.0;  // 7.2 M tets estimated
  const double gb = 1e9;
  EXPECT_NO_THROW(resolve_mesh_sizes(s, 173.2, 1e6, {}, 24 * gb));  // 16 M take 24 GB
  const std::string m =
      expect_error([&] { resolve_mesh_sizes(s, 173.2, 1e6, {}, 8 * gb); }, ErrorCode::TooLarge,
                   {"more than this machine's memory (8 GB) can optimise", "use a mesh size of at least"});
  s.size = std::stod(m.substr(m.find("at least ") + 9)) * 1.001;  // the size it names fits in 8 GB
  const MeshSizes fits = resolve_mesh_sizes(s, 173.2, 1e6, {}, 8 * gb);
  EXPECT_LE(fits.estimated_tets, 8 * gb / MeshDefaults::kBytesPerTet);
  EXPECT_GT(fits.estimated_tets, 0.99 * 8 * gb / MeshDefaults::kBytesPerTet);
  // memory unknown: the fixed budget
  s.size = std::cbrt(7.2e6 / (1.001 * MeshDefaults::kMaxTetsUnknownMemory));
  expect_error([&] { resolve_mesh_sizes(s, 173.2, 1e6, {}, 0); }, ErrorCode::TooLarge, {"use a mesh size of at least"});
  s.size *= 1.002;
  EXPECT_NO_THROW(resolve_mesh_sizes(s, 173.2, 1e6, {}, 0));
}

TEST(MeshSettings, ChecksSayWhatToChange) {
  MeshSettings s;
  s.size = 1, s.min_size = 2;
  expect_error([&] { check_mesh_settings(s, "--size", "--min-size"); }, ErrorCode::InvalidParameter,
               {"--min-size (2 mm) is larger than --size (1 mm)"});
  s = {};
  s.size = -1;
  expect_error([&] { check_mesh_settings(s); }, ErrorCode::InvalidParameter, {"the mesh size must be a positive"});
  s = {};
  s.size = NAN;
  expect_error([&] { check_mesh_settings(s); }, ErrorCode::InvalidParameter, {"the mesh size"});
  s = {};
  s.gmsh_volume_by_front = true;
  expect_error([&] { check_mesh_settings(s); }, ErrorCode::InvalidParameter, {"--mesher gmsh"});
  s = {};
  s.min_size = 5;  // above the automatic size of a 100 mm part (2 mm)
  expect_error([&] { resolve_mesh_sizes(s, 100, 1000); }, ErrorCode::InvalidParameter,
               {"larger than the automatic mesh size"});
  expect_error([] { mesher_from_name("netgen"); }, ErrorCode::InvalidParameter, {"\"native\""});
  EXPECT_EQ(mesher_from_name("gmsh"), Mesher::Gmsh);
}

TEST(MeshSettings, TheMeshersReceiveEveryDecision) {
  MeshSettings s;
  s.wall_layers = 2;
  s.gmsh_volume_by_front = true;
  const MeshSizes sizes = resolve_mesh_sizes(s, 100, 1000, {}, 3e9);  // a 3 GB machine: 2e6 estimated tets
  const mesh::NativeMeshParams n = native_mesh_params(s, sizes);
  EXPECT_EQ(n.surface.size, 2.0);
  EXPECT_EQ(n.surface.min_size, 0.2);
  EXPECT_DOUBLE_EQ(n.surface.gradation, 1.3);
  EXPECT_DOUBLE_EQ(n.surface.max_angle, 2 * 3.14159265358979323846 / 40);
  EXPECT_EQ(n.surface.wall_layers, 2);
  EXPECT_EQ(n.volume.max_tets, 4'000'000);  // the fills stop at twice the budget
  const mesh::FragmentMeshParams g = gmsh_mesh_params(s, sizes);
  EXPECT_EQ(g.size, 2.0);
  EXPECT_EQ(g.min_size, 0.2);  // the same smallest size on both paths
  EXPECT_EQ(g.elements_per_turn, 40);
  EXPECT_TRUE(g.volume_by_front);
  EXPECT_DOUBLE_EQ(gmsh_time_budget(s, sizes), 120 + sizes.estimated_tets / 2000);
  s.gmsh_seconds = 7;
  EXPECT_EQ(gmsh_time_budget(s, sizes), 7);
  EXPECT_DOUBLE_EQ(native_time_budget(s, sizes), 300 + sizes.estimated_tets / 250);
  s.native_seconds = 9;
  EXPECT_EQ(native_time_budget(s, sizes), 9);
}

TEST(MeshBytes, AMeshGoesThroughBytesUnchanged) {
  mesh::StructuredBoxParams p;
  p.size = {4, 2, 2};
  p.cells = {4, 2, 2};
  p.nondesign = {{0, 0, 0, 1, 2, 2}};
  const TetMesh m = mesh::structured_box_mesh(p);
  const std::string bytes = mesh_to_bytes(m);
  const TetMesh r = mesh_from_bytes(bytes);
  EXPECT_EQ(r.V, m.V);
  EXPECT_EQ(r.T, m.T);
  EXPECT_EQ(r.domain, m.domain);
  EXPECT_EQ(r.F, m.F);
  EXPECT_EQ(r.face, m.face);
  EXPECT_EQ(r.nd_face, m.nd_face);
  expect_error([&] { mesh_from_bytes(bytes.substr(0, bytes.size() - 3)); }, ErrorCode::Internal, {"cut short"});
  expect_error([] { mesh_from_bytes("not a mesh at all"); }, ErrorCode::Internal, {"not a mesh"});
}

}  // namespace
}  // namespace topopt::pipeline
