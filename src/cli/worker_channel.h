// The worker's side of its line protocol with the FreeCAD workbench (topopt worker): one JSON
// object per line on the worker's stdout, and the test-only fault injection that makes the
// worker crash, abort or hang at a chosen stage.
#pragma once
#include <cstdio>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/progress.h"
#include "simp/optimizer.h"

namespace topopt::cli {

/// A fault to inject, read from TOPOPT_FAULT=STAGE[/WORD]:KIND (for tests only): when the
/// worker reports progress of STAGE ("read", "brep", "mesh", "simp", "surface", "write") whose
/// message starts with WORD (any message if no WORD is given), it sends that line and then
/// aborts (KIND "abort"), dies by an access violation ("segv") or stops answering ("hang").
struct FaultPlan {
  std::string stage;  ///< empty: no fault
  std::string word;
  std::string kind;
  /// True when a progress line of `stage` with `message` is where the fault goes.
  bool matches(const std::string& stage, const std::string& message) const;
};

/// The plan in TOPOPT_FAULT, or an empty plan when the variable is unset or empty. Throws
/// Error(InvalidParameter) for a malformed value, naming the expected form.
FaultPlan fault_from_environment();

/// Writes the protocol's lines. Constructing it takes stdout over: the protocol keeps a
/// private copy of the stdout descriptor and file descriptor 1 is pointed at stderr, so that
/// nothing the core or its libraries print can break a line. Lines (each flushed at once):
///   {"stage": S, "fraction": F, "message": M}           progress of a stage
///   {"iteration": I, "compliance": C, "volume": V, "change": D, "seconds": T}   (stage "simp")
///   {"warning": M}                                       a warning of the core
///   {"done": true}                                       the last line on success
///   {"error": {"code": K, "message": M, "stage": S}}     the last line on failure
/// Thread-safe: progress may come from any thread of the core.
class WorkerChannel {
 public:
  WorkerChannel();
  ~WorkerChannel();
  WorkerChannel(const WorkerChannel&) = delete;
  WorkerChannel& operator=(const WorkerChannel&) = delete;

  void progress(const std::string& stage, double fraction, const std::string& message);
  void iteration(const simp::IterationRecord& rec);
  void warning(const std::string& message);
  void done();
  void error(const std::string& code, const std::string& message);

  /// A Progress whose reports and warnings become lines (the core's per-iteration "simp"
  /// reports are left to iteration()); warnings are also appended to `warnings`.
  Progress make_progress(std::vector<std::string>& warnings);

  /// Makes the channel inject `fault` when its stage is reported (tests only).
  void inject_at(FaultPlan fault) { fault_ = std::move(fault); }

  /// The stage of the last progress line ("start" before any).
  std::string stage() const;

 private:
  void send(const nlohmann::json& line, const std::string& stage, const std::string& message);

  FILE* out_ = nullptr;
  mutable std::mutex mutex_;
  std::string stage_ = "start";
  FaultPlan fault_;
};

}  // namespace topopt::cli
