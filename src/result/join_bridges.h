// Bridges for the non-design solids the optimum leaves apart. A designer's non-design solid (a
// boss a bolt goes through, a clamp pad) is part of the product even when it carries no load
// of the study, so the delivered part is one piece: each such solid is joined to the piece that
// carries the loads by the cheapest path through the design tets, the cost of a step its length
// times a penalty that grows as the density falls (the path follows the optimum's grey or solid
// material where there is some), thickened to a member of a given diameter and set solid.
#pragma once
#include <vector>

#include "common/types.h"
#include "result/design_hygiene.h"

namespace topopt::result {

/// The penalty of a step into a design tet of density rho (clamped to [0, 1]): 1 in solid
/// material, kVoidPenalty in void, linear between.
inline constexpr double kVoidPenalty = 10;
double bridge_penalty(double rho);

/// Joins every piece of the result shape (level_components at `threshold` of the node
/// densities of `density`, #T element densities) that piece_fates names (apart from the
/// load-carrying pieces, kept) and that holds non-design tets to the load-carrying pieces:
/// Dijkstra on the tets' face adjacency (neighbours #T by 4, tet_neighbours) from the piece's
/// tets to the nearest load-carrying tet (or one joined before), a step costing the distance
/// between the tets' centres times bridge_penalty of the density of the tet entered
/// (non-design tets: 1); then every design tet with a node within size / 2 of the path (the
/// polyline through the path's tet centres, carried on by size / 2 past both ends, so that the
/// tube ends inside the pieces it joins) or on a tet of the path is set to density 1, so
/// every such node has node density 1 (the path's nodes join the piece to the load-carrying
/// one) and the result shape's member there is at least `size` across. Last the junctions
/// are closed within `size` of the path: the solid nodes closed by a ball of size / 2 and the
/// design tets whose nodes are all closed set to 1, then the one-element notches left filled
/// (design tets whose four nodes all touch a crisp or non-design tet, a few rounds), so that
/// the tube meets the pieces in fillets, not crevices: these left triangles below 10° where the
/// cut crossed a non-design face next to its edge, and slivers the member measure saw.
/// anchors: #V flags (kAnchorSupport | kAnchorLoad; empty: the largest piece carries). size:
/// the bridges' diameter (mm; <= 0: 3 × the mean edge length of the design tets). Appends one
/// Bridge per piece to `bridges` (joined: the piece is one with a load-carrying piece in the
/// returned densities; false when no path exists) and returns the densities (#T).
/// build: an overhang control's build direction (unit; zero: none). With one, the tube is
/// carried down along −build before the junctions close: every design tet with a node below the
/// axis, within size / 2 of it across the build direction and not under material of that shadow
/// (a node at or above the threshold, or of a non-design tet, within half an edge across above it)
/// is set solid too, down to the first material below (a member, a non-design solid) or where Ω
/// ends (the plate), so the bridge stands on a wall with sides along the build instead of hanging
/// as a horizontal tube, whose underside faces straight down (on the bracket lying, 95 mm² too
/// flat that the overhang pass, which only restores slopes, could not lift); what lies under that
/// material is its own to print, the wall does not go through it — unless the void under it is
/// thinner than `size`, which is filled (a ceiling just over the plate is an overhang too).
VecXd join_non_design_solids(const TetMesh& mesh, const MatX4i& neighbours, const VecXd& density, double threshold,
                             const std::vector<char>& anchors, double size, std::vector<Bridge>& bridges,
                             const Eigen::Vector3d& build = Eigen::Vector3d::Zero());

/// The warning for a bridge made: the solids it joins, the material it adds, its length and
/// diameter, and the job key that leaves them apart instead.
std::string bridge_warning(const Bridge& bridge);

}  // namespace topopt::result
