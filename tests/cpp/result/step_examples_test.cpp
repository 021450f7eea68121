// The result's STEP on a shared example (the rocker at 3 mm, the load case of
// ../shared/data/README.md): written, read back by OCCT as valid solids, one per body, with the
// volume of the result surface (the STL) within 0.5 %, and compact: about half as many faces
// as the surface has triangles (Ω's and the non-design solids' planar faces merged), no 2D curves,
// and the input's bores and bosses as cylinders of the input's radius and axis. The bundled
// lever example is one piece and reads back as one solid.
#include <gtest/gtest.h>

#include <BRep_Tool.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <cstdlib>
#include <filesystem>
#include <gp_Lin.hxx>

#include "pipeline/job.h"
#include "pipeline/result_files.h"
#include "pipeline/run_job.h"
#include "result/step_export.h"
#include "result/step_export_analytic.h"
#include "result/verification.h"

namespace topopt::result {
namespace {

/// The cylindrical faces of `shape` and how many of them have the radius and the axis of one of
/// the input's cylinders (`source`, within 1e-6 mm and 1e-9 rad).
std::pair<int, int> cylinders_of_the_input(const TopoDS_Shape& shape, const SourceFaces& source) {
  std::pair<int, int> n{0, 0};
  for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next()) {
    const auto c = Handle(Geom_CylindricalSurface)::DownCast(BRep_Tool::Surface(TopoDS::Face(e.Current())));
    if (c.IsNull()) continue;
    ++n.first;
    for (int id = 0; id < source.size(); ++id) {
      const auto in = Handle(Geom_CylindricalSurface)::DownCast(source.surface(id));
      if (!in.IsNull() && std::abs(in->Radius() - c->Radius()) < 1e-6 &&
          in->Axis().Direction().IsParallel(c->Axis().Direction(), 1e-9) &&
          gp_Lin(in->Axis()).Distance(c->Axis().Location()) < 1e-6) {
        ++n.second;
        break;
      }
    }
  }
  return n;
}

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
  const SourceFaces source = pipeline::source_faces(job);
  const StepExportReport written = write_result_step(path, s, {}, {}, &source);
  EXPECT_TRUE(written.valid);
  EXPECT_LT(written.triangles, s.F.rows());  // the free-form region was coarsened
  STEPControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  const StepExportReport back = describe_solid(reader.OneShape());
  EXPECT_TRUE(back.valid) << solid_faults(reader.OneShape());
  EXPECT_EQ(back.solids, result_bodies(s));
  EXPECT_EQ(back.faces, written.faces);
  // the bores and bosses the result keeps are cylinders of the input's radius and axis
  // (measured at 3 mm: 14, all of the input, none left as facets)
  EXPECT_EQ(back.analytic_faces, written.analytic_faces);
  const auto [cylinders, of_the_input] = cylinders_of_the_input(reader.OneShape(), source);
  EXPECT_GE(cylinders, 4);
  EXPECT_EQ(of_the_input, cylinders);
  EXPECT_LE(written.analytic_refused, 2);
  const double stl_volume = check_surface(s.V, s.F).volume;
  EXPECT_NEAR(back.volume, stl_volume, 0.005 * stl_volume);
  // compact: Ω's and the non-design planar faces merged, the cylinders one face each (measured
  // 1 276 faces, 14 of them on the input's cylinders, from 11 168 triangles), no 2D curves on
  // the planes (measured 1 256 bytes per face: fewer faces than with the cylinders as facets,
  // each with longer wires)
  RecordProperty("faces", back.faces);
  RecordProperty("analytic_faces", back.analytic_faces);
  RecordProperty("analytic_refused", written.analytic_refused);
  RecordProperty("triangles", static_cast<int>(s.F.rows()));
  RecordProperty("bytes", static_cast<int>(written.bytes));
  EXPECT_LT(back.faces, 0.2 * s.F.rows());
  EXPECT_LT(written.bytes, 1400L * back.faces);
  std::filesystem::remove(path);
}

TEST(StepExamples, TheLeverIsOnePieceAndReadsBackAsOneSolid) {
  // the bundled example's job as scripts/run-example runs it, on one thread as measured (issue
  // 19: its result.step held a second solid, a 10 mm³ crumb around one node whose density
  // reached the threshold while every tet around it averaged below it, which the design
  // hygiene's crisp tets did not see). The user's first result is also converged (it stopped
  // at its 60-iteration cap) and verified: the result solid's compliance within 10 % of the
  // crisp design's (it was 782 against 937 N·mm, 0.83, on a 3 mm mesh whose members were one
  // tet thick for the 4 mm filter; the job's filter is now 6 mm)
  setenv("OMP_NUM_THREADS", "1", 1);
  const pipeline::Job job = pipeline::read_job(std::string(TOPOPT_EXAMPLES) + "/lever.topopt.json");
  const pipeline::RunResult run = pipeline::run_job(job);
  EXPECT_TRUE(run.optimization.simp.converged) << run.optimization.simp.status;
  const TriSurface& s = run.optimization.surface;
  EXPECT_EQ(result_bodies(s), 1);
  const Verification v = verify_result(s, run.mesh, run.optimization.design, run.optimization.threshold,
                                       pipeline::verification_problem(job));
  EXPECT_TRUE(v.unheld_volumes.empty());
  EXPECT_NEAR(v.ratio(), 1.0, 0.10) << "as built " << v.as_built.compliance << ", crisp " << v.crisp.compliance;
  RecordProperty("as_built_over_crisp", std::to_string(v.ratio()));
  for (const std::string& w : run.warnings) RecordProperty("warning", w);
  const std::string path = (std::filesystem::temp_directory_path() / "topopt_step_examples_lever.step").string();
  const SourceFaces source = pipeline::source_faces(job);
  const StepExportReport written = write_result_step(path, s, {}, {}, &source);
  EXPECT_TRUE(written.valid);
  STEPControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  const StepExportReport back = describe_solid(reader.OneShape());
  EXPECT_TRUE(back.valid) << solid_faults(reader.OneShape());
  EXPECT_EQ(back.solids, 1);
  const double stl_volume = check_surface(s.V, s.F).volume;
  EXPECT_NEAR(back.volume, stl_volume, 0.005 * stl_volume);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace topopt::result
