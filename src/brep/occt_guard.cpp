// OCCT exceptions in words (see occt_guard.h).
#include "brep/occt_guard.h"

#include <OSD_Signal.hxx>
#include <Standard_ConstructionError.hxx>
#include <Standard_DimensionError.hxx>
#include <Standard_NoMoreObject.hxx>
#include <Standard_NoSuchObject.hxx>
#include <Standard_NullObject.hxx>
#include <Standard_NumericError.hxx>
#include <Standard_OutOfMemory.hxx>
#include <Standard_RangeError.hxx>
#include <Standard_TypeMismatch.hxx>
#include <StdFail_NotDone.hxx>
#include <TopoDS_FrozenShape.hxx>
#include <TopoDS_UnCompatibleShapes.hxx>

namespace topopt::brep {

bool occt_failure_is_signal(const Standard_Failure& failure) { return failure.IsKind(STANDARD_TYPE(OSD_Signal)); }

std::string occt_failure_kind(const Standard_Failure& f) {
  if (occt_failure_is_signal(f)) return "an access violation or another fatal signal, caught";
  if (f.IsKind(STANDARD_TYPE(Standard_OutOfMemory))) return "out of memory";
  if (f.IsKind(STANDARD_TYPE(Standard_RangeError))) return "an index out of range";
  if (f.IsKind(STANDARD_TYPE(Standard_NoSuchObject)) || f.IsKind(STANDARD_TYPE(Standard_NoMoreObject)))
    return "a reference to a missing sub-shape";
  if (f.IsKind(STANDARD_TYPE(Standard_NullObject))) return "a missing curve, surface or shape";
  if (f.IsKind(STANDARD_TYPE(TopoDS_UnCompatibleShapes)) || f.IsKind(STANDARD_TYPE(TopoDS_FrozenShape)) ||
      f.IsKind(STANDARD_TYPE(Standard_TypeMismatch)))
    return "sub-shapes of the wrong kind in the topology";
  if (f.IsKind(STANDARD_TYPE(Standard_ConstructionError)) || f.IsKind(STANDARD_TYPE(Standard_DimensionError)) ||
      f.IsKind(STANDARD_TYPE(StdFail_NotDone)))
    return "a geometric construction that could not be made";
  if (f.IsKind(STANDARD_TYPE(Standard_NumericError))) return "a numerical failure (division by zero or overflow)";
  return "an internal failure of the geometry kernel";
}

Error occt_error(const Standard_Failure& failure, const std::string& doing, OcctBlame blame) {
  const bool signal = occt_failure_is_signal(failure);
  const std::string what_to_do =
      blame == OcctBlame::inputs
          ? "check the part and the non-design solids with Part > Check geometry in FreeCAD and re-export them "
            "from your CAD system; if they are sound, please report this with the files"
          : "the fault is in the shape TopOpt made itself, not in your part or non-design solids; please report "
            "this with the job file";
  return Error(signal ? ErrorCode::Crashed : ErrorCode::InvalidShape,
               doing + " failed inside the geometry kernel, OCCT (" + occt_failure_kind(failure) + "): " + what_to_do);
}

}  // namespace topopt::brep
