// Checking and healing input solids before anything is meshed.
#pragma once
#include <TopoDS_Shape.hxx>
#include <string>
#include <vector>

#include "brep/foreign.h"
#include "common/progress.h"

namespace topopt::brep {

/// Checks that `shape` consists of closed, valid solids of positive volume and nothing else
/// (no free faces or open shells). Heals what can be healed without changing the geometry:
/// closed shells become solids, reversed solids are turned outwards, invalid B-Reps go
/// through ShapeFix. Each repair is appended to `notes` in words a user understands.
/// `what` names the input in messages ("part", "non-design input").
/// The checks and repairs run in a child process under `params`' budget (brep/foreign.h):
/// OCCT's checker and ShapeFix crash or hang on some damaged B-Reps. Items that changed come
/// back as binary BREP written by OCCT; the others are the caller's own shapes, untouched.
/// Returns the checked (possibly healed) shape: a solid, or a compound of solids in the
/// input order. Throws Error(InvalidShape) saying which item is wrong and how, and
/// Error(Crashed) or Error(Timeout) when OCCT crashed or hung on the input.
TopoDS_Shape check_solids(const TopoDS_Shape& shape, const std::string& what, std::vector<std::string>& notes,
                          const ForeignParams& params = {}, const Progress& progress = {});

}  // namespace topopt::brep
