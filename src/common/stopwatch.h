// Wall-clock laps for progress messages ("factorisation 0.41 s").
#pragma once
#include <chrono>
#include <string>

namespace topopt {

/// Measures laps of wall-clock time from its construction.
class Stopwatch {
 public:
  /// The time since the construction or the previous lap, as "<seconds> s", and starts the
  /// next lap.
  std::string lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - start_).count();
    start_ = now;
    return std::to_string(s) + " s";
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace topopt
