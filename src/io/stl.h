// STL output of triangle surfaces.
#pragma once
#include <string>

#include "common/types.h"

namespace topopt::io {

/// Writes a binary STL (normals from the vertex order). With `tags` (#F), each triangle's
/// 16-bit attribute holds its tag (e.g. its B-Rep face number; 65535 and up are written as
/// 65535), otherwise 0. Throws Error(Io) on failure.
void write_stl(const std::string& path, const MatX3d& V, const MatX3i& F, const std::string& header = "TopOpt result",
               const VecXi* tags = nullptr);

}  // namespace topopt::io
