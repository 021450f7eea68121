// The one run path from a job to its results — mesh, SIMP, result surface, warnings, and on
// request the result files — used by `topopt optimize`, the Python module's run_job and the
// worker process alike, so that all of them do exactly the same thing. Its signature holds
// no CLI or Python types.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "common/progress.h"
#include "mesh/two_brep/native_mesher.h"
#include "pipeline/job.h"
#include "pipeline/job_mesh.h"
#include "pipeline/optimize_job.h"
#include "pipeline/result_files.h"

namespace topopt::pipeline {

struct RunOptions {
  /// Make and test job.output.directory before meshing, and write density.vtu,
  /// history.csv, history.json and result.stl into it at the end, then (as job.output asks)
  /// result.step, verification.vtu and verification.json (result_files.h: each may fail
  /// alone, with a warning, after the others are written).
  bool write_outputs = false;
  /// The SIMP run (empty: serial simp::optimize; under mpirun dist's optimize_on_ranks) and
  /// the number of ranks it runs on (history.json's "ranks").
  SimpRunner simp;
  int ranks = 1;
  ResultFilesParams result_files;  ///< budgets of the STEP export and the verification
};

struct RunResult {
  TetMesh mesh;                       ///< the job's mesh (nodes numbered to follow space)
  mesh::MeshRun mesh_run;             ///< the mesher used and its stages ("file" for mesh.file)
  double seconds_mesh = 0;            ///< meshing (or reading mesh.file) wall time
  result::SourceFaces source;         ///< the input's curved faces (source_faces): the surface's and result.step's
  OptimizeResult optimization;        ///< SIMP, threshold, smoothed surface, their times
  std::vector<std::string> warnings;  ///< what the run warned about (e.g. the Gmsh fallback)
  std::vector<std::string> written;   ///< the result files written (RunOptions::write_outputs)
  ResultFiles files;                  ///< the STEP export's and the verification's figures (write_outputs)
};

/// Runs `job`: checks that it has supports and loads (and, with options.write_outputs, that
/// its output folder can be written) before any work, meshes it (job_mesh: mesh.file, the
/// given `shapes`, or the job's part files), runs optimize_job with `on_iteration` called
/// after every iteration, and writes the outputs. Warnings go to `progress` and into the
/// result. Throws what those steps throw (each a topopt::Error that says what to change).
RunResult run_job(const Job& job, const JobShapes& shapes = {}, const Progress& progress = {},
                  const std::function<void(const simp::IterationRecord&)>& on_iteration = {},
                  const RunOptions& options = {});

}  // namespace topopt::pipeline
