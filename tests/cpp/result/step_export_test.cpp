// The result as a CAD solid: one valid solid whose volume is the surface's, Ω's planar faces
// back as single planar B-Rep faces, and a STEP file OCCT reads back as the same solid.
#include "result/step_export.h"

#include <gtest/gtest.h>

#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <Geom_Plane.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <cmath>
#include <array>
#include <filesystem>
#include <map>
#include <gp_Pln.hxx>

#include "common/error.h"
#include "simp/density_filter.h"
#include "testing/bar_field.h"
#include "testing/cube_piece.h"

namespace topopt::result {
namespace {

/// A 40x20x10 box, a non-design block at each end (x in [0, 6] and [36, 40]) and between them
/// a round bar of varying radius: the unsmoothed iso-surface of that density field.
TriSurface bar_surface() {
  const testing::BarField bar = testing::bar_field(6, testing::wavy_radius);
  return extract_iso_surface(bar.mesh, node_densities(bar.mesh, bar.density), 0.5);
}

/// The faces of `shape` on the plane x = x0 (normal along x).
int faces_on_plane_x(const TopoDS_Shape& shape, double x0) {
  int n = 0;
  for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next()) {
    Handle(Geom_Plane) plane = Handle(Geom_Plane)::DownCast(BRep_Tool::Surface(TopoDS::Face(e.Current())));
    if (plane.IsNull()) continue;
    const gp_Pln pl = plane->Pln();
    if (std::abs(std::abs(pl.Axis().Direction().X()) - 1) < 1e-9 && std::abs(pl.Location().X() - x0) < 1e-9) ++n;
  }
  return n;
}

/// The shape OCCT's STEP reader makes of the file at `path` (null when it cannot read it).
TopoDS_Shape read_step(const std::string& path) {
  STEPControl_Reader reader;
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return {};
  reader.TransferRoots();
  return reader.OneShape();
}

/// The export without coarsening: every triangle of the surface becomes (part of) a face, so
/// the solid's volume is the surface's exactly.
const StepExportParams kFacets{.coarsen = {.tolerance = 0}};

TEST(StepExport, OneValidSolidWithTheSurfacesVolumeAndMergedPlanarFaces) {
  const TriSurface s = bar_surface();
  const double volume = check_surface(s.V, s.F).volume;
  const TopoDS_Shape solid = result_solid(s, kFacets);
  const StepExportReport r = describe_solid(solid);
  EXPECT_TRUE(r.valid);
  EXPECT_EQ(r.solids, 1);
  EXPECT_NEAR(r.volume, volume, 1e-6 * volume);
  // Ω's faces x = 0 and x = 40 keep one connected region each (the block's end and the bar's
  // section meet there): each is one planar B-Rep face
  EXPECT_EQ(faces_on_plane_x(solid, 0), 1);
  EXPECT_EQ(faces_on_plane_x(solid, 40), 1);
  // the blocks' five other faces are planar too; the bar's facets stay apart
  EXPECT_GE(r.planar_faces, 2 + 2 * 4);
  long free_form = 0;
  for (long q = 0; q < s.tag.size(); ++q) free_form += s.tag[q] == 0;
  EXPECT_LE(r.faces, free_form + r.planar_faces);
  // without merging every triangle is a face
  EXPECT_EQ(describe_solid(result_solid(s, {.unify = false, .coarsen = {.tolerance = 0}})).faces, s.F.rows());
}

TEST(StepExport, ABodyPerPieceAndVoidsAsInnerShells) {
  // a detached piece (the bracket's and the mount's results hold detached non-design solids)
  // made one shell of several pieces, which BRepCheck refuses: one solid per body now
  const TriSurface bar = bar_surface();
  const double volume = check_surface(bar.V, bar.F).volume;
  const TriSurface two = testing::with_cube(bar, {20, 16, 1}, 3);  // clear of the bar
  EXPECT_EQ(result_bodies(two), 2);
  StepExportReport r = describe_solid(result_solid(two, kFacets));
  EXPECT_TRUE(r.valid);
  EXPECT_EQ(r.solids, 2);
  EXPECT_NEAR(r.volume, volume + 27, 1e-6 * volume);
  // a closed void inside the first end block (x in [0, 6], y in [6, 14], z in [2, 8])
  const TriSurface hollow = testing::with_cube(bar, {2, 9, 4}, 2, true);
  EXPECT_EQ(result_bodies(hollow), 1);
  r = describe_solid(result_solid(hollow, kFacets));
  EXPECT_TRUE(r.valid);
  EXPECT_EQ(r.solids, 1);
  EXPECT_NEAR(r.volume, volume - 8, 1e-6 * volume);
}

TEST(StepExport, ASolidCheckedWhileBuiltIsWhatOcctsCheckOfTheWholeShapeSays) {
  // write_result_step checks the solid once (each body as result_solid builds it), not again on
  // the whole shape: the word "checked" must agree with OCCT's check of what is returned, for one
  // body, two bodies in a compound and a body with a void; unmerged (params.unify off) nothing is
  // checked and the word is "not checked"
  const TriSurface bar = bar_surface();
  for (const TriSurface& s :
       {bar, testing::with_cube(bar, {20, 16, 1}, 3), testing::with_cube(bar, {2, 9, 4}, 2, true)}) {
    bool checked = false;
    const TopoDS_Shape shape = result_solid(s, {}, nullptr, nullptr, nullptr, &checked);
    EXPECT_TRUE(checked);
    EXPECT_TRUE(BRepCheck_Analyzer(shape).IsValid());
    const StepExportReport r = describe_solid(shape, checked), again = describe_solid(shape);
    EXPECT_EQ(r.valid, again.valid);
    EXPECT_EQ(r.solids, result_bodies(s));
    EXPECT_EQ(r.faces, again.faces);
    EXPECT_NEAR(r.volume, again.volume, 1e-9 * again.volume);
    checked = true;
    result_solid(s, {.unify = false, .coarsen = {.tolerance = 0}}, nullptr, nullptr, nullptr, &checked);
    EXPECT_FALSE(checked);
  }
}

TEST(StepExport, SeparateBodiesAreOneCompoundOfSolidsWithAWarningNamingEach) {
  // The bracket's and the mount's results hold non-design solids the design does not join (held
  // by their own supports): as made they are separate parts, so the STEP cannot honestly be one
  // solid. What is checked: the file holds them as one compound of valid solids, one per body,
  // and the user is told which bodies they are (volume, place, what they are made of).
  const TriSurface bar = bar_surface();
  const TriSurface two = testing::with_cube(bar, {20, 16, 1}, 3);  // a 3 mm cube clear of the bar
  const std::vector<std::string> named = body_descriptions(two);
  ASSERT_EQ(named.size(), 2u);
  EXPECT_NE(named[0].find("the design with non-design solids"), std::string::npos) << named[0];
  EXPECT_NE(named[1].find("body 2: 27 mm³ around (21.5, 17.5, 2.5)"), std::string::npos) << named[1];
  std::vector<std::string> warnings;
  Progress progress;
  progress.log = [&](LogLevel level, const std::string& m) {
    if (level == LogLevel::Warning) warnings.push_back(m);
  };
  const std::string path = (std::filesystem::temp_directory_path() / "topopt_step_export_two.step").string();
  const StepExportReport written = write_result_step(path, two, kFacets, progress);
  EXPECT_TRUE(written.valid);
  EXPECT_EQ(written.solids, 2);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("2 separate solids in one compound"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find(named[1]), std::string::npos) << warnings[0];
  const TopoDS_Shape shape = read_step(path);
  ASSERT_FALSE(shape.IsNull());
  const StepExportReport back = describe_solid(shape);
  EXPECT_TRUE(back.valid);
  EXPECT_EQ(back.solids, 2);
  // one body: no warning
  warnings.clear();
  write_result_step(path, bar, kFacets, progress);
  EXPECT_TRUE(warnings.empty());
  std::filesystem::remove(path);
}

TEST(StepExport, TheStepFileReadsBackAsOneValidSolidOfTheSameVolume) {
  const TriSurface s = bar_surface();
  const std::string path = (std::filesystem::temp_directory_path() / "topopt_step_export_test.step").string();
  const StepExportReport written = write_result_step(path, s);
  EXPECT_GT(written.bytes, 0);
  const TopoDS_Shape shape = read_step(path);
  ASSERT_FALSE(shape.IsNull());
  const StepExportReport back = describe_solid(shape);
  EXPECT_TRUE(back.valid);
  EXPECT_EQ(back.solids, 1);
  EXPECT_EQ(back.faces, written.faces);
  const double stl_volume = check_surface(s.V, s.F).volume;
  EXPECT_NEAR(back.volume, stl_volume, 0.005 * stl_volume);
  EXPECT_EQ(faces_on_plane_x(shape, 0), 1);
  std::filesystem::remove(path);
}

/// The closed surface of the cube [0, n]³ with every face an n by n grid of squares, each
/// split in two triangles (12 n² triangles, outward), all tagged free-form.
TriSurface grid_cube(int n) {
  std::map<std::array<int, 3>, int> index;
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> triangles;
  const auto at = [&](std::array<int, 3> p) {
    const auto [it, added] = index.emplace(p, static_cast<int>(points.size()));
    if (added) points.emplace_back(p[0], p[1], p[2]);
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side)
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const auto corner = [&](int di, int dj) {
            std::array<int, 3> p{};
            p[axis] = side * n, p[(axis + 1) % 3] = i + di, p[(axis + 2) % 3] = j + dj;
            return at(p);
          };
          // (axis+1, axis+2) turn about +axis: counter-clockwise seen from outside on the far side
          const int a = corner(0, 0), b = corner(1, 0), c = corner(1, 1), d = corner(0, 1);
          if (side == 1) triangles.emplace_back(a, b, c), triangles.emplace_back(a, c, d);
          if (side == 0) triangles.emplace_back(a, c, b), triangles.emplace_back(a, d, c);
        }
  TriSurface s;
  s.V.resize(static_cast<long>(points.size()), 3);
  for (size_t k = 0; k < points.size(); ++k) s.V.row(static_cast<long>(k)) = points[k];
  s.F.resize(static_cast<long>(triangles.size()), 3);
  for (size_t k = 0; k < triangles.size(); ++k) s.F.row(static_cast<long>(k)) = triangles[k];
  s.tag = VecXi::Zero(s.F.rows());
  s.lock = VecXi::Zero(s.V.rows());
  s.point_face = VecXi::Zero(s.V.rows());
  return s;
}

