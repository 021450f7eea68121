// The triangles around each node of a triangle mesh, as one flat adjacency (CSR): what the face
// front's smoothing and the surface optimiser walk when they move or remove a node.
#pragma once
#include <vector>

#include "brep/topology_index.h"
#include "common/types.h"

namespace topopt::mesh {

/// Compressed rows (offset, index; row v is index[offset[v] .. offset[v+1])): the type the
/// B-Rep index keeps its tables in, the code base's one adjacency type.
using TriangleStars = decltype(brep::TopologyIndex::face_edges);

/// The star of every node: row v of the result lists the triangles (rows of T) with a corner
/// at v, in increasing order, each once per corner it has there.
/// T: #T by 3 node indices; only its first `nt` rows are read. nodes: the number of rows of the
/// result (every index in T must be below it). dead: empty, or #nt flags; a triangle whose flag
/// is set is left out.
TriangleStars triangle_stars(const MatX3i& T, long nt, long nodes, const std::vector<char>& dead = {});

}  // namespace topopt::mesh
