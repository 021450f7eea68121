// Connected pieces of a set of tets: across shared faces (tet_components) or across shared
// nodes (node_components). The result's hygiene and verification count the result's pieces
// with them, the optimiser the eroded design's.
#pragma once
#include <vector>

#include "common/types.h"

namespace topopt::mesh {

/// Face-connected components of the tets with mask[t] set, over `neighbours` (#T by 4).
/// Returns #T labels, 0..count-1 for masked tets, -1 for the others; `count` gets the number.
VecXi tet_components(const MatX4i& neighbours, const std::vector<char>& mask, int& count);

/// Components of the tets with mask[t] set that share a node (pieces touching at an edge or a
/// corner are one; the verification's tets, which fill the result surface, are joined so;
/// the pieces of the result shape cut from node densities are result::level_components').
/// Returns #T labels, 0..count-1 for masked tets, -1 for the others; `count` gets the number.
VecXi node_components(const TetMesh& mesh, const std::vector<char>& mask, int& count);

}  // namespace topopt::mesh
