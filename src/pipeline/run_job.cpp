// The one run path (see run_job.h).
#include "pipeline/run_job.h"

#include <chrono>

#include "common/error.h"
#include "pipeline/output_files.h"

namespace topopt::pipeline {

RunResult run_job(const Job& job, const JobShapes& shapes, const Progress& progress,
                  const std::function<void(const simp::IterationRecord&)>& on_iteration, const RunOptions& options) {
  require_supports_and_loads(job);
  if (options.write_outputs) prepare_output_folder(job.output.directory, "'output.directory' (or --out-dir)");
  RunResult r;
  Progress watched = progress;  // keeps the warnings for the result, and still passes them on
  watched.log = [&r, &progress](LogLevel level, const std::string& message) {
    if (level == LogLevel::Warning) r.warnings.push_back(message);
    if (progress.log) progress.log(level, message);
  };
  const auto t0 = std::chrono::steady_clock::now();
  r.mesh = job_mesh(job, shapes, watched, &r.mesh_run);
  if (shapes.part.IsNull() && !job.mesh.file.empty()) r.mesh_run.mesher = "file";
  r.seconds_mesh = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  watched.say("mesh", 1, std::to_string(r.mesh.V.rows()) + " nodes, " + std::to_string(r.mesh.T.rows()) + " tets");
  watched.check_cancel("meshing");
  r.source = source_faces(job, shapes, watched);  // once: the surface and result.step use them
  r.optimization = optimize_job(job, r.mesh, watched, on_iteration, options.simp, &r.source);
  r.optimization.ranks = options.ranks;
  if (!options.write_outputs) return r;
  r.written = write_optimize_outputs(r.mesh, r.optimization, job.output.directory);
  r.files =
      write_result_files(job, r.mesh, r.optimization, job.output.directory, options.result_files, watched, r.source);
  r.written.insert(r.written.end(), r.files.written.begin(), r.files.written.end());
  return r;
}

}  // namespace topopt::pipeline
