// Checking and healing input solids before anything is meshed.
#pragma once
#include <TopoDS_Shape.hxx>
#include <string>
#include <vector>

namespace topopt::brep {

/// Checks that `shape` consists of closed, valid solids of positive volume and nothing else
/// (no free faces or open shells). Heals what can be healed without changing the geometry:
/// closed shells become solids, reversed solids are turned outwards, invalid B-Reps go
/// through ShapeFix. Each repair is appended to `notes` in words a user understands.
/// `what` names the input in messages ("part", "non-design input").
/// Returns the checked (possibly healed) shape: a solid, or a compound of solids in the
/// input order. Throws Error(InvalidShape) saying which item is wrong and how.
TopoDS_Shape check_solids(const TopoDS_Shape& shape, const std::string& what, std::vector<std::string>& notes);

}  // namespace topopt::brep
