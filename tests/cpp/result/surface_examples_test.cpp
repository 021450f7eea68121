// The design surfaces of the shared examples (rocker, cantilever, bracket, mount; load cases of
// ../shared/data/README.md) on coarse meshes, each at two settings (the threshold that keeps
// the volume fraction with the default smoothing; threshold 0.4 with 60 smoothing pairs): a
// valid solid (closed, outward, no self-intersection by the exact check), no triangle below 10°
// on the free-form surface and on Ω's faces, the smallest angle on the non-design faces at its
// measured floor, the volume of the kept design (smoothing does not shrink it), Ω's planar faces'
// points in their planes, the points splits added inside Ω's curved faces on their true
// surfaces, and the non-design points where marching tetrahedra put them (or, added by a split,
// on the non-design triangles they put there); at the volume's threshold, its result.step read
// back by OCCT as one valid solid of one shell with the surface's volume.
#include <gtest/gtest.h>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp_Explorer.hxx>

#include <algorithm>
#include <array>
#include <filesystem>
#include <set>
#include <string>

#include "pipeline/job.h"
#include "pipeline/optimize_job.h"
#include "pipeline/result_files.h"
#include "pipeline/run_job.h"
#include "result/result_check.h"
#include "result/step_export.h"
#include "testing/nondesign_distance.h"

namespace topopt::result {
namespace {

struct Example {
  std::string name;
  double size;          // mesh size (mm)
  std::string problem;  // supports and load cases
  /// The smallest angle asserted on Ω's kept faces (issue 19 asks 10°). Measured on main before
  /// the splits on curved faces and on non-design faces: rocker 7.95° (a needle on the cylindrical
  /// face 5 whose short edge lies on the B-Rep edge to face 2, and one on face 7 whose long edge is
  /// the straight B-Rep edge to face 6: 9.09°), cantilever 9.32° (a triangle of three non-design
  /// points on planar face 6, whose split half on the other side was thinner still); now every
  /// example reaches 10° at both settings (the splits put the new point on the face's true surface
  /// through the input's SourceFaces).
  double min_angle_faces;
  /// The smallest free-form angle asserted (issue 19 asks 10°): every example at both settings
  /// reaches it (the mount at threshold 0.4 measured 7.9° until its free needle, a 0.30 mm edge
  /// between two non-design points, was mended by splitting its long edge: 13.47°).
  double min_angle = 10.0;
};

/// The smallest angle asserted on the non-design solids' faces (issue 19 asks 10°): the smallest
/// angle of any triangle tagged -k (the exposed parts of the FE mesh's boundary triangles of the
/// non-design solids, as the remesher left them). Measured 7.27° on the bracket at the default
/// threshold (a needle on the boss cylinder of non-design solid 5 next to the crease, its long
/// edge between two chords bent 2.2°) until splits between two chords of one curved non-design
/// face put the new point on the face's true surface (SourceFaces) and flips across such bent
/// edges were allowed.
constexpr double kMinAngleNondesign = 10.0;

pipeline::Job example_job(const Example& e) {
  const std::string dir = std::string(TOPOPT_SHARED_DATA) + "/examples/";
  return pipeline::parse_job(R"({"part": ")" + dir + e.name + R"(.step", "nondesign": ")" + dir + e.name +
                                 R"(_nondesign.step", "mesh": {"size": )" + std::to_string(e.size) +
                                 R"(}, "optimization": {"volume_fraction": 0.3, "max_iterations": 40}, )" + e.problem +
                                 "}",
                             "/tmp");
}

double nondesign_volume(const TetMesh& mesh) {
  double v = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (mesh.domain[t] == 0) continue;
    const Eigen::Vector3d a = mesh.V.row(mesh.T(t, 0)).transpose();
    v += std::abs((mesh.V.row(mesh.T(t, 1)).transpose() - a)
                      .cross(mesh.V.row(mesh.T(t, 2)).transpose() - a)
                      .dot(mesh.V.row(mesh.T(t, 3)).transpose() - a)) /
         6;
  }
  return v;
}

