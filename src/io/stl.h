// STL output of triangle surfaces.
#pragma once
#include <string>

#include "common/types.h"

namespace topopt::io {

/// Writes a binary STL (normals from the vertex order). Throws Error(Io) on failure.
void write_stl(const std::string& path, const MatX3d& V, const MatX3i& F, const std::string& header = "TopOpt result");

}  // namespace topopt::io
