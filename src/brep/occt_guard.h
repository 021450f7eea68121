// OCCT failures in the user's words. OCCT reports trouble by exceptions whose messages are
// its own class and method names ("NCollection_IndexedMap::FindKey"); where OCCT's signal
// handler is installed (OSD::SetSignal, as the CLI does), an access violation inside OCCT
// becomes such an exception too, at the nearest OCC_CATCH_SIGNALS. Everything here turns
// them into topopt::Error saying what failed and what to do; no OCCT name reaches the user.
#pragma once
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <string>

#include "common/error.h"

#if !defined(OCC_CONVERT_SIGNALS)
#error "topopt_core is built with OCC_CONVERT_SIGNALS, as Debian's OCCT is (src/CMakeLists.txt)"
#endif

namespace topopt::brep {

/// What an OCCT exception means, in a few words for a message: "an access violation",
/// "an index out of range", "a missing curve or surface", ... (never an OCCT class name).
std::string occt_failure_kind(const Standard_Failure& failure);

/// True when `failure` is a signal turned into an exception (access violation, bus error,
/// illegal instruction, floating-point trap): OCCT crashed rather than refused.
bool occt_failure_is_signal(const Standard_Failure& failure);

/// What an OCCT failure is put down to: the user's input shapes (check and re-export them), or
/// a shape TopOpt made itself (the result surface as a solid: nothing the user's CAD can fix).
enum class OcctBlame { inputs, own_shape };

/// The Error for an OCCT failure while `doing` ("classifying the non-design solids against
/// the part"): code Crashed for a signal, InvalidShape otherwise; the message names the
/// stage and the kind of failure and, by `blame`, says to check and re-export the inputs or
/// that the fault is in TopOpt's own shape (to be reported with the job).
Error occt_error(const Standard_Failure& failure, const std::string& doing, OcctBlame blame = OcctBlame::inputs);

/// Runs `work()` and returns its result; an OCCT exception escaping it is rethrown as
/// occt_error(failure, doing). Where OSD::SetSignal is active, an access violation on this
/// thread inside `work` is caught too (OCC_CATCH_SIGNALS: a long jump back here, so the
/// objects `work` had on the stack are abandoned, not destroyed: use it around whole stages
/// whose partial results are dropped on failure). Without OSD::SetSignal (FreeCAD) a fault
/// still ends the process: keep foreign geometry in a child (brep/foreign.h).
/// `blame`: as occt_error's.
template <class Work>
auto guard_occt(const std::string& doing, Work&& work, OcctBlame blame = OcctBlame::inputs) -> decltype(work()) {
  try {
    OCC_CATCH_SIGNALS
    return work();
  } catch (const Standard_Failure& failure) {
    throw occt_error(failure, doing, blame);
  }
}

}  // namespace topopt::brep
