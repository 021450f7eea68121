// The part of a tet mesh that a crisp design keeps: its kept tets and the boundary triangles
// that are faces of kept tets. Loads on a crisp design are made on this part (fem::make_loads),
// so that a face load lands only where material is and a body load weighs only the kept tets;
// the verification also drops the pieces of its own mesh that nothing holds with it.
#pragma once
#include <vector>

#include "common/types.h"

namespace topopt::fem {

/// How kept_part numbers the nodes of the part.
enum class KeptNodes {
  Same,    ///< the mesh's own nodes and numbering (loads made on the part fit the whole mesh's dofs)
  Compact  ///< only the nodes of kept tets, renumbered in the order the kept tets first use them
};

/// The tets of `mesh` with kept[t] (#T flags, 1 = kept), in their order, with their domain tags
/// (0 where the mesh has none), and the boundary triangles of `mesh` (F, face, nd_face) that are
/// faces of kept tets, in their order; faces the cut opens get no triangles (they are free
/// surface: no support or face load acts there). nodes: see KeptNodes. Returns the part.
TetMesh kept_part(const TetMesh& mesh, const std::vector<char>& kept, KeptNodes nodes = KeptNodes::Same);

}  // namespace topopt::fem
