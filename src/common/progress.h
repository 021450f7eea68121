// Progress, cancellation and logging, passed in by the caller (CLI, Python, workbench).
// The core keeps no global state: every long-running function takes a `const Progress&`.
#pragma once
#include <functional>
#include <string>

#include "common/error.h"

namespace topopt {

enum class LogLevel { Debug, Info, Warning };

/// Callbacks a long-running computation reports through. Every member may be empty.
struct Progress {
  /// stage: short name ("mesh", "solve", "simp"); fraction in [0,1] or < 0 if unknown;
  /// message: one line for a status bar.
  std::function<void(const std::string& stage, double fraction, const std::string& message)> report;
  /// Returns true when the user asked to stop; checked at safe points.
  std::function<bool()> cancelled;
  /// Diagnostics for a log window or stderr.
  std::function<void(LogLevel level, const std::string& message)> log;

  void say(const std::string& stage, double fraction, const std::string& message) const {
    if (report) report(stage, fraction, message);
  }
  void info(const std::string& message) const {
    if (log) log(LogLevel::Info, message);
  }
  void warn(const std::string& message) const {
    if (log) log(LogLevel::Warning, message);
  }
  /// Throws Error(Cancelled) if the user asked to stop.
  void check_cancel(const std::string& where) const {
    if (cancelled && cancelled()) throw Error(ErrorCode::Cancelled, "cancelled during " + where);
  }
};

}  // namespace topopt
