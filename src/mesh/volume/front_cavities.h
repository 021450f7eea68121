// The volume front's last resort for the small cavities its advancing passes leave: each
// closed component of the front is filled from one point that sees all its faces (one of its
// nodes, its centroid or a point spread over its box: the one whose worst tet is best); when
// no point sees them all, the cavity takes in the tets behind its faces and tries again (a
// twisted prism between the two sides of a thin wall has no such point, the larger cavity
// usually has), and as the last resort it is filled in pieces. Every tet is checked against
// the whole front as it is made (TetFront::admits).
#pragma once
#include <vector>

#include "common/progress.h"
#include "mesh/volume/tet_front.h"

namespace topopt::mesh {

/// The front's faces in closed components (faces sharing a node belong together), each in
/// ascending order, the components ordered by their first face.
std::vector<std::vector<int>> front_components(const TetFront& front);

/// Fills the components of the front from single points as above. P: the nodes (points may
/// be appended); tets: the tets so far (new ones appended; tets taken into a cavity are
/// marked removed, t[0] = -1). Faces that stay open are left on the front for the caller.
void close_cavities(TetFront& front, std::vector<Eigen::Vector3d>& P, std::vector<Tet>& tets, const Progress& progress);

}  // namespace topopt::mesh
