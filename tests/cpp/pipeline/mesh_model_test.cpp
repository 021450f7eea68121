// The mesher choice: auto meshes natively and reports it, falls back to Gmsh (in a child
// process) where the native mesher cannot close a mesh, refuses a mesh too large before any
// meshing, names Gmsh's timeout, and leaves no file behind from Gmsh.
#include "pipeline/mesh_model.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <BRepPrimAPI_MakeBox.hxx>
#include <BRep_Builder.hxx>
#include <TopoDS_Compound.hxx>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>

#include "brep/shape_io.h"
#include "common/error.h"
#include "fem/boundary_conditions.h"
#include "fem/elasticity.h"
#include "mesh/core/conformity.h"
#include "mesh/two_brep/native_mesher.h"
#include "testing/expect_error.h"

namespace topopt::pipeline {
namespace {
namespace fs = std::filesystem;

brep::TwoBReps example(const std::string& name) {
  const std::string dir = std::string(TOPOPT_SHARED_DATA) + "/examples/";
  return brep::load_two_breps(brep::read_shape_file(dir + name + ".step"),
                              brep::read_shape_file(dir + name + "_nondesign.step"));
}

/// Two non-design blocks inside a box that touch on x = 20 with faces of different sizes, with
/// the imprint withheld: brep/imprint.h makes such faces identical, and without it the native
/// mesher meets unequal touching faces and fails ("only identical touching faces"). A failure
/// of the native mesher on demand, which Gmsh's fragments mesh.
brep::TwoBReps native_fails() {
  auto box = [](double x, double y, double z, double dx, double dy, double dz) {
    return BRepPrimAPI_MakeBox(gp_Pnt(x, y, z), dx, dy, dz).Shape();
  };
  TopoDS_Compound nd;
  BRep_Builder builder;
  builder.MakeCompound(nd);
  builder.Add(nd, box(10, 5, 2, 10, 10, 6));
  builder.Add(nd, box(20, 2, 1, 10, 16, 8));
  brep::TwoBReps m = brep::load_two_breps(box(0, 0, 0, 40, 20, 10), nd);
  m.meshed = brep::without_imprint(m.nondesign, m.nd_on_part, m.relations);
  return m;
}

using topopt::testing::expect_error;

MeshSettings with(Mesher mesher, double size = 0) {
  MeshSettings s;
  s.mesher = mesher;
  s.size = size;
  return s;
}

TEST(MeshModel, MesherChoiceIsCheckedAndReported) {
  const brep::TwoBReps model = example("cantilever");
  mesh::MeshRun run;
  const TetMesh m = mesh_model(model, with(Mesher::Auto), {}, &run);
  EXPECT_EQ(run.mesher, "native");
  EXPECT_TRUE(run.fallback_reason.empty());
  ASSERT_EQ(run.seconds.size(), 6u);  // steps 1-7, 8-11, 12, 13-14, the sliver pass, the conformity check
  EXPECT_EQ(run.seconds.back().first, "conformity check");
  EXPECT_TRUE(mesh::check_conformity(m, &model).ok());
  // a size that would not fit in memory is refused up front, by auto too (Gmsh would not fit either)
  expect_error([&] { mesh_model(model, with(Mesher::Auto, 0.01)); }, ErrorCode::TooLarge, {"mesh size of at least"});
  expect_error([&] { mesh_model(model, with(Mesher::Gmsh, 0.01)); }, ErrorCode::TooLarge, {"mesh size of at least"});
}

TEST(MeshModel, AutoFallsBackToGmshInAChildProcess) {
  const brep::TwoBReps model = native_fails();
  ASSERT_EQ(model.relations.contacts.size(), 1u);
  std::vector<std::string> warnings;
  Progress p;
  p.log = [&](LogLevel level, const std::string& m) {
    if (level == LogLevel::Warning) warnings.push_back(m);
  };
  mesh::MeshRun run;
  const TetMesh m = mesh_model(model, with(Mesher::Auto), p, &run);
  EXPECT_EQ(run.mesher, "gmsh");
  EXPECT_NE(run.fallback_reason.find("identical touching faces"), std::string::npos);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("meshing with Gmsh's OCC fragments instead"), std::string::npos);
  const mesh::ConformityReport c = mesh::check_conformity(m, &model);
  EXPECT_TRUE(c.ok()) << c.to_json().dump();
  // "native" does not fall back
  expect_error([&] { mesh_model(model, with(Mesher::Native)); }, ErrorCode::MeshingFailed, {"identical touching"});
}

TEST(MeshModel, GmshPastItsTimeBudgetIsANamedError) {
  MeshSettings s = with(Mesher::Gmsh);
  s.gmsh_seconds = 0.05;
  expect_error([&] { mesh_model(example("rocker"), s); }, ErrorCode::Timeout,
               {"meshing with Gmsh did not finish within"});
  // under auto, the native mesher's failure is named first
  s.mesher = Mesher::Auto;
  expect_error([&] { mesh_model(native_fails(), s); }, ErrorCode::Timeout,
               {"the native mesher could not mesh this part", "identical touching faces",
                "the Gmsh fallback failed too", "did not finish"});
}

TEST(MeshModel, GmshInItsChildAfterParallelWorkInTheParent) {
  // the workbench's process solves (CHOLMOD, BLAS and OpenMP threads) before a later run falls
  // back to Gmsh: the forked child, which has one thread, must still mesh (not hang)
  const brep::TwoBReps model = example("cantilever");
  const TetMesh native = mesh_model(model, with(Mesher::Native, 2));
  const fem::Supports s =
      fem::make_supports(native, {fem::SupportSpec{fem::SupportSpec::Kind::Fixed, {1}, {true, true, true}, {}}});
  const Eigen::MatrixXd F = fem::make_loads(
      native, {}, {fem::LoadCase{"tip", {fem::LoadSpec{fem::LoadSpec::Kind::Gravity, {}, {0, 0, -9810}, 0, {}}}, 1}});
  fem::Elasticity fe(native, {}, s, {});
  EXPECT_GT(F.col(0).dot(fe.solve(F).col(0)), 0);
  MeshSettings g = with(Mesher::Gmsh, 4);
  g.gmsh_seconds = 120;
  mesh::MeshRun run;
  const TetMesh m = mesh_model(model, g, {}, &run);
  EXPECT_EQ(run.mesher, "gmsh");
  EXPECT_TRUE(mesh::check_conformity(m, &model).ok());
}

TEST(MeshModel, GmshWritesNoFileOfItsOwn) {
  // Gmsh starts FLTK, which rewrites $HOME/.fltk/fltk.org/fltk.prefs, and Gmsh removes
  // $HOME/.gmsh-tmp: a HOME of our own must stay as it was (a file Gmsh would delete included)
  const fs::path home = fs::temp_directory_path() / ("topopt_gmsh_home_" + std::to_string(::getpid()));
  fs::create_directories(home);
  std::ofstream(home / ".gmsh-tmp") << "the user's file\n";
  const char* old = std::getenv("HOME");
  const std::string saved = old ? old : "";
  ::setenv("HOME", home.c_str(), 1);
  mesh::MeshRun run;
  EXPECT_NO_THROW(mesh_model(example("cantilever"), with(Mesher::Gmsh, 4), {}, &run));
  if (old)
    ::setenv("HOME", saved.c_str(), 1);
  else
    ::unsetenv("HOME");
  EXPECT_EQ(run.mesher, "gmsh");
  std::vector<std::string> left;
  for (const auto& e : fs::recursive_directory_iterator(home)) left.push_back(e.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{".gmsh-tmp"});
  EXPECT_TRUE(fs::exists(home / ".gmsh-tmp"));
  fs::remove_all(home);
}

TEST(MeshModel, NativePastItsTimeBudgetIsANamedErrorSoonAfter) {
  const brep::TwoBReps model = example("rocker");
  MeshSettings s = with(Mesher::Native);
  s.native_seconds = 0.05;
  const auto t0 = std::chrono::steady_clock::now();
  expect_error([&] { mesh_model(model, s); }, ErrorCode::Timeout,
               {"the native mesher did not finish within its time budget of 1 s of computing", "and was stopped in ",
                "give a larger mesh size"});
  // the stages check the deadline often: stopped well before the mesh would be done (the
  // whole mesh takes about 1 s unloaded; this bound allows for a machine shared six ways)
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  // under auto, Gmsh meshes it instead, and says why
  s.mesher = Mesher::Auto;
  mesh::MeshRun run;
  const TetMesh m = mesh_model(example("cantilever"), s, {}, &run);
  EXPECT_EQ(run.mesher, "gmsh");
  EXPECT_NE(run.fallback_reason.find("did not finish within its time budget"), std::string::npos)
      << run.fallback_reason;
  EXPECT_GT(m.T.rows(), 1000);
  ASSERT_FALSE(run.seconds.empty());
  EXPECT_EQ(run.seconds.back().first, "conformity check");  // Gmsh's mesh is checked too
  // a negative budget is the user's mistake, named
  s.native_seconds = -1;
  expect_error([&] { mesh_model(model, s); }, ErrorCode::InvalidParameter, {"time limit"});
}

TEST(MeshModel, NativeTetsWithinOneAndAHalfOfGmshsAtTheSameSettings) {
  // The default size on two shared examples, both meshers given the same sizes (the part's
  // diagonal / 50, its tenth as the floor, 40 elements per turn): the native mesh has at most
  // 1.5 times Gmsh's tets (bench/twobrep --shared: every shared part), every domain within
  // 0.5 % of its B-Rep volume, and the run says per face which rule sets its size (the
  // rocker's bores: curvature; its flat faces next to them: graded from those neighbours; the
  // cantilever's faces under its pads: the non-design solids' segments).
  for (const std::string name : {"cantilever", "rocker"}) {
    SCOPED_TRACE(name);
    const brep::TwoBReps model = example(name);
    mesh::MeshRun run;
    const TetMesh native = mesh_model(model, with(Mesher::Native), {}, &run);
    const TetMesh gmsh = mesh_model(model, with(Mesher::Gmsh));
    EXPECT_LE(native.T.rows(), 1.5 * gmsh.T.rows()) << native.T.rows() << " against " << gmsh.T.rows();
    EXPECT_LT(mesh::check_conformity(native, &model).max_volume_error, 0.005);
    ASSERT_EQ(run.face_sizes.size(), static_cast<size_t>(model.part.num_faces()));
    int curvature = 0, neighbour = 0, nondesign = 0;
    for (const mesh::FaceSize& f : run.face_sizes) {
      EXPECT_LE(f.size, f.face_size + 1e-12) << "Face" << f.face;
      curvature += f.reason == mesh::SizeReason::Curvature || f.reason == mesh::SizeReason::MinSize;
      neighbour += f.reason == mesh::SizeReason::Neighbour;
      nondesign += f.reason == mesh::SizeReason::NonDesign;
    }
    if (name == "rocker") {
      EXPECT_GT(curvature, 0);
      EXPECT_GT(neighbour, 0);
    }
    if (name == "cantilever") {
      EXPECT_GT(nondesign, 0);
    }
  }
}

}  // namespace
}  // namespace topopt::pipeline
