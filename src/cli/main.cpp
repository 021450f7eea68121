// build/topopt: meshing, analysis and topology optimisation from the shell.
#include <sys/resource.h>
#include <OSD.hxx>
#include <Standard_Failure.hxx>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "brep/occt_guard.h"
#include "cli/commands.h"
#include "common/cpu_time.h"
#include "common/error.h"
#include "pipeline/output_files.h"
#ifdef TOPOPT_WITH_PETSC
#include "dist/dist_run.h"
#include "dist/mpi_session.h"
#endif

namespace topopt::cli {

namespace {
/// The first of the environment variables `names` that holds a whole number, or `fallback`.
int environment_number(std::initializer_list<const char*> names, int fallback) {
  for (const char* name : names)
    if (const char* v = std::getenv(name)) {
      char* end = nullptr;
      const long n = std::strtol(v, &end, 10);
      if (end != v && *end == 0 && n >= 0) return static_cast<int>(n);
    }
  return fallback;
}
}  // namespace

int launched_ranks() {
  return std::max(1, environment_number({"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "SLURM_STEP_NUM_TASKS"}, 1));
}

int launched_rank() { return environment_number({"OMPI_COMM_WORLD_RANK", "PMI_RANK", "SLURM_PROCID"}, 0); }

void write_stats_file(const std::string& path, const std::string& json_text) {
  if (path.empty()) return;
  pipeline::write_replacing(path, [&](const std::string& temporary) {
    std::ofstream f(temporary);
    f << json_text << "\n";
    if (!f) throw Error(ErrorCode::Io, "cannot write --stats " + path + " (disk full?)");
  });
}

std::string serial_stats_json(long tets, double seconds_run) {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  nlohmann::json j;
  j["ranks"] = 1;
  const double cpu = process_cpu_seconds();
  j["per_rank"] = {{{"rank", 0},
                    {"tets", tets},
                    {"seconds_run", seconds_run},
                    {"cpu_seconds", cpu},
                    {"peak_mb", usage.ru_maxrss / 1e3}}};
  return j.dump(2);
}

std::string amg_option(ArgReader& reader) {
  const std::string amg = reader.option("amg", "gamg");
  if (amg != "gamg" && amg != "boomeramg")
    throw Error(ErrorCode::InvalidParameter, "--amg takes gamg or boomeramg, not '" + amg + "'");
  return amg;
}

ArgReader::ArgReader(const Args& args, std::string usage)
    : args_(args), used_(args.size(), false), usage_(std::move(usage)) {
  for (size_t i = 0; i < args_.size(); ++i)
    if (args_[i] == "--help" || args_[i] == "-h") help_ = true, used_[i] = true;
}

std::string ArgReader::option(const std::string& name, const std::string& fallback) {
  for (size_t i = 0; i < args_.size(); ++i) {
    if (args_[i] != "--" + name) continue;
    if (i + 1 >= args_.size()) throw Error(ErrorCode::InvalidParameter, "--" + name + " needs a value\n" + usage_);
    used_[i] = used_[i + 1] = true;
    return args_[i + 1];
  }
  return fallback;
}

double ArgReader::number(const std::string& name, double fallback) {
  std::string s = option(name);
  if (s.empty()) return fallback;
  try {
    size_t end = 0;
    double v = std::stod(s, &end);
    if (end != s.size() || !std::isfinite(v)) throw std::invalid_argument(s);
    return v;
  } catch (const std::exception&) {
    throw Error(ErrorCode::InvalidParameter, "--" + name + " takes a finite number, not '" + s + "'");
  }
}

brep::ForeignParams ArgReader::time_budget() {
  brep::ForeignParams p;
  p.seconds = number("time-budget", 0);
  if (p.seconds < 0)
    throw Error(ErrorCode::InvalidParameter,
                "--time-budget takes the seconds allowed for reading or checking one input (0: from its size)");
  return p;
}

bool ArgReader::print_help() const {
  if (help_) std::cout << usage_ << "\n";
  return help_;
}

bool ArgReader::flag(const std::string& name) {
  for (size_t i = 0; i < args_.size(); ++i)
    if (args_[i] == "--" + name) return used_[i] = true;
  return false;
}

bool ArgReader::has(const std::string& name) const {
  for (const auto& a : args_)
    if (a == "--" + name) return true;
  return false;
}

std::vector<std::string> ArgReader::positionals() {
  std::vector<std::string> out;
  for (size_t i = 0; i < args_.size(); ++i) {
    if (used_[i]) continue;
    if (args_[i].rfind("--", 0) == 0)
      throw Error(ErrorCode::InvalidParameter, "unknown option " + args_[i] + "\n" + usage_);
    out.push_back(args_[i]);
  }
  return out;
}

}  // namespace topopt::cli

namespace {

const char* kUsage =
    "usage: topopt <command> [options]\n"
    "commands:\n"
    "  info      check the part and non-design solids; print topology and classification\n"
    "  mesh      mesh part and non-design solids into one tagged tetrahedral mesh\n"
    "  surface   native surface mesh of one model, with its checks (closed, oriented, no self-intersection)\n"
    "  solve     linear elastic analysis of a job file\n"
    "  optimize  topology optimisation of a job file: mesh, SIMP, result surface\n"
    "  result    the result of a finished optimize at another threshold, as STEP (and STL)\n"
    "  worker    one request of the FreeCAD workbench, run out of FreeCAD's process\n"
    "Run 'topopt <command> --help' for a command's options.\n";

/// Exit codes: 0 success, 1 user error (message printed), 2 usage, 3 internal error.
int exit_code_for(topopt::ErrorCode code) {
  switch (code) {
    case topopt::ErrorCode::InvalidParameter:
      return 2;
    case topopt::ErrorCode::Internal:
      return 3;
    default:
      return 1;
  }
}

void print_error(const char* command, const topopt::Error& e) {
  std::cerr << "topopt " << command << ": error (" << topopt::error_code_name(e.code()) << "): " << e.what() << "\n";
}

/// Runs one sub-command; every failure becomes a message and an exit code. OCCT's failures
/// (and access violations caught by its handler) are put in words by brep::occt_error.
int run_command(const std::function<int(const topopt::cli::Args&)>& command, const topopt::cli::Args& args,
                const char* name) {
  try {
    OCC_CATCH_SIGNALS
    return command(args);
  } catch (const topopt::Error& e) {
    print_error(name, e);
    return exit_code_for(e.code());
  } catch (const Standard_Failure& failure) {
    const topopt::Error e = topopt::brep::occt_error(failure, std::string("the ") + name + " command");
    print_error(name, e);
    return exit_code_for(e.code());
  } catch (const std::bad_alloc&) {
    std::cerr << "topopt " << name << ": out of memory: use a coarser mesh size\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "topopt " << name << ": internal error: " << e.what() << "\n";
    return 3;
  }
}

#ifdef TOPOPT_MPI_COMPANION
/// The serial `topopt` under mpirun: replaces this process by the PETSc-linked companion
/// (TOPOPT_MPI_COMPANION, built next to this executable) with the same arguments, so that the
/// launcher's rank and environment carry over. Returns only when that fails, with the message
/// for the user. argv: main's, null-terminated.
std::string hand_over_to_companion(char** argv) {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return "cannot find this executable's folder (/proc/self/exe) to start " TOPOPT_MPI_COMPANION;
  const std::string companion = (self.parent_path() / TOPOPT_MPI_COMPANION).string();
  std::vector<char*> arguments{const_cast<char*>(companion.c_str())};
  for (char** a = argv + 1; *a; ++a) arguments.push_back(*a);
  arguments.push_back(nullptr);
  ::execv(companion.c_str(), arguments.data());
  return "cannot start " + companion + " (" + std::strerror(errno) +
         "), the build of topopt that runs on several MPI ranks: rebuild (scripts/build) or run without mpirun";
}
#endif

/// mpirun -np N topopt COMMAND ...: solve and optimize on all ranks (rank 0 reads, meshes and
/// writes; the others serve its runs); the serial build hands them over to its PETSc-linked
/// companion (topopt-mpi). Any other command, or a build without PETSc, is refused with a
/// message from rank 0 and exit code 2 on every rank.
int run_on_ranks(int argc, char** argv) {
  using namespace topopt::cli;
  const char* name = argv[1];
  const Args args(argv + 2, argv + argc);
  const bool distributable = !std::strcmp(name, "solve") || !std::strcmp(name, "optimize");
#ifdef TOPOPT_MPI_COMPANION
  if (distributable) {
    const std::string why = hand_over_to_companion(argv);
    if (launched_rank() == 0) std::cerr << "topopt " << name << ": " << why << "\n";
    return 2;
  }
#endif
#ifdef TOPOPT_WITH_PETSC
  if (distributable) {
    // an error inside a run, on any rank, is printed by that rank as a serial run prints it
    // (with the rank), then ends every rank with its exit code
    const topopt::dist::MpiSession session([name](std::exception_ptr failure, int rank) {
      const std::string label = std::string(name) + " (MPI rank " + std::to_string(rank) + ")";
      return run_command([&](const Args&) -> int { std::rethrow_exception(failure); }, {}, label.c_str());
    });
    if (session.rank() != 0) {
      // --test-fail-after-distribution: a test hook, not in the usage (dist_run.h, ServeParams)
      topopt::dist::ServeParams serve;
      serve.fail_after_distribution =
          std::find(args.begin(), args.end(), "--test-fail-after-distribution") != args.end();
      topopt::dist::serve_ranks(session, serve);
      return 0;
    }
    const bool solve = !std::strcmp(name, "solve");
    const int code = run_command(
        [&](const Args& a) { return solve ? cmd_solve(a, &session) : cmd_optimize(a, &session); }, args, name);
    topopt::dist::release_ranks(session);
    return code;
  }
#endif
  if (launched_rank() == 0) {
    if (!distributable)
      std::cerr << "topopt " << name << ": only solve and optimize run on several MPI ranks; run '" << name
                << "' without mpirun\n";
    else
      std::cerr << "topopt " << name << ": this topopt was built without MPI (PETSc was not found when it was "
                << "built), so it cannot run on " << launched_ranks() << " ranks: run it without mpirun, or install "
                << "petsc-dev (scripts/setup) and rebuild (scripts/build)\n";
  }
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace topopt::cli;
  use_huge_pages_in_cholmod();
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    std::cout << kUsage;
    return argc < 2 ? 2 : 0;
  }
  const std::map<std::string, int (*)(const Args&)> commands{
      {"info", cmd_info},
      {"mesh", cmd_mesh},
      {"solve", [](const Args& a) { return cmd_solve(a, nullptr); }},
      {"optimize", [](const Args& a) { return cmd_optimize(a, nullptr); }},
      {"surface", cmd_surface},
      {"result", cmd_result},
      {"worker", cmd_worker}};
  auto it = commands.find(argv[1]);
  if (it == commands.end()) {
    std::cerr << "topopt: unknown command '" << argv[1] << "'\n" << kUsage;
    return 2;
  }
  // OCCT's signal handler: an access violation on this thread becomes an exception at the
  // nearest OCC_CATCH_SIGNALS (here, or brep::guard_occt's), reported as an error below.
  // No floating-point traps: the core relies on IEEE arithmetic. Foreign geometry is read in
  // child processes that reset these handlers (brep/foreign.h).
  OSD::SetSignal(Standard_False);
  if (launched_ranks() > 1) return run_on_ranks(argc, argv);
  return run_command(it->second, Args(argv + 2, argv + argc), argv[1]);
}
