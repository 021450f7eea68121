// Foreign geometry: STEP, IGES and BREP files and BREP strings that come from outside. OCCT
// can crash, hang or exhaust memory on a damaged one, so every read, check and heal of it
// runs in a child process (common/isolate.h) with a time and memory budget taken from the
// input's size; the child hands back the shape as binary BREP written by OCCT (exact doubles:
// OCCT's BREP text keeps 15 digits of edge ranges, and that moves meshes), which the caller
// re-reads.
// A crash, a hang or a refusal comes back as a topopt::Error naming the input and saying
// what to do, and the caller (the CLI, FreeCAD) is unharmed.
#pragma once
#include <TopoDS_Shape.hxx>
#include <functional>
#include <string>

#include "common/error.h"
#include "common/progress.h"

namespace topopt::brep {

/// The budget of one child that reads, or checks and heals, one input.
struct ForeignParams {
  /// Time allowed in seconds; <= 0: base_seconds + seconds_per_mb x the input's size in MB.
  /// Measured on the shared machine (2 cores, loaded): reading STEP about 1.7 s/MB (NIST 2,
  /// 2 MB: 3.4 s), checking 0.7 s/MB of BREP; the default is about 9x that plus a floor for
  /// a busy machine, so that only a hang reaches it.
  double seconds = 0;
  double base_seconds = 30;    ///< floor of the automatic budget (fork, load, small inputs)
  double seconds_per_mb = 15;  ///< added per MB of input
  /// Address space the child may add to what it inherits, in GB; <= 0: the larger of 4 GB and
  /// 50x the input's size (a 2 MB STEP needs about 0.1 GB). A damaged count that asks OCCT
  /// for an array of a billion points ends as an error instead of taking the machine's memory.
  double memory_gb = 0;
};

/// One foreign input as messages name it.
struct ForeignInput {
  std::string subject;             ///< "the part's file 'x.step'", "the non-design input", ...
  std::string advice;              ///< what to do when it is damaged: "re-export it from your CAD system"
  double bytes = 0;                ///< its size (file or text bytes; a shape's estimate: shape_bytes)
  ErrorCode code = ErrorCode::Io;  ///< the code of a refusal: Io for a file, InvalidShape for a shape
};

/// The automatic time budget for an input of `bytes` (ForeignParams::seconds if > 0).
double foreign_seconds(double bytes, const ForeignParams& params);

/// The size of `shape` as BREP text, estimated from its faces (4 KB each, as in the NIST
/// parts): the size that sets the budget of checking and healing a shape held in memory.
double shape_bytes(const TopoDS_Shape& shape);

/// Runs `work` (`doing` the input: "reading", "checking and healing") in a child process
/// under the input's budget and returns its bytes. In the child, faults end the process
/// (OCCT's and FreeCAD's signal handlers are reset), memory is limited, and OCCT's
/// exceptions become Error(input.code) in words. Throws, naming the input and giving the advice:
/// the child's own Error; Error(Crashed) "... is damaged: OCCT crashed reading it ...";
/// Error(Timeout) when it runs past the budget; Error(Cancelled) on a cancel.
std::string run_foreign(const ForeignInput& input, const std::string& doing, const ForeignParams& params,
                        const std::function<std::string()>& work, const Progress& progress = {});

/// Cheap structural checks of BREP text before any child is started: the "CASCADE Topology"
/// header near its start and a "TShapes" section after it. Throws Error(Io) naming the input.
void precheck_brep_text(const std::string& text, const ForeignInput& input);

/// Parses BREP text. The stream throws at its first failed read: BRepTools::Read otherwise
/// spins forever on a cut-short text (a failed `>>` leaves its variable as it was, and
/// loops such as a vertex's `do { IS >> n; ... } while (n > 0)` never end). Throws
/// Error(Io) naming the input and the line where reading failed, or an empty shape.
TopoDS_Shape parse_brep_text(const std::string& text, const ForeignInput& input);

/// The bytes that carry `shape` out of the child: binary BREP written by OCCT (BinTools, every
/// double exact) and read back once in the child, so that the caller's read of them
/// (shape_from_handover) has already succeeded once.
std::string handover_bytes(const TopoDS_Shape& shape, const ForeignInput& input);

/// The shape in bytes made by handover_bytes. Throws Error naming the input if they do not
/// hold one (OCCT's failures in words).
TopoDS_Shape shape_from_handover(const std::string& bytes, const ForeignInput& input);

}  // namespace topopt::brep
