// Sub-commands of build/topopt. Each takes the arguments after its name and returns the exit
// code; a topopt::Error escaping one is printed by main with its code.
#pragma once
#include <string>
#include <vector>

#include "brep/foreign.h"

namespace topopt::cli {

using Args = std::vector<std::string>;

int cmd_info(const Args& args);
int cmd_mesh(const Args& args);
int cmd_solve(const Args& args);
int cmd_optimize(const Args& args);
int cmd_surface(const Args& args);
/// topopt worker REQUEST.json: one request of the FreeCAD workbench, run out of FreeCAD's process
/// (JSON lines on stdout, results in files; see cmd_worker.cpp and worker_channel.h).
int cmd_worker(const Args& args);

/// Small argument reader shared by the sub-commands: `--name value` options, `--flag`
/// switches and positionals. Unknown options are an error with the usage text.
class ArgReader {
 public:
  ArgReader(const Args& args, std::string usage);
  /// Value of --name, or `fallback` if absent. Throws InvalidParameter if given without a value.
  std::string option(const std::string& name, const std::string& fallback = "");
  /// Value of --name as a finite number, or `fallback` if absent. Throws InvalidParameter
  /// for anything else ("abc", "nan", "inf").
  double number(const std::string& name, double fallback);
  /// --time-budget S: the seconds allowed for reading, or checking and healing, one input
  /// (brep::ForeignParams::seconds; absent or 0: from the input's size).
  brep::ForeignParams time_budget();
  bool flag(const std::string& name);
  bool has(const std::string& name) const;
  /// Remaining positional arguments; call after every option and flag has been read.
  /// Throws InvalidParameter naming any option that was not consumed.
  std::vector<std::string> positionals();
  bool wants_help() const { return help_; }
  /// When --help was given: prints the usage to stdout and returns true (the command returns 0).
  bool print_help() const;
  const std::string& usage() const { return usage_; }

 private:
  std::vector<std::string> args_;
  std::vector<bool> used_;
  std::string usage_;
  bool help_ = false;
};

}  // namespace topopt::cli
