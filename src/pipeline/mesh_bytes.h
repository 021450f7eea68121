// A TetMesh as bytes and back: how a mesh made in a child process (the isolated Gmsh
// fallback, a worker) reaches its parent through a pipe. Native byte order; both ends are
// the same build.
#pragma once
#include <string>

#include "common/types.h"

namespace topopt::pipeline {

/// V, T, domain, F, face and nd_face with their shapes.
std::string mesh_to_bytes(const TetMesh& mesh);

/// The mesh mesh_to_bytes() wrote. Throws Error(Internal) for bytes that are not one (cut
/// short, or not from mesh_to_bytes).
TetMesh mesh_from_bytes(const std::string& bytes);

}  // namespace topopt::pipeline
