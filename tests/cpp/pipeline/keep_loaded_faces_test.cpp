// keep_loaded_faces (issue 19): a tip load on the bare end face of a cantilever without a load
// pad. With the default the design keeps a solid layer on every loaded and supported face, so
// the result carries the whole end face and the verification runs; the option is named in a
// warning, and can be turned off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "mesh/core/structured_box.h"
#include "pipeline/job.h"
#include "pipeline/optimize_job.h"
#include "result/verification.h"

namespace topopt::pipeline {
namespace {

/// A 30 x 10 x 5 mm box in 2 mm cells, all design, fixed at Face1 (x = 0), pulled down by
/// 100 N on its bare end face Face2 (x = 30); 30 iterations at volume fraction 0.3.
Job bare_cantilever(bool keep) {
  Job job = parse_job(
      R"({"supports": [{"type": "fixed", "faces": ["Face1"]}],
          "load_cases": [{"name": "tip", "loads": [{"type": "force", "faces": ["Face2"], "vector": [0, -100, 0]}]}],
          "optimization": {"volume_fraction": 0.3, "max_iterations": 30, "keep_loaded_faces": )" +
          std::string(keep ? "true" : "false") + "}}",
      "/tmp");
  return job;
}

TetMesh bare_box() {
  mesh::StructuredBoxParams p;
  p.size = {30, 10, 5};
  p.cells = {15, 5, 3};
  return mesh::structured_box_mesh(p);
}

/// The area (mm²) of the result surface's triangles on Ω's face `face`.
double area_on(const result::TriSurface& s, int face) {
  double area = 0;
  for (long q = 0; q < s.F.rows(); ++q)
    if (s.tag[q] == face) {
      const Eigen::Vector3d a = s.V.row(s.F(q, 0)), b = s.V.row(s.F(q, 1)), c = s.V.row(s.F(q, 2));
      area += (b - a).cross(c - a).norm() / 2;
    }
  return area;
}

TEST(KeepLoadedFaces, TheLayerOnTheLoadedAndSupportedFacesIsTheirDesignTets) {
  const TetMesh mesh = bare_box();
  std::vector<int> on;
  const std::vector<char> layer = loaded_face_layer(mesh, {2}, &on);
  EXPECT_EQ(on, std::vector<int>{2});
  long count = 0;
  for (long t = 0; t < mesh.T.rows(); ++t) {
    bool touches = false;
    for (int k = 0; k < 4; ++k) touches |= std::abs(mesh.V(mesh.T(t, k), 0) - 30) < 1e-9;
    EXPECT_EQ(layer[t] != 0, touches) << "tet " << t;
    count += layer[t];
  }
  EXPECT_GT(count, 0);
  EXPECT_EQ(loaded_faces(bare_cantilever(true)), (std::vector<int>{1, 2}));
}

TEST(KeepLoadedFaces, ABareLoadedFaceKeepsItsMaterialAndTheVerificationRuns) {
  const TetMesh mesh = bare_box();
  const Job job = bare_cantilever(true);
  std::vector<std::string> warnings;
  Progress progress;
  progress.log = [&](LogLevel level, const std::string& m) {
    if (level == LogLevel::Warning) warnings.push_back(m);
  };
  const OptimizeResult r = optimize_job(job, mesh, progress);
  bool named = false;
  for (const std::string& w : warnings)
    named |= w.find("Face1, Face2 is kept solid") != std::string::npos &&
             w.find("\"optimization.keep_loaded_faces\": false") != std::string::npos;
  EXPECT_TRUE(named) << "no warning names the kept faces and the setting";
  // the layer stays solid: every tet touching the end face has density 1, and the result
  // holds the whole 10 x 5 end face and the whole support face
  for (long t = 0; t < mesh.T.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      if (std::abs(mesh.V(mesh.T(t, k), 0) - 30) < 1e-9) {
        EXPECT_EQ(r.simp.density[t], 1.0) << "tet " << t;
      }
  EXPECT_NEAR(area_on(r.surface, 2), 50, 0.5);
  EXPECT_NEAR(area_on(r.surface, 1), 50, 0.5);
  result::VerificationProblem problem{job.material, job.supports, job.load_cases};
  const result::Verification v = result::verify_result(r.surface, mesh, r.design, r.threshold, problem);
  EXPECT_GT(v.as_built.compliance, 0);
  EXPECT_GT(v.crisp.compliance, 0);
  EXPECT_NEAR(v.ratio(), 1.0, 0.3) << "as built " << v.as_built.compliance << ", crisp " << v.crisp.compliance;
}

TEST(KeepLoadedFaces, OffTheOptimisationIsFreeOnTheLoadedFace) {
  const TetMesh mesh = bare_box();
  std::vector<std::string> warnings;
  Progress progress;
  progress.log = [&](LogLevel level, const std::string& m) {
    if (level == LogLevel::Warning) warnings.push_back(m);
  };
  const OptimizeResult r = optimize_job(bare_cantilever(false), mesh, progress);
  for (const std::string& w : warnings) EXPECT_EQ(w.find("kept solid"), std::string::npos) << w;
  // design tets on the end face take what SIMP gives them (some are grey or void)
  double lowest = 1;
  for (long t = 0; t < mesh.T.rows(); ++t)
    for (int k = 0; k < 4; ++k)
      if (std::abs(mesh.V(mesh.T(t, k), 0) - 30) < 1e-9) lowest = std::min(lowest, r.simp.density[t]);
  EXPECT_LT(lowest, 0.5);
}

}  // namespace
}  // namespace topopt::pipeline
