// Reading shapes: STEP, IGES and BREP files, and BREP strings (the form in which the
// FreeCAD workbench hands shapes over: Shape.exportBrepToString()).
#pragma once
#include <TopoDS_Shape.hxx>
#include <string>

namespace topopt::brep {

/// Reads a shape from a file, by extension: .step/.stp, .iges/.igs, .brep/.brp
/// (case-insensitive). Multiple roots come back as one compound (STEPControl OneShape, as
/// FreeCAD's Part.read does, so sub-shape numbering matches FreeCAD's).
/// Throws Error(Io) naming the file if it is missing, unreadable or empty.
TopoDS_Shape read_shape_file(const std::string& path);

/// Reads a shape from the text of a BREP file. Throws Error(Io) if the text is not a shape.
/// `what` names the shape in the message ("part", "non-design solids").
TopoDS_Shape read_brep_string(const std::string& text, const std::string& what = "shape");

/// The BREP text of a shape (the inverse of read_brep_string).
std::string write_brep_string(const TopoDS_Shape& shape);

}  // namespace topopt::brep
