// The mesher choice and the isolated Gmsh fallback (see mesh_model.h).
#include "pipeline/mesh_model.h"

#include <sys/prctl.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>

#include "common/cpu_time.h"
#include "common/error.h"
#include "common/isolate.h"
#include "mesh/core/conformity.h"
#include "mesh/two_brep/gmsh_fragments.h"
#include "pipeline/mesh_bytes.h"

#if __has_include(<linux/landlock.h>)
#include <linux/landlock.h>
#endif

namespace topopt::pipeline {
namespace {

/// Refuses this process every later write to the file system (files already open, such as
/// the pipe to the parent, stay writable), where the kernel has Landlock. Only ever called
/// in a child process. Returns whether the kernel took the rule.
bool refuse_file_writes() {
#if defined(LANDLOCK_CREATE_RULESET_VERSION) && defined(SYS_landlock_create_ruleset)
  const long abi = ::syscall(SYS_landlock_create_ruleset, nullptr, 0, LANDLOCK_CREATE_RULESET_VERSION);
  if (abi < 1) return false;
  landlock_ruleset_attr attr{};
  attr.handled_access_fs = LANDLOCK_ACCESS_FS_WRITE_FILE | LANDLOCK_ACCESS_FS_REMOVE_DIR |
                           LANDLOCK_ACCESS_FS_REMOVE_FILE | LANDLOCK_ACCESS_FS_MAKE_CHAR | LANDLOCK_ACCESS_FS_MAKE_DIR |
                           LANDLOCK_ACCESS_FS_MAKE_REG | LANDLOCK_ACCESS_FS_MAKE_SOCK | LANDLOCK_ACCESS_FS_MAKE_FIFO |
                           LANDLOCK_ACCESS_FS_MAKE_BLOCK | LANDLOCK_ACCESS_FS_MAKE_SYM;
#ifdef LANDLOCK_ACCESS_FS_REFER
  if (abi >= 2) attr.handled_access_fs |= LANDLOCK_ACCESS_FS_REFER;
#endif
#ifdef LANDLOCK_ACCESS_FS_TRUNCATE
  if (abi >= 3) attr.handled_access_fs |= LANDLOCK_ACCESS_FS_TRUNCATE;
#endif
  const long fd = ::syscall(SYS_landlock_create_ruleset, &attr, sizeof attr, 0);
  if (fd < 0) return false;
  const bool ok = ::prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) == 0 &&
                  ::syscall(SYS_landlock_restrict_self, static_cast<int>(fd), 0) == 0;
  ::close(static_cast<int>(fd));
  return ok;
#else
  return false;
#endif
}

/// Gmsh starts FLTK, which rewrites its preference files under $HOME/.fltk (and, for root,
/// /etc/fltk), and Gmsh itself removes $HOME/.gmsh-tmp. In the child: HOME names no folder
/// that can exist, and writes are refused where the kernel allows it.
void keep_gmsh_from_writing_files() {
  ::setenv("HOME", "/dev/null", 1);
  refuse_file_writes();
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The native mesher stopped after `seconds` of computing: it checks its Progress's
/// cancelled() at safe points in every stage's loop, and here that also answers yes once the
/// budget is spent; such a stop becomes Error(Timeout) naming the budget and the stage.
TetMesh mesh_native_within(const brep::TwoBReps& model, const MeshSettings& settings, const MeshSizes& sizes,
                           const Progress& progress, mesh::MeshRun* run) {
  const double seconds = native_time_budget(settings, sizes);
  const double end = process_cpu_seconds() + seconds;  // all threads
  std::atomic<bool> expired{false};
  Progress timed = progress;
  timed.cancelled = [&progress, &expired, end] {
    if (progress.cancelled && progress.cancelled()) return true;
    if (process_cpu_seconds() > end) expired = true;
    return expired.load();
  };
  try {
    return mesh::mesh_native(model, native_mesh_params(settings, sizes), timed, run);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::Cancelled || !expired.load()) throw;
    const std::string what = e.what();  // "cancelled during <stage>" (Progress::check_cancel)
    const size_t at = what.find("during ");
    const std::string stage = at == std::string::npos ? what : what.substr(at + 7);
    throw Error(ErrorCode::Timeout,
                "the native mesher did not finish within its time budget of " +
                    std::to_string(static_cast<long>(std::ceil(seconds))) + " s of computing (for about " +
                    std::to_string(static_cast<long>(sizes.estimated_tets)) +
                    " tets at this size) and was stopped in " + stage + ": give a larger mesh size, or mesh with Gmsh");
  }
}

/// The native mesher; under "auto" its failure (a timeout included) comes back in `reason`
/// instead of as an error, but a cancel or a mesh too large for memory (Gmsh's would not fit
/// either).
bool try_native(const brep::TwoBReps& model, const MeshSettings& settings, const MeshSizes& sizes,
                const Progress& progress, mesh::MeshRun* run, TetMesh& out, std::string& reason) {
  const bool fallback = settings.mesher == Mesher::Auto;
  try {
    out = mesh_native_within(model, settings, sizes, progress, run);
    return true;
  } catch (const Error& e) {
    if (!fallback || e.code() == ErrorCode::Cancelled || e.code() == ErrorCode::TooLarge) throw;
    reason = e.what();
  } catch (const std::exception& e) {  // a bug in the native mesher: Gmsh may still mesh the part
    if (!fallback) throw;
    reason = e.what();
  }
  return false;
}

/// Gmsh in its child; under "auto" (a non-empty native failure) a crash or timeout names both.
TetMesh gmsh(const brep::TwoBReps& model, const MeshSettings& settings, const MeshSizes& sizes,
             const std::string& native_failure, const Progress& progress, mesh::MeshRun* run) {
  const auto t0 = std::chrono::steady_clock::now();
  TetMesh m;
  try {
    m = mesh_with_gmsh_isolated(model, gmsh_mesh_params(settings, sizes), gmsh_time_budget(settings, sizes), progress);
  } catch (const Error& e) {
    if (native_failure.empty() || e.code() == ErrorCode::Cancelled) throw;
    throw Error(e.code(), "the native mesher could not mesh this part (" + native_failure +
                              "), and the Gmsh fallback failed too: " + e.what());
  }
  if (run) {
    run->mesher = settings.gmsh_volume_by_front ? "gmsh surfaces + native volumes" : "gmsh";
    run->seconds = {{"gmsh fragments, surface and volume", seconds_since(t0)}};
  }
  // the same check as the native mesher's own (mesh::mesh_native): no mesh leaves unchecked
  const auto t1 = std::chrono::steady_clock::now();
  mesh::ConformityParams cp;
  cp.volume_tolerance = 0.05;  // gross errors only: the faceting of curved faces is not one
  mesh::require_valid_mesh(mesh::check_conformity(m, &model, cp), "the mesh made by Gmsh");
  if (run) run->seconds.push_back({"conformity check", seconds_since(t1)});
  return m;
}

}  // namespace

