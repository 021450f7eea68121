// Runs build/topopt as a user would and captures what it prints; shared by the CLI tests.
#pragma once
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <memory>
#include <string>

namespace topopt::testing {

struct CliResult {
  int code;         ///< exit status
  std::string out;  ///< stdout and stderr together
};

/// Runs `topopt <args>` through the shell (args are not quoted: keep paths simple); launcher,
/// when given, goes before it (e.g. "mpirun -np 2").
inline CliResult run_cli(const std::string& args, const std::string& launcher = "") {
  std::string cmd = (launcher.empty() ? "" : launcher + " ") + std::string(TOPOPT_CLI) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  size_t n;
  while (pipe && (n = fread(buf.data(), 1, buf.size(), pipe)) > 0) out.append(buf.data(), n);
  int status = pipe ? pclose(pipe) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace topopt::testing
