// Gmsh MSH 4.1 (ASCII) for tagged tet meshes: what `topopt mesh` writes and `solve`/`optimize`
// read. Physical volumes: 1 = design Ω0, 2… = non-design solids Ω1… in input order. Physical
// surfaces: Ω's B-Rep faces with tag = FreeCAD's face number (named "FaceN"); triangles that
// also lie on a face K of the non-design compound carry the extra physical tag 100000+K
// (named "NonDesign:FaceK").
#pragma once
#include <string>

#include "common/tet_boundary.h"
#include "common/types.h"

namespace topopt::io {

/// Tag offset of the physical surfaces naming the non-design compound's faces.
constexpr int kNonDesignFaceTag = 100000;

/// Writes `mesh` to `path` as MSH 4.1 ASCII. Throws Error(Io) if the file cannot be written.
void write_msh(const std::string& path, const TetMesh& mesh);

/// Reads an MSH 4.1 ASCII file (ours, or Gmsh's with physical groups). Tets: domain = the
/// physical volume tag − 1 (or the entity tag − 1 without physical groups); negatively
/// oriented tets are flipped. Triangles with a physical tag become TetMesh::F with that face
/// number; if the file has none, the boundary of the tets is used with face 0. Other element
/// types are skipped. Throws Error(Io) naming the line for a malformed file.
TetMesh read_msh(const std::string& path);

/// The boundary triangles of a tet mesh live in common/tet_boundary.h (meshing needs them
/// too); the name is kept here for the callers that read meshes.
using topopt::boundary_triangles;

}  // namespace topopt::io