TetMesh mesh_with_gmsh_isolated(const brep::TwoBReps& model, const mesh::FragmentMeshParams& params, double seconds,
                                const Progress& progress) {
  const pid_t parent = ::getpid();
  progress.say("mesh", -1,
               "meshing with Gmsh (in a separate process, at most " +
                   std::to_string(static_cast<long>(std::ceil(seconds))) + " s)");
  const std::string bytes = run_isolated(
      "meshing with Gmsh", seconds,
      [&] {
        if (::getpid() != parent) keep_gmsh_from_writing_files();  // never in the caller's process
        return mesh_to_bytes(mesh::mesh_with_gmsh_fragments(model, params, Progress{}));
      },
      progress);
  return mesh_from_bytes(bytes);
}

TetMesh mesh_model(const brep::TwoBReps& model, const MeshSettings& settings, const Progress& progress,
                   mesh::MeshRun* run) {
  check_mesh_settings(settings);
  const MeshSizes sizes =
      resolve_mesh_sizes(settings, model.part.diagonal(), std::abs(model.part.solid_volume.sum()), progress);
  TetMesh m;
  std::string reason;
  if (settings.mesher != Mesher::Gmsh) {
    if (try_native(model, settings, sizes, progress, run, m, reason)) return m;
    if (run) run->fallback_reason = reason;
    progress.warn("the native mesher could not mesh this part (" + reason +
                  "); meshing with Gmsh's OCC fragments instead");
  }
  return gmsh(model, settings, sizes, reason, progress, run);
}

}  // namespace topopt::pipeline