TEST(StepExport, ASurfaceOverTheOldBudgetIsWrittenWithItsPlanarFacesWhole) {
  // past the 60 000 triangles the export refused until branch step7 (a cube of 12 n² triangles,
  // free-form): written with the default budget as one valid solid of the cube's volume and
  // its six planar faces whole
  const int n = 71;
  const TriSurface big = grid_cube(n);
  ASSERT_GT(big.F.rows(), 60000);
  const SurfaceCheck check = check_surface(big.V, big.F);
  ASSERT_TRUE(check.closed_manifold());
  const std::string path = (std::filesystem::temp_directory_path() / "topopt_step_export_big.step").string();
  std::filesystem::remove(path);
  const StepExportReport written = write_result_step(path, big);
  EXPECT_TRUE(written.valid);
  EXPECT_EQ(written.solids, 1);
  EXPECT_NEAR(written.volume, double(n) * n * n, 1e-6 * n * n * n);
  EXPECT_EQ(written.faces, 6);
  const StepExportReport back = describe_solid(read_step(path));
  EXPECT_TRUE(back.valid);
  EXPECT_EQ(back.solids, 1);
  EXPECT_EQ(back.faces, 6);
  std::filesystem::remove(path);
}

TEST(StepExport, ASurfaceOverTheBudgetIsCoarsenedToItOrRefusedByName) {
  // a budget below what the default coarsening leaves of a curved result surface: coarsened
  // harder until it fits, one valid solid within 0.5 % of the surface's volume, read back
  const TriSurface s = bar_surface();
  const double volume = check_surface(s.V, s.F).volume;
  CoarsenReport usual;
  coarsen_free_form(s, CoarsenParams{}, &usual);
  StepExportParams params;
  params.max_triangles = static_cast<long>(0.9 * usual.triangles_after);
  ASSERT_LT(params.max_triangles, usual.triangles_after);
  const std::string path = (std::filesystem::temp_directory_path() / "topopt_step_export_budget.step").string();
  std::filesystem::remove(path);
  const StepExportReport written = write_result_step(path, s, params);
  EXPECT_LE(written.triangles, params.max_triangles);
  EXPECT_TRUE(written.valid);
  EXPECT_EQ(written.solids, 1);
  EXPECT_NEAR(written.volume, volume, 0.005 * volume);
  const StepExportReport back = describe_solid(read_step(path));
  EXPECT_TRUE(back.valid);
  EXPECT_EQ(back.solids, 1);
  EXPECT_NEAR(back.volume, volume, 0.005 * volume);
  std::filesystem::remove(path);
  // nothing to coarsen (every triangle on Ω's faces): past the budget it is refused by the key
  // that raises it, and nothing is written
  TriSurface fixed = grid_cube(8);
  fixed.tag.setOnes();
  params.max_triangles = fixed.F.rows() - 1;
  try {
    write_result_step(path, fixed, params);
    FAIL() << "a surface of " << fixed.F.rows() << " triangles was written past a budget of " << params.max_triangles;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::TooLarge);
    const std::string message = e.what();
    EXPECT_NE(message.find(max_triangles_key), std::string::npos) << message;
    EXPECT_NE(message.find(std::to_string(fixed.F.rows()) + " triangles"), std::string::npos) << message;
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  params.max_triangles = fixed.F.rows();
  EXPECT_TRUE(write_result_step(path, fixed, params).valid);
  std::filesystem::remove(path);
}

TEST(StepExport, AnOpenOrDegenerateSurfaceIsANamedError) {
  TriSurface s = bar_surface();
  TriSurface open = s;
  open.F.conservativeResize(s.F.rows() - 1, 3);
  try {
    result_solid(open);
    FAIL() << "an open surface became a solid";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidShape);
    EXPECT_NE(std::string(e.what()).find("not closed"), std::string::npos) << e.what();
  }
  // a triangle squashed flat: its corner moved onto the opposite edge's midpoint
  TriSurface flat = s;
  flat.V.row(flat.F(0, 2)) = (flat.V.row(flat.F(0, 0)) + flat.V.row(flat.F(0, 1))) / 2;
  try {
    result_solid(flat, kFacets);
    FAIL() << "a triangle without area became a face";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidShape);
    EXPECT_NE(std::string(e.what()).find("without area"), std::string::npos) << e.what();
  }
  // in the child the same error comes back with its code, and no file is left
  const std::string path = (std::filesystem::temp_directory_path() / "topopt_step_export_bad.step").string();
  std::filesystem::remove(path);
  try {
    write_result_step(path, open);
    FAIL() << "an open surface was written";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::InvalidShape);
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace topopt::result
