// The optimisation path shared by `topopt optimize` and the Python module's run_job:
// a job's mesh → SIMP → the result surface at the volume-matching threshold → smoothing.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "common/progress.h"
#include "io/job.h"
#include "result/iso_surface.h"
#include "result/smoothing.h"
#include "simp/optimizer.h"

namespace topopt::pipeline {

/// The "optimization" section of a job (docs/optimization.md), validated.
struct OptimizeSettings {
  simp::SimpParams simp;
  double threshold = -1;  ///< < 0: the one that meets the volume fraction
  result::SmoothParams smooth;
};

/// Reads job.raw["optimization"]. Throws Error(InvalidParameter) naming a bad key.
OptimizeSettings optimize_settings(const io::Job& job);

struct OptimizeResult {
  simp::SimpResult simp;
  double threshold = 0;
  result::TriSurface surface;  ///< smoothed, closed
  double seconds_simp = 0, seconds_surface = 0;
};

/// Runs SIMP on `mesh` with the job's supports and loads, then extracts and smooths the
/// shape. on_iteration gets every iteration. Throws what fem and simp throw (NoSupport,
/// InvalidParameter, Cancelled).
OptimizeResult optimize_job(const io::Job& job, const TetMesh& mesh, const Progress& progress = {},
                            const std::function<void(const simp::IterationRecord&)>& on_iteration = {});

/// The result shape of given element densities at a threshold (< 0: the one that keeps
/// `volume_fraction` of the design domain), smoothed.
result::TriSurface result_surface(const TetMesh& mesh, const VecXd& density, double threshold, double volume_fraction,
                                  const result::SmoothParams& smooth, double* threshold_used = nullptr);

/// Writes DIR/density.vtu, DIR/history.csv, DIR/history.json and DIR/result.stl.
/// Returns the paths written.
std::vector<std::string> write_optimize_outputs(const TetMesh& mesh, const OptimizeResult& r, const std::string& dir);

}  // namespace topopt::pipeline
