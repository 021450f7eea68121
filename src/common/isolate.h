// Running risky work (a foreign B-Rep read by OCCT, Gmsh) in a child process, so that a
// crash, an abort or a hang inside it ends the child, never the caller (the CLI or FreeCAD).
#pragma once
#include <functional>
#include <string>

#include "common/progress.h"

namespace topopt {

/// Runs `work` in a forked child and returns the bytes it returned. `what` names the work
/// for messages ("reading the part"). The parent waits at most `seconds` (<= 0: no limit),
/// checking progress.cancelled() ten times a second.
///
/// Throws, naming `what`:
/// - the child's own topopt::Error (code and message carried over the pipe);
/// - Error(Crashed) when the child dies by a signal or exits without answering (an access
///   violation or abort inside OCCT or Gmsh);
/// - Error(Timeout) when it runs past `seconds` (the child is killed);
/// - Error(Cancelled) when the user cancels (the child is killed).
/// The child runs only `work`, on one thread (a fork copies the calling thread alone), and
/// leaves with _exit: nothing of the parent's state is written or destroyed by it.
/// With TOPOPT_NO_ISOLATION=1 in the environment `work` runs in this process (for debuggers).
std::string run_isolated(const std::string& what, double seconds, const std::function<std::string()>& work,
                         const Progress& progress = {});

}  // namespace topopt
