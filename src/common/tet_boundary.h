// The boundary of a tet mesh from its connectivity alone: the faces used by one tet. Meshing
// (the Gmsh fallback) and file reading (MSH without triangles) both need it.
#pragma once
#include "common/types.h"

namespace topopt {

/// The boundary triangles of the tets T (#T by 4, positively oriented): every face used by
/// exactly one tet, turned so that its normal points out of that tet. Returns #F by 3, rows
/// in ascending order of their node triples (deterministic).
MatX3i boundary_triangles(const MatX4i& T);

}  // namespace topopt
