// Renumbers a tet mesh's nodes and tets along a space-filling (Morton) curve, so that nodes
// close in space get close numbers. Mesh generators number nodes entity by entity (Gmsh puts
// a tet's surface nodes and volume nodes thousands apart), which scatters every sparse
// product, assembly and filter access; after this, neighbours are mostly in cache.
#pragma once
#include "common/types.h"

namespace topopt::mesh {

/// Reorders `mesh` in place: nodes by the Morton code of their position in the bounding
/// box (21 bits an axis), tets (with their domain tags) by the code of their centroid.
/// T and F are renumbered; tet orientation, triangle orientation, F's order and its face tags
/// are unchanged. Returns the new index of every old node (#V), for callers that hold node
/// numbers.
VecXi reorder_for_locality(TetMesh& mesh);

}  // namespace topopt::mesh