/// The properties every design surface must have; `design` (#T) and `threshold` are what it
/// was cut from.
void check_design_surface(const TetMesh& mesh, const TriSurface& s, const VecXd& design, double threshold,
                          const Example& e, const SourceFaces& source) {
  const ResultCheck c = check_result(s);
  EXPECT_TRUE(c.closed.closed_manifold()) << c.closed.unpaired_edges << " unpaired edges";
  EXPECT_GT(c.closed.volume, 0);
  EXPECT_EQ(c.crossings.size(), 0u);
  EXPECT_GE(c.min_angle_free, e.min_angle);
  EXPECT_GE(c.min_angle_faces, e.min_angle_faces);
  EXPECT_GE(c.min_angle_nondesign, kMinAngleNondesign);
  // the volume: the kept design (exact for the linear field) plus the non-design solids
  const VecXd nd = node_densities(mesh, design);
  const double kept = kept_design_volume(mesh, nd, threshold) + nondesign_volume(mesh);
  EXPECT_NEAR(c.closed.volume, kept, 0.03 * kept);
  // Ω's planar faces' points in their planes
  const double scale = (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm();
  double off_plane = 0;
  for (long t = 0; t < s.F.rows(); ++t) {
    const int f = s.tag[t];
    if (f <= 0 || f >= static_cast<int>(s.face_plane.size()) || s.face_plane[f].head<3>().norm() == 0) continue;
    for (int k = 0; k < 3; ++k)
      off_plane = std::max(
          off_plane, std::abs(s.face_plane[f].head<3>().dot(s.V.row(s.F(t, k)).transpose()) - s.face_plane[f][3]));
  }
  EXPECT_LE(off_plane, 1e-9 * scale);
  // the non-design points are points of the unsmoothed surface, unmoved, or points a split added
  // on an edge of its non-design triangles: on a triangle of the unsmoothed surface's non-design
  // faces (a split within one plane), or on the true surface of the curved non-design face the
  // triangles around it lie on (a split between two chords of that face)
  const std::vector<int> on = source.classify(s);
  std::vector<double> to_curved(s.V.rows(), 1e300);  // per point: distance to its triangles' curved faces
  for (long t = 0; t < s.F.rows(); ++t)
    for (int k = 0; k < 3 && s.tag[t] < 0 && on[t] >= 0; ++k) {
      const Eigen::Vector3d p = s.V.row(s.F(t, k)).transpose();
      GeomAPI_ProjectPointOnSurf nearest(gp_Pnt(p.x(), p.y(), p.z()), source.surface(on[t]));
      if (nearest.NbPoints() > 0) to_curved[s.F(t, k)] = std::min(to_curved[s.F(t, k)], nearest.LowerDistance());
    }
  const TriSurface raw = extract_iso_surface(mesh, nd, threshold, SmoothParams{}.crossing_margin);
  std::set<std::array<double, 3>> fixed;
  for (long i = 0; i < raw.V.rows(); ++i)
    if (raw.lock[i] == 2) fixed.insert({raw.V(i, 0), raw.V(i, 1), raw.V(i, 2)});
  long off = 0, locked = 0, added = 0;
  for (long i = 0; i < s.V.rows(); ++i) {
    if (s.lock[i] != 2) continue;
    ++locked;
    if (fixed.count({s.V(i, 0), s.V(i, 1), s.V(i, 2)})) continue;
    ++added;
    off += testing::distance_to_nondesign(raw, s.V.row(i).transpose()) > 1e-9 * scale && to_curved[i] > 1e-9 * scale;
  }
  EXPECT_GT(locked, 0);
  EXPECT_EQ(off, 0) << "of " << added << " non-design points added by splits";
  // the points splits added inside Ω's curved faces lie on the faces' true surfaces
  std::set<std::array<double, 3>> cut;
  for (long i = 0; i < raw.V.rows(); ++i) cut.insert({raw.V(i, 0), raw.V(i, 1), raw.V(i, 2)});
  double off_surface = 0;
  for (long t = 0; t < s.F.rows(); ++t)
    for (int k = 0; k < 3 && s.tag[t] > 0 && on[t] >= 0; ++k) {
      const Eigen::Vector3d p = s.V.row(s.F(t, k)).transpose();
      if (cut.count({p.x(), p.y(), p.z()})) continue;
      GeomAPI_ProjectPointOnSurf nearest(gp_Pnt(p.x(), p.y(), p.z()), source.surface(on[t]));
      ASSERT_GT(nearest.NbPoints(), 0);
      off_surface = std::max(off_surface, nearest.LowerDistance());
    }
  EXPECT_LE(off_surface, 1e-9 * scale);
}

/// The run's result as result.step, read back by OCCT: one valid solid of one shell (the result
/// is one piece, the non-design solids no load needs joined by bridges, and holds no closed
/// void) whose volume is the surface's within 0.5 %.
void check_step(const TriSurface& s, const std::string& name, const SourceFaces& source) {
  const std::string path =
      (std::filesystem::temp_directory_path() / ("topopt_surface_examples_" + name + ".step")).string();
  const StepExportReport written = write_result_step(path, s, {}, {}, &source);
  EXPECT_TRUE(written.valid);
  STEPControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  const TopoDS_Shape back = reader.OneShape();
  const StepExportReport r = describe_solid(back);
  EXPECT_TRUE(r.valid) << solid_faults(back);
  EXPECT_EQ(r.solids, 1);
  int shells = 0;
  for (TopExp_Explorer x(back, TopAbs_SHELL); x.More(); x.Next()) ++shells;
  EXPECT_EQ(shells, 1);
  const double volume = check_surface(s.V, s.F).volume;
  EXPECT_NEAR(r.volume, volume, 0.005 * volume);
  std::filesystem::remove(path);
}

void check_example(const Example& e) {
  const pipeline::Job job = example_job(e);
  const pipeline::RunResult run = pipeline::run_job(job);
  const pipeline::OptimizeResult& r = run.optimization;
  const SourceFaces source = pipeline::source_faces(job);
  {
    SCOPED_TRACE(e.name + ": the volume's threshold, 20 smoothing pairs");
    check_design_surface(run.mesh, r.surface, r.design, r.threshold, e, source);
    check_step(r.surface, e.name, source);
  }
  SCOPED_TRACE(e.name + ": threshold 0.4, 60 smoothing pairs");
  SmoothParams smooth;
  smooth.iterations = 60;
  VecXd design;
  const TriSurface s =
      pipeline::result_surface(run.mesh, r.simp.density, 0.4, 0.3, smooth, nullptr,
                               pipeline::anchor_nodes(run.mesh, job), {}, nullptr, &design, {}, nullptr, &source);
  check_design_surface(run.mesh, s, design, 0.4, e, source);
}

TEST(SurfaceExamples, Rocker) {
  check_example({"rocker", 3.0,
                 R"("supports": [{"type": "fixed", "faces": ["Face10"]}], "load_cases": [{"name": "rocker", "loads":
                  [{"type": "force", "faces": ["Face9"], "vector": [0, -1000, 0]},
                   {"type": "force", "faces": ["Face11"], "vector": [600, 0, 0]}]}])",
                 10.0});
}

