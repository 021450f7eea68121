// Reading shapes: STEP, IGES and BREP files, and BREP strings (the form in which the
// FreeCAD workbench hands shapes over: Shape.exportBrepToString()). Every read of such
// foreign geometry runs in a child process under a time and memory budget (brep/foreign.h):
// a damaged input ends as a topopt::Error naming it, never as a crash or a hang.
#pragma once
#include <TopoDS_Shape.hxx>
#include <string>

#include "brep/foreign.h"
#include "common/progress.h"

namespace topopt::brep {

/// Reads a shape from a file, by extension: .step/.stp, .iges/.igs, .brep/.brp
/// (case-insensitive). Multiple roots come back as one compound (STEPControl OneShape, as
/// FreeCAD's Part.read does, so sub-shape numbering matches FreeCAD's). `what` names the
/// input in messages ("part": "the part's file 'x.step'"; empty: "the file 'x.step'").
/// Throws Error(Io) if the file is missing, unreadable, empty or damaged (saying so and
/// to re-export it), Error(Crashed) if OCCT crashed on it, Error(Timeout) past the budget.
TopoDS_Shape read_shape_file(const std::string& path, const std::string& what = "", const ForeignParams& params = {},
                             const Progress& progress = {});

/// Reads a shape from the text of a BREP file; `what` names it in messages ("part",
/// "non-design input"). Throws as read_shape_file does.
TopoDS_Shape read_brep_string(const std::string& text, const std::string& what = "shape",
                              const ForeignParams& params = {}, const Progress& progress = {});

/// The BREP text of a shape (the inverse of read_brep_string).
std::string write_brep_string(const TopoDS_Shape& shape);

}  // namespace topopt::brep
