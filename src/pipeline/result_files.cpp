// The result back in CAD and verified (see result_files.h).
#include "pipeline/result_files.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "brep/shape_io.h"
#include "common/error.h"
#include "io/vtu.h"
#include "pipeline/output_files.h"
#include "result/step_export_analytic.h"

namespace topopt::pipeline {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

json figures_json(const result::AnalysisFigures& a) {
  return {{"compliance", a.compliance},
          {"max_displacement", a.max_displacement},
          {"max_von_mises", a.max_von_mises},
          {"tets", a.tets},
          {"nodes", a.nodes},
          {"seconds", a.seconds},
          {"cpu_seconds", a.cpu_seconds}};
}

json step_json(const result::StepExportReport& s) {
  return {{"valid", s.valid},
          {"solids", s.solids},
          {"faces", s.faces},
          {"planar_faces", s.planar_faces},
          {"volume", s.volume},
          {"bytes", s.bytes},
          {"seconds", s.seconds},
          {"cpu_seconds", s.cpu_seconds},
          {"triangles", s.triangles},
          {"unmerged_bodies", s.unmerged_bodies},
          {"facet_bodies", s.facet_bodies},
          {"analytic_faces", s.analytic_faces},
          {"analytic_refused", s.analytic_refused}};
}

json verification_json(const result::Verification& v) {
  return {{"compliance_as_built", v.as_built.compliance},
          {"max_displacement", v.as_built.max_displacement},
          {"max_von_mises", v.as_built.max_von_mises},
          {"tets", v.as_built.tets},
          {"as_built", figures_json(v.as_built)},
          {"crisp", figures_json(v.crisp)},
          {"ratio", v.ratio()},
          {"crisp_carries_load", v.crisp_carries_load()},
          {"unheld_volumes", v.unheld_volumes}};
}

void write_verification_vtu(const std::string& path, const Job& job, const result::Verification& v) {
  std::vector<io::VtuField> points, cells;
  for (size_t c = 0; c < job.load_cases.size(); ++c) {
    io::VtuField u{"displacement_" + job.load_cases[c].name, 3, {}};
    u.values.assign(v.U.col(c).data(), v.U.col(c).data() + v.U.rows());
    points.push_back(std::move(u));
    io::VtuField vm{"von_mises_" + job.load_cases[c].name, 1, {}};
    vm.values.assign(v.von_mises[c].data(), v.von_mises[c].data() + v.von_mises[c].size());
    cells.push_back(std::move(vm));
  }
  io::write_vtu(path, v.mesh, points, cells);
}

/// Runs `step`; a topopt::Error or another exception becomes a warning "<what> failed: ..."
/// recorded in `failures[key]` (Cancelled is passed on). Returns whether it succeeded.
template <class Step>
bool attempt(const std::string& what, const std::string& key, Step&& step, ResultFiles& out, json& failures,
             const Progress& progress) {
  std::string why, code = "Internal";
  try {
    step();
    return true;
  } catch (const Error& e) {
    if (e.code() == ErrorCode::Cancelled) throw;
    why = e.what(), code = error_code_name(e.code());
  } catch (const std::exception& e) {
    why = e.what();
  }
  const std::string warning = what + " failed (" + code + "): " + why;
  out.warnings.push_back(warning);
  progress.warn(warning);
  failures[key] = {{"code", code}, {"message", why}};
  return false;
}

}  // namespace

result::SourceFaces source_faces(const Job& job, const JobShapes& shapes, const Progress& progress) {
  if (!shapes.part.IsNull()) return {shapes.part, shapes.nondesign};
  if (job.part.empty()) return {};
  try {
    const TopoDS_Shape part = brep::read_shape_file(job.part, "part");
    const TopoDS_Shape nondesign =
        job.nondesign.empty() ? TopoDS_Shape() : brep::read_shape_file(job.nondesign, "non-design input");
    return {part, nondesign};
  } catch (const Error& e) {
    progress.warn(std::string("the part's files could not be read again, so its curved faces stay facets in "
                              "result.step and the result surface adds no point on them: ") +
                  e.what());
    return {};
  }
}

result::StepExportParams step_params(const Job& job, result::StepExportParams params) {
  if (job.output.step_max_triangles >= 0) params.max_triangles = job.output.step_max_triangles;
  return params;
}

result::VerificationProblem verification_problem(const Job& job) {
  return {job.material, job.supports, job.load_cases, job.optimization.simp.responses.stress_limit};
}

namespace {

/// Writes files.report as DIR/verification.json (listed once in files.written).
void write_report(ResultFiles& files, const fs::path& dir) {
  const std::string path = write_replacing((dir / "verification.json").string(), [&](const std::string& p) {
    std::ofstream f(p);
    f << files.report.dump(2) << "\n";
    if (!f) throw Error(ErrorCode::Io, "cannot write verification.json (disk full?)");
  });
  if (std::find(files.written.begin(), files.written.end(), path) == files.written.end()) files.written.push_back(path);
}

}  // namespace

ResultFiles write_result_step_first(const Job& job, const OptimizeResult& r, const std::string& dir,
                                    const ResultFilesParams& params, const Progress& progress,
                                    const result::SourceFaces& source) {
  ResultFiles out;
  if (!job.output.step && !job.output.verification) return out;
  const fs::path d(dir);
  json& report = out.report;
  report["failed"] = json::object();
  if (job.output.step) {
    progress.say("step", -1, "writing the result as a STEP solid");
    attempt(
        "result.step (the result as a CAD solid)", "step",
        [&]() {
          const std::string path = (d / "result.step").string();
          out.written.push_back(write_replacing(path, [&](const std::string& p) {
            out.step = result::write_result_step(p, r.surface, step_params(job, params.step), progress, &source);
          }));
          out.step->bytes = static_cast<long>(fs::file_size(path));
          report["step"] = step_json(*out.step);
          report["step"]["threshold"] = r.threshold;  // the shape's: the workbench's slider may move away from it
        },
        out, report["failed"], progress);
  }
  write_report(out, d);
  return out;
}

void add_verification(ResultFiles& files, const Job& job, const TetMesh& mesh, const OptimizeResult& r,
                      const std::string& dir, const ResultFilesParams& params, const Progress& progress) {
  if (!job.output.verification) return;
  const fs::path d(dir);
  json& report = files.report;
  if (!report.contains("failed")) report["failed"] = json::object();
  progress.say("verification", -1, "meshing and solving the result solid");
  attempt(
      "the verification (the result solid meshed and analysed)", "verification",
      [&]() {
        files.verification = result::verify_result(r.surface, mesh, r.design, r.threshold, verification_problem(job),
                                                   params.verification, progress);
        report.update(verification_json(*files.verification));
        files.written.push_back(write_replacing((d / "verification.vtu").string(), [&](const std::string& p) {
          write_verification_vtu(p, job, *files.verification);
        }));
      },
      files, report["failed"], progress);
  write_report(files, d);
}

ResultFiles write_result_files(const Job& job, const TetMesh& mesh, const OptimizeResult& r, const std::string& dir,
                               const ResultFilesParams& params, const Progress& progress,
                               const result::SourceFaces& source) {
  ResultFiles out = write_result_step_first(job, r, dir, params, progress, source);
  add_verification(out, job, mesh, r, dir, params, progress);
  return out;
}

}  // namespace topopt::pipeline
