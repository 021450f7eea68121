// Gross damage to a solid's geometry, found before OCCT's checker sees it: OCCT's BRepCheck
// crashes on an edge without a curve and spins forever projecting an edge onto a face that
// it lies far away from (both seen in damaged BREP text). These tests read only the stored
// data (no projection, no bounding box of curves), so they cannot hang themselves.
#pragma once
#include <TopoDS_Shape.hxx>
#include <string>

namespace topopt::brep {

/// Checks that every vertex of `solid` has finite coordinates, every face a surface, every
/// edge that is not degenerate a 3D curve with a finite range, and that each edge lies on
/// each face it bounds: at 5 samples the edge's curve may be at most 1000x the edge's
/// tolerance or 1 % of the size of the vertices' box (whichever is larger; a sound B-Rep
/// stays within the tolerance) from its stored curve on the face (same-parameter edges), or
/// from the face's plane where none is stored. Other edges are left to OCCT's checker.
/// Entities are named as FreeCAD numbers them within `solid`. Throws Error(InvalidShape):
/// "`label` is damaged: Edge12 lies 35 mm away from Face3, which it bounds ...; `advice`".
void check_gross_damage(const TopoDS_Shape& solid, const std::string& label, const std::string& advice);

}  // namespace topopt::brep
