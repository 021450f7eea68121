// The minimum member size held on the crisp design the user gets (issue 22: the robust
// formulation "or an equivalent, verified on the result"). The robust formulation imposes the
// size through the eroded design, and where that design cannot carry the load (it came apart, or
// is not joined: docs/optimization.md, "Minimum member size") the intermediate design keeps
// members thinner than the size. This pass measures the crisp design (the tets whose node
// densities reach the result's threshold) with the product's member measure
// (simp::measure_members, PartFaces::Clipped, the reach of a mesh size), and thickens every member
// thinner than the size: the design tets within (size − thickness)/2 of a thin tet's centre are
// set solid (a dilation of the thin set inside Ω: a plate of thickness w grows by (size − w)/2 on
// either side; when that adds nothing the crisp design keeps, the radius grows by a quarter of a
// mesh size, up to one), measured again, at most `rounds` times. A member along the part's face
// grows on one side only, so it takes a few rounds. Nothing is removed, so the result holds more
// than the volume fraction by the volume added, which the report and the warning name.
//
// Not held to the size: the design tets within a mesh size of a non-design tet or touching a node
// where a support or load acts — where the design meets what it is attached to, whose own
// thickness is the user's (the cantilever's 2 mm slab), not a member of the design.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "common/types.h"

namespace topopt::result {

struct MemberEnforceParams {
  double size = 0;  ///< the minimum member size (mm); <= 0: nothing is done
  int rounds = 6;   ///< measure-and-thicken rounds at most
};

/// What enforce_min_member found and did.
struct MemberEnforcement {
  double size = 0;               ///< the size held (mm)
  double cell = 0;               ///< mm: the mesh size, the measure's reach and resolution (member_cell)
  double smallest_before = 0;    ///< mm: the smallest member of the tets held to the size, before
  double smallest_after = 0;     ///< ... and after (0 when there is none)
  std::array<double, 3> thinnest_at{0, 0, 0};  ///< where the thinnest was before (a design tet's centre)
  double volume_added = 0;       ///< mm³: Σ volume × (1 − density) of the design tets set solid
  double design_volume = 0;      ///< mm³ of the design domain
  long tets_added = 0;           ///< design tets set solid
  std::array<double, 3> added_lo{0, 0, 0}, added_hi{0, 0, 0};  ///< the box of the tets set solid
  int rounds = 0;                ///< thickening rounds run
  bool measured = false;         ///< a size was set and the design holds tets held to it
  /// The size met to the measure's resolution: smallest_after >= size − cell.
  bool met() const { return !measured || smallest_after >= size - cell; }
};

/// The mesh size the pass measures with (mm): the mean over the design tets (all tets without
/// any) of the edge of the regular tet of the same volume, (6√2 v)^(1/3) — 1.12 cells on a
/// structured box of cubes cut into six tets.
double member_cell(const TetMesh& mesh);

/// #T flags: the design tets not held to the size — their centre within `cell` (mm) of a
/// non-design tet's centre, or a node with a nonzero `anchors` flag (#V; may be empty).
std::vector<char> member_attachments(const TetMesh& mesh, const std::vector<char>& anchors, double cell);

/// The crisp design of `density` (#T) at `threshold` (crisp_tets of the node densities) with its
/// members thinner than params.size thickened as the header says. anchors: #V flags of the nodes
/// where supports and loads act (may be empty). Returns the densities (#T; the tets set solid at
/// 1, the others as given) and fills `report`.
VecXd enforce_min_member(const TetMesh& mesh, const VecXd& density, double threshold, const std::vector<char>& anchors,
                         const MemberEnforceParams& params, MemberEnforcement& report);

/// The warning for a pass that thickened something or did not meet the size, in the user's terms
/// (the job key, the sizes, the volume added and where); "" when there is nothing to say.
std::string member_warning(const MemberEnforcement& report);

}  // namespace topopt::result
