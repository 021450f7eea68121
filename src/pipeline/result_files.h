// The result handed back to CAD and checked by analysis, after the optimisation's own files:
// DIR/result.step (the result as one solid, result/step_export.h), DIR/verification.vtu and
// DIR/verification.json (the result solid meshed and solved with the job's supports and loads
// next to the crisp design on the FE mesh, result/verification.h). Each step runs with a time
// budget and may fail on its own: what failed is named in a warning and in
// verification.json, and never costs the files already written.
#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/progress.h"
#include "pipeline/job.h"
#include "pipeline/job_mesh.h"
#include "pipeline/optimize_job.h"
#include "result/step_export.h"
#include "result/step_export_analytic.h"
#include "result/verification.h"

namespace topopt::pipeline {

struct ResultFilesParams {
  result::StepExportParams step;            ///< the STEP export's budget and merging
  result::VerificationParams verification;  ///< the verification's budget, mesher and solver
};

struct ResultFiles {
  std::vector<std::string> written;                  ///< paths written
  std::vector<std::string> warnings;                 ///< one per step that failed, naming it and why
  std::optional<result::StepExportReport> step;      ///< when result.step was written
  std::optional<result::Verification> verification;  ///< when the verification ran
  nlohmann::json report = nlohmann::json::object();  ///< verification.json as written last (step, figures, failed)
};

/// The input's curved analytic faces for the result surface and result.step
/// (result/step_export_analytic.h): those of `shapes` when given (the run's own shapes), else of
/// the job's part and non-design files read again; none (a warning through progress) when the
/// job names no part or its files cannot be read, so that the STEP is still written, with those
/// faces as facets. run_job makes them once per run (RunResult::source).
result::SourceFaces source_faces(const Job& job, const JobShapes& shapes = {}, const Progress& progress = {});

/// `params` with what the job's "output" section sets for the STEP export (its triangle budget).
result::StepExportParams step_params(const Job& job, result::StepExportParams params = {});

/// The job's problem (material, supports, load cases) as the verification solves it, and its stress
/// limit (optimization.stress_limit) the verification warns past.
result::VerificationProblem verification_problem(const Job& job);

/// Writes, as job.output asks (step, verification), DIR/result.step, DIR/verification.vtu and
/// DIR/verification.json for the optimisation `r` on the FE `mesh`; `dir` exists
/// (prepare_output_folder). verification.json is written whenever either step was asked for,
/// with what succeeded and the error of what failed. Warnings also go to progress.warn.
/// The input's curved faces (`source`: source_faces of the run) come back as analytic faces.
/// Throws only Error(Cancelled) when progress says so. The same as
/// write_result_step_first followed by add_verification.
ResultFiles write_result_files(const Job& job, const TetMesh& mesh, const OptimizeResult& r, const std::string& dir,
                               const ResultFilesParams& params = {}, const Progress& progress = {},
                               const result::SourceFaces& source = {});

/// The first part of write_result_files, for a caller that shows the result before it is
/// verified: DIR/result.step when job.output.step asks for it, and DIR/verification.json
/// holding its report (or why it failed) when either output was asked for. Returns the files
/// so far; add_verification continues them. Throws only Error(Cancelled).
ResultFiles write_result_step_first(const Job& job, const OptimizeResult& r, const std::string& dir,
                                    const ResultFilesParams& params = {}, const Progress& progress = {},
                                    const result::SourceFaces& source = {});

/// The second part: when job.output.verification asks for it, verifies `r`'s result solid
/// against the FE `mesh`, writes DIR/verification.vtu and adds the figures (or the failure)
/// to `files.report`, rewriting DIR/verification.json once with the first part's step report
/// and failures kept. `files`: what write_result_step_first returned for the same job, `r`
/// and `dir`. Throws only Error(Cancelled).
void add_verification(ResultFiles& files, const Job& job, const TetMesh& mesh, const OptimizeResult& r,
                      const std::string& dir, const ResultFilesParams& params = {}, const Progress& progress = {});

}  // namespace topopt::pipeline
