// The result's STEP on a shared example (the rocker at 3 mm, the load case of
// ../shared/data/README.md): written, read back by OCCT as valid solids, one per body, with the
// volume of the result surface (the STL) within 0.5 %, and compact: about half as many faces
// as the surface has triangles (Ω's and the non-design solids' planar faces merged), no 2D curves.
#include <gtest/gtest.h>

#include <STEPControl_Reader.hxx>
#include <filesystem>

#include "pipeline/job.h"
#include "pipeline/run_job.h"
#include "result/step_export.h"

namespace topopt::result {
namespace {

TEST(StepExamples, RockerReadsBackAsOneValidCompactSolidOfTheStlsVolume) {
  const std::string dir = std::string(TOPOPT_SHARED_DATA) + "/examples/";
  const pipeline::Job job =
      pipeline::parse_job(R"({"part": ")" + dir + R"(rocker.step", "nondesign": ")" + dir +
                              R"(rocker_nondesign.step", "mesh": {"size": 3.0}, "optimization": {"volume_fraction": 0.3,
          "max_iterations": 40}, "supports": [{"type": "fixed", "faces": ["Face10"]}], "load_cases": [{"name": "rocker",
          "loads": [{"type": "force", "faces": ["Face9"], "vector": [0, -1000, 0]},
                    {"type": "force", "faces": ["Face11"], "vector": [600, 0, 0]}]}]})",
                          "/tmp");
  const pipeline::RunResult run = pipeline::run_job(job);
  const TriSurface& s = run.optimization.surface;
  const std::string path = (std::filesystem::temp_directory_path() / "topopt_step_examples_rocker.step").string();
  const StepExportReport written = write_result_step(path, s);
  EXPECT_TRUE(written.valid);
  EXPECT_LT(written.triangles, s.F.rows());  // the free-form region was coarsened
  STEPControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  const StepExportReport back = describe_solid(reader.OneShape());
  EXPECT_TRUE(back.valid) << solid_faults(reader.OneShape());
  EXPECT_EQ(back.solids, result_bodies(s));
  EXPECT_EQ(back.faces, written.faces);
  const double stl_volume = check_surface(s.V, s.F).volume;
  EXPECT_NEAR(back.volume, stl_volume, 0.005 * stl_volume);
  // compact: Ω's and the non-design planar faces merged (measured 5 636 faces from 11 180
  // triangles), and no 2D curves on the planes (measured 1 076 bytes per face; 2 480 with them)
  EXPECT_LT(back.faces, 0.55 * s.F.rows());
  EXPECT_LT(written.bytes, 1200L * back.faces);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace topopt::result