TEST(SurfaceExamples, Cantilever) {
  check_example({"cantilever", 3.0,
                 R"("supports": [{"type": "fixed", "faces": ["Face1"]}], "load_cases": [{"name": "tip", "loads":
                  [{"type": "force", "faces": ["NonDesign:Face12"], "vector": [0, 0, -1000]}]}])",
                 10.0});
}

TEST(SurfaceExamples, Bracket) {
  check_example({"bracket", 5.0,
                 R"("supports": [{"type": "fixed", "faces": ["Face10", "Face11", "Face12", "Face13"]}], "load_cases":
                  [{"name": "x", "loads": [{"type": "force", "faces": ["Face7"], "vector": [5000, 0, 0]}]},
                   {"name": "z", "loads": [{"type": "force", "faces": ["Face7"], "vector": [0, 0, -5000]}]}])",
                 10.0});
}

TEST(SurfaceExamples, Mount) {
  // bolt bores Face28-31 fixed; the lug's bore Face8: 10 000 N in -z, and separately 5 000 N in +y
  check_example({"mount", 5.0,
                 R"("supports": [{"type": "fixed", "faces": ["Face28", "Face29", "Face30", "Face31"]}], "load_cases":
                  [{"name": "down", "loads": [{"type": "force", "faces": ["Face8"], "vector": [0, 0, -10000]}]},
                   {"name": "side", "loads": [{"type": "force", "faces": ["Face8"], "vector": [0, 5000, 0]}]}])",
                 10.0});
}

}  // namespace
}  // namespace topopt::result
