// The shared examples (cantilever, rocker, bracket, mount) through the whole job path with the default settings
// (projection with β continuation, hygiene), on coarse meshes at two volume fractions: the design ends crisp (grey ≤ 3
// % of the design volume) at full β, in one piece with no closed void (the non-design solids no load needs joined by
// bridges, result.join_non_design), with a measured thinnest member, and its surface is closed.
#include <gtest/gtest.h>

#include <string>

#include "pipeline/job.h"
#include "pipeline/optimize_job.h"
#include "pipeline/run_job.h"
#include "result/design_hygiene.h"
#include "result/iso_surface.h"

namespace topopt::pipeline {
namespace {

struct Example {
  std::string name;
  double size;                      // mesh size (mm)
  std::string problem;              // supports and load cases (../shared/data/README.md)
  bool some_solids_unused = false;  // non-design solids the loads leave unconnected (joined by bridges)
};

std::string job_text(const Example& e, double volume_fraction) {
  const std::string dir = std::string(TOPOPT_SHARED_DATA) + "/examples/";
  return R"({"part": ")" + dir + e.name + R"(.step", "nondesign": ")" + dir + e.name +
         R"(_nondesign.step", "mesh": {"size": )" + std::to_string(e.size) +
         R"(}, "optimization": {"volume_fraction": )" + std::to_string(volume_fraction) + "}, " + e.problem + "}";
}

/// Share of the design volume with 0.1 < ρ < 0.9.
double grey_share(const TetMesh& mesh, const VecXd& density) {
  double grey = 0, total = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    if (mesh.domain[t] != 0) continue;
    const Eigen::Vector3d a = mesh.V.row(mesh.T(t, 0)).transpose();
    const double v = std::abs((mesh.V.row(mesh.T(t, 1)).transpose() - a)
                                  .cross(mesh.V.row(mesh.T(t, 2)).transpose() - a)
                                  .dot(mesh.V.row(mesh.T(t, 3)).transpose() - a)) /
                     6;
    total += v;
    if (density[t] > 0.1 && density[t] < 0.9) grey += v;
  }
  return grey / total;
}

void check_crisp(const Example& e) {
  for (const double vf : {0.3, 0.45}) {
    SCOPED_TRACE(e.name + " at volume fraction " + std::to_string(vf));
    const Job job = parse_job(job_text(e, vf), "/tmp");
    const RunResult run = run_job(job);
    const OptimizeResult& r = run.optimization;
    // at full β at the end (converged, or at the iteration cap with the compliance creeping:
    // the coarse cantilever at 0.3 still gains 3e-4 per iteration at iteration 100)
    EXPECT_EQ(r.simp.history.back().beta, job.optimization.simp.projection.beta_max) << r.simp.status;
    EXPECT_LE(grey_share(run.mesh, r.simp.density), 0.03);
    // the design handed over is one piece with no closed void: cleaning it again finds nothing
    result::HygieneReport again;
    result::clean_design(run.mesh, r.design, r.threshold, anchor_nodes(run.mesh, job), {}, again);
    std::string said;
    for (const auto& w : r.hygiene.warnings) said += "\n  first: " + w;
    for (const auto& w : again.warnings) said += "\n  again: " + w;
    // one piece carries the loads and nothing is apart: the non-design solids the loads do not
    // need are joined by bridges (one warning each), and cleaning again makes no new one
    EXPECT_EQ(again.anchored_pieces, 1) << said;
    EXPECT_EQ(again.pieces, 1) << said;
    EXPECT_TRUE(again.apart.empty()) << said;
    EXPECT_TRUE(again.bridges.empty()) << said;
    if (!e.some_solids_unused) {
      EXPECT_TRUE(r.hygiene.bridges.empty()) << said;
    } else if (vf < 0.4) {
      EXPECT_FALSE(r.hygiene.bridges.empty()) << said;  // the solids the design left apart at 0.3
    }
    for (const auto& b : r.hygiene.bridges) EXPECT_TRUE(b.joined) << said;
    EXPECT_EQ(again.voids_filled, 0);
    EXPECT_GT(again.min_feature, 0);
    const result::SurfaceCheck check = result::check_surface(r.surface.V, r.surface.F);
    EXPECT_EQ(check.open_edges + check.overshared_edges + check.misoriented_edges, 0);
  }
}

TEST(CrispExamples, Cantilever) {
  check_crisp({"cantilever", 3.0,
               R"("supports": [{"type": "fixed", "faces": ["Face1"]}], "load_cases": [{"name": "tip", "loads":
                  [{"type": "force", "faces": ["NonDesign:Face12"], "vector": [0, 0, -1000]}]}])"});
}

TEST(CrispExamples, Rocker) {
  check_crisp({"rocker", 3.0,
               R"("supports": [{"type": "fixed", "faces": ["Face10"]}], "load_cases": [{"name": "rocker", "loads":
                  [{"type": "force", "faces": ["Face9"], "vector": [0, -1000, 0]},
                   {"type": "force", "faces": ["Face11"], "vector": [600, 0, 0]}]}])"});
}

TEST(CrispExamples, Bracket) {
  // the two clamp pads (no load on them here) carry nothing in these load cases, nor (at 0.3,
  // 2.5 and 5 mm) the bolt bosses 3 and 4: the design leaves them apart, bridges join them
  check_crisp({"bracket", 5.0,
               R"("supports": [{"type": "fixed", "faces": ["Face10", "Face11", "Face12", "Face13"]}], "load_cases":
                  [{"name": "x", "loads": [{"type": "force", "faces": ["Face7"], "vector": [5000, 0, 0]}]},
                   {"name": "z", "loads": [{"type": "force", "faces": ["Face7"], "vector": [0, 0, -5000]}]}])",
               true});
}

TEST(CrispExamples, Mount) {
  // bolt bores Face28-31 fixed; the lug's bore Face8: 10 000 N in -z, and separately 5 000 N in +y;
  // at 0.3 and 5 mm the design reaches only two of the four bolt bosses: solids 1 and 2 (a support
  // each, no load) are left apart, bridges join them
  check_crisp({"mount", 5.0,
               R"("supports": [{"type": "fixed", "faces": ["Face28", "Face29", "Face30", "Face31"]}], "load_cases":
                  [{"name": "down", "loads": [{"type": "force", "faces": ["Face8"], "vector": [0, 0, -10000]}]},
                   {"name": "side", "loads": [{"type": "force", "faces": ["Face8"], "vector": [0, 5000, 0]}]}])",
               true});
}

}  // namespace
}  // namespace topopt::pipeline
