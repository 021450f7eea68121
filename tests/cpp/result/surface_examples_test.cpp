// The design surfaces of the shared examples (rocker, cantilever, bracket, mount; load cases of
// ../shared/data/README.md) on coarse meshes, each at two settings (the threshold that keeps
// the volume fraction with the default smoothing; threshold 0.4 with 60 smoothing pairs): a
// valid solid (closed, outward, no self-intersection by the exact check), no triangle below 10°
// on the free-form surface, the smallest angles on Ω's faces and the
// non-design faces at their measured floors, the volume of the kept design (smoothing does not shrink it), Ω's
// planar faces' points in their planes and the non-design points where marching tetrahedra put
// them.
#include <gtest/gtest.h>

#include <array>
#include <set>
#include <string>

#include "pipeline/job.h"
#include "pipeline/optimize_job.h"
#include "pipeline/run_job.h"
#include "result/result_check.h"

namespace topopt::result {
namespace {

struct Example {
  std::string name;
  double size;          // mesh size (mm)
  std::string problem;  // supports and load cases
  /// The smallest angle asserted on Ω's kept faces (issue 19 asks 10°; not reached on all yet).
  /// Measured at the two settings: rocker 7.95° / 11.5° (a needle on the cylindrical face 5
  /// between a point on a B-Rep edge or on the cut line and an FE node 0.4-0.6 mm away, where
  /// every collapse makes a worse triangle and a curved face's edges are not split), cantilever
  /// 9.32° (an FE boundary triangle of the non-design solid on the border of its footprint, whose
  /// points may not move) / 12.6°, bracket 10.24° / 12.2° and mount 12.87° / 12.12° (their
  /// cut-line needles, 9.67° and 5.45° before, mended by splitting the long edge): asserted just
  /// under what is measured so it cannot get worse unseen.
  double min_angle_faces;
  /// The smallest free-form angle asserted (issue 19 asks 10°): every example at both settings
  /// reaches it (the mount at threshold 0.4 measured 7.9° until its free needle, a 0.30 mm edge
  /// between two non-design points, was mended by splitting its long edge: 13.47°).
  double min_angle = 10.0;
};

/// The smallest angle asserted on the non-design solids' faces (issue 19 asks 10°): measured
/// 9.99° (bracket) to 14.3°; their points never move, flips within one plane only.
constexpr double kMinAngleNondesign = 9.5;

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
                          const Example& e) {
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
  // the non-design points are points of the unsmoothed surface, unmoved
  const TriSurface raw = extract_iso_surface(mesh, nd, threshold, SmoothParams{}.crossing_margin);
  std::set<std::array<double, 3>> fixed;
  for (long i = 0; i < raw.V.rows(); ++i)
    if (raw.lock[i] == 2) fixed.insert({raw.V(i, 0), raw.V(i, 1), raw.V(i, 2)});
  long moved = 0, locked = 0;
  for (long i = 0; i < s.V.rows(); ++i)
    if (s.lock[i] == 2) ++locked, moved += !fixed.count({s.V(i, 0), s.V(i, 1), s.V(i, 2)});
  EXPECT_GT(locked, 0);
  EXPECT_EQ(moved, 0);
}

void check_example(const Example& e) {
  const pipeline::Job job = example_job(e);
  const pipeline::RunResult run = pipeline::run_job(job);
  const pipeline::OptimizeResult& r = run.optimization;
  {
    SCOPED_TRACE(e.name + ": the volume's threshold, 20 smoothing pairs");
    check_design_surface(run.mesh, r.surface, r.design, r.threshold, e);
  }
  SCOPED_TRACE(e.name + ": threshold 0.4, 60 smoothing pairs");
  SmoothParams smooth;
  smooth.iterations = 60;
  VecXd design;
  const TriSurface s = pipeline::result_surface(run.mesh, r.simp.density, 0.4, 0.3, smooth, nullptr,
                                                pipeline::anchor_nodes(run.mesh, job), {}, nullptr, &design);
  check_design_surface(run.mesh, s, design, 0.4, e);
}

TEST(SurfaceExamples, Rocker) {
  check_example({"rocker", 3.0,
                 R"("supports": [{"type": "fixed", "faces": ["Face10"]}], "load_cases": [{"name": "rocker", "loads":
                  [{"type": "force", "faces": ["Face9"], "vector": [0, -1000, 0]},
                   {"type": "force", "faces": ["Face11"], "vector": [600, 0, 0]}]}])",
                 7.5});
}

TEST(SurfaceExamples, Cantilever) {
  check_example({"cantilever", 3.0,
                 R"("supports": [{"type": "fixed", "faces": ["Face1"]}], "load_cases": [{"name": "tip", "loads":
                  [{"type": "force", "faces": ["NonDesign:Face12"], "vector": [0, 0, -1000]}]}])",
                 9.0});
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
                 12.0});
}

}  // namespace
}  // namespace topopt::result
